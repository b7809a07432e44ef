#include "diff_rigid_body/algorithm/frame_jacobians.h"

#include <algorithm>

#include "diff_rigid_body/algorithm/crba.h"
#include "diff_rigid_body/algorithm/rnea.h"

namespace diff_rigid_body
{
namespace
{
/// The frame's pose (R_F, p_F): X_segment T(link_origin) X_link-in-segment.
void framePose(const BodyModel& model, const BodyWorkspace<double>& ws, const LinkInBody& link, Matrix3<double>& R,
               Vector3<double>& p)
{
  const Segment& segment = model.segments[link.segment];
  const Matrix3<double>& Rs = ws.R[link.segment];
  R = Rs * link.pose_in_segment_link.linear();
  p = ws.p[link.segment] + Rs * (segment.link_origin + link.pose_in_segment_link.translation());
}

void writePose(const Matrix3<double>& R, const Vector3<double>& p, double* pose12)
{
  for (int i = 0; i < 3; ++i)
    pose12[i] = p[i];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      pose12[3 + 3 * r + c] = R(r, c);
}

/// J_c = (V_c + W_c x (P - r), W_c) (6 x d row-major), written from the unit
/// motions of the dofs that segment s hangs from (the only nonzero columns):
/// dof k adds m_k (S_k.v + S_k.w x lever, S_k.w) to column c_k, in fixed axes
/// or, for LOCAL, in R's. A free root's rotation dofs are motion coordinates,
/// so its columns 0..2 are then turned by the chart: J_x = J_nu A, A = T there.
void writeJacobian(const BodyModel& model, const BodyWorkspace<double>& ws, std::size_t s,
                   const Vector3<double>& lever, bool local, const Matrix3<double>& R, double* J)
{
  const std::size_t d = model.coordinates;
  std::fill(J, J + 6 * d, 0.0);
  const Segment& segment = model.segments[s];
  for (int k = segment.first_dof + segment.dof_count - 1; k >= 0; k = model.dofs[static_cast<std::size_t>(k)].parent)
  {
    const Dof& dof = model.dofs[static_cast<std::size_t>(k)];
    const Motion<double>& S = ws.S[static_cast<std::size_t>(k)];
    const Vector3<double> W = dof.multiplier * S.w;
    Vector3<double> linear = dof.multiplier * S.v + W.cross(lever);
    Vector3<double> angular = W;
    if (local)
    {
      linear = R.transpose() * linear;
      angular = R.transpose() * angular;
    }
    const std::size_t c = static_cast<std::size_t>(dof.coordinate);
    for (int i = 0; i < 3; ++i)
    {
      J[static_cast<std::size_t>(i) * d + c] += linear[i];
      J[static_cast<std::size_t>(3 + i) * d + c] += angular[i];
    }
  }
  if (!model.hasFreeRoot())
    return;
  const Matrix3<double>& T = ws.chart.T;
  for (std::size_t i = 0; i < 6; ++i)
  {
    double* row = J + i * d;  // the rotation coordinates phi, theta, psi are x[0..2]
    const double along[3] = { row[0], row[1], row[2] };
    for (int c = 0; c < 3; ++c)
      row[c] = along[0] * T(0, c) + along[1] * T(1, c) + along[2] * T(2, c);
  }
}
}  // namespace

void markSupport(const BodyModel& model, std::size_t link, std::vector<char>& needed)
{
  for (int s = static_cast<int>(model.links[link].segment); s >= 0; s = model.segments[static_cast<std::size_t>(s)].parent)
    needed[static_cast<std::size_t>(s)] = 1;
}

void frameMotion(const BodyModel& model, BodyWorkspace<double>& ws, const double* xd)
{
  const double* nu_dot = motionAccelerations(model, ws, xd, static_cast<const double*>(nullptr));
  detail::propagateMotion(model, ws, motionRates(model, ws, xd), nu_dot, Vector3<double>::Zero().eval());
}

void frameJacobian(const BodyModel& model, BodyWorkspace<double>& ws, std::size_t link, FrameReference reference,
                   double* pose12, double* jacobian, double* bias)
{
  const LinkInBody& in_body = model.links[link];
  const std::size_t s = in_body.segment;
  Matrix3<double> R;
  Vector3<double> p;
  framePose(model, ws, in_body, R, p);
  writePose(R, p, pose12);
  const Vector3<double> point = reference == FrameReference::World ? Vector3<double>::Zero() : p;
  const Vector3<double> lever = point - ws.r;
  const bool local = reference == FrameReference::Local;
  if (jacobian)
    writeJacobian(model, ws, s, lever, local, R, jacobian);
  if (!bias)
    return;
  const Segment& segment = model.segments[s];
  const std::size_t last = static_cast<std::size_t>(segment.first_dof + segment.dof_count - 1);
  const Motion<double>& v = ws.dof_velocity[last];
  const Motion<double>& a = ws.dof_acceleration[last];
  const Vector3<double> v_point = v.v + v.w.cross(lever);
  Vector3<double> linear = a.v + a.w.cross(lever) + v.w.cross(v_point);
  Vector3<double> angular = a.w;
  if (local)
  {
    linear = R.transpose() * linear;
    angular = R.transpose() * angular;
  }
  std::copy(linear.data(), linear.data() + 3, bias);
  std::copy(angular.data(), angular.data() + 3, bias + 3);
}

double centerOfMass(const BodyModel& model, BodyWorkspace<double>& ws, const double* x, const double* xd,
                    double* com, double* jacobian, double* bias)
{
  forwardKinematics(model, ws, x);
  detail::compositeInertias(model, ws);
  const Inertia<double>& whole = ws.composite[0];
  const double mass = whole.m;
  if (!(mass > 0.0))
    return 0.0;
  const Vector3<double> c = ws.r + whole.h / mass;
  std::copy(c.data(), c.data() + 3, com);
  const std::size_t d = model.coordinates;
  if (jacobian)
  {
    Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> J(jacobian, 3, static_cast<Eigen::Index>(d));
    J.setZero();
    for (std::size_t k = 0; k < model.dofs.size(); ++k)
    {
      const Dof& dof = model.dofs[k];
      const Force<double> F = spatial::momentum(ws.composite[static_cast<std::size_t>(dof.segment)], ws.S[k]);
      J.col(dof.coordinate) += (dof.multiplier * F.f) / mass;  // m / m is exactly 1: a free body's dc/dt = I
    }
    columnsToCoordinates(model, ws, J);
  }
  if (bias)
  {
    const double* nu_dot = motionAccelerations(model, ws, xd, static_cast<const double*>(nullptr));
    inverseDynamicsInMotion(model, ws, motionRates(model, ws, xd), nu_dot, Vector3<double>::Zero().eval(),
                            ws.tau.data(), /*inertias_ready=*/true);
    const Vector3<double> rate = ws.subtree_force[0].f / mass;
    std::copy(rate.data(), rate.data() + 3, bias);
  }
  return mass;
}

}  // namespace diff_rigid_body
