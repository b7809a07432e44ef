// The methods compared by the benchmarks, each behind one small interface so
// that the timing binary (Google Benchmark) and the error binary (MPFR
// reference) run exactly the same code:
//   mass matrix  M(q) of one body, 36 values row-major, q order;
//   Jacobians    J = dp/dq of many vertices, 18 values per vertex (3x6
//                row-major, q order);
//   backprop     dL/dq = sum_i J_i^T g_i.
// Peers: KDL (chain TransX, TransY, TransZ, RotZ, RotY, RotX, body at the
// tip with its COM at the tip origin) and MuJoCo (3 slide joints and hinges
// z, y, x). Their joint order is (tx, ty, tz, psi, theta, phi), ours is
// (phi, theta, psi, tx, ty, tz): kPeerIndex maps ours to theirs.
#pragma once

#include <complex>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "bench_common.h"
#include "diff_rigid_body/algorithm/free_body/mass_matrix.h"
#include "diff_rigid_body/algorithm/free_body/vertex_jacobian.h"
#include "reference/vertex_kernels.h"

#ifdef DRB_BENCH_HAVE_KDL
#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/jacobian.hpp>
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

namespace drb_bench
{
/// Our q index i is the peers' joint kPeerIndex[i].
constexpr int kPeerIndex[6] = { 5, 4, 3, 0, 1, 2 };

// ---------------------------------------------------------------------------
// Ours.

inline void oursMassMatrix(const Vector6d& q, double mass, const Matrix3d& I, double* out)
{
  const Matrix6d M = drb::massMatrix(q, mass, I);
  std::memcpy(out, M.data(), 36 * sizeof(double));  // symmetric: column-major = row-major
}

// ---------------------------------------------------------------------------
// Kinetic energy by finite differences: E(qdot) = 1/2 m |tdot|^2 +
// 1/2 w^T I' w, with the world angular velocity w = vee(Rdot R^T) and Rdot a
// central difference of R along rdot; M from E by polarisation,
// M_ii = 2 E(e_i), M_ij = E(e_i + e_j) - E(e_i) - E(e_j).
struct EnergyFiniteDifferences
{
  double mass;
  Matrix3d I;

  double energy(const Vector6d& q, const Vector6d& qdot) const
  {
    const double h = 1.0 / 65536.0;  // ~ cbrt(eps)
    const Matrix3d R = drb::rpyToMatrix(q[0], q[1], q[2]);
    const Matrix3d Rp = drb::rpyToMatrix(q[0] + h * qdot[0], q[1] + h * qdot[1], q[2] + h * qdot[2]);
    const Matrix3d Rm = drb::rpyToMatrix(q[0] - h * qdot[0], q[1] - h * qdot[1], q[2] - h * qdot[2]);
    const Matrix3d W = (Rp - Rm) / (2 * h) * R.transpose();
    const Eigen::Vector3d w((W(2, 1) - W(1, 2)) / 2, (W(0, 2) - W(2, 0)) / 2, (W(1, 0) - W(0, 1)) / 2);
    const Eigen::Vector3d Iw = R * (I * (R.transpose() * w));
    return 0.5 * mass * qdot.tail<3>().squaredNorm() + 0.5 * w.dot(Iw);
  }

  void operator()(const Vector6d& q, double* out) const
  {
    double e[6];
    for (int i = 0; i < 6; ++i)
      e[i] = energy(q, Vector6d::Unit(i));
    for (int i = 0; i < 6; ++i)
    {
      out[6 * i + i] = 2 * e[i];
      for (int j = i + 1; j < 6; ++j)
      {
        const double v = energy(q, Vector6d::Unit(i) + Vector6d::Unit(j)) - e[i] - e[j];
        out[6 * i + j] = v;
        out[6 * j + i] = v;
      }
    }
  }
};

// ---------------------------------------------------------------------------
// KDL.

#ifdef DRB_BENCH_HAVE_KDL
inline KDL::Chain kdlChain(double mass, const Matrix3d& I)
{
  KDL::Chain chain;
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::TransX)));
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::TransY)));
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::TransZ)));
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ)));
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotY)));
  // The body: COM at the tip frame origin, so the translation joints move the COM.
  const KDL::RotationalInertia Ic(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotX), KDL::Frame::Identity(),
                                KDL::RigidBodyInertia(mass, KDL::Vector::Zero(), Ic)));
  return chain;
}

inline void toKdl(const Vector6d& q, KDL::JntArray& joints)
{
  for (int i = 0; i < 6; ++i)
    joints(kPeerIndex[i]) = q[i];
}

/// ChainDynParam::JntToMass, reordered into q order.
struct KdlMassMatrix
{
  KDL::Chain chain;
  KDL::ChainDynParam dyn;
  KDL::JntArray joints{ 6 };
  KDL::JntSpaceInertiaMatrix H{ 6 };

  KdlMassMatrix(double mass, const Matrix3d& I) : chain(kdlChain(mass, I)), dyn(chain, KDL::Vector::Zero())
  {
  }
  void operator()(const Vector6d& q, double* out)
  {
    toKdl(q, joints);
    dyn.JntToMass(joints, H);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j)
        out[6 * i + j] = H(kPeerIndex[i], kPeerIndex[j]);
  }
};

/// ChainJntToJacSolver once per body (reference point: the COM), then
/// Jacobian::changeRefPoint to each vertex.
struct KdlJacobians
{
  KDL::Chain chain;
  KDL::ChainJntToJacSolver jac_solver;
  KDL::ChainFkSolverPos_recursive fk_solver;
  KDL::JntArray joints{ 6 };
  KDL::Jacobian base{ 6 }, work{ 6 };
  KDL::Frame frame;

  KdlJacobians() : chain(kdlChain(1.0, Matrix3d::Identity())), jac_solver(chain), fk_solver(chain)
  {
  }
  void operator()(const Vector6d& q, const Matrix3Xd& vertices, double* out)
  {
    toKdl(q, joints);
    jac_solver.JntToJac(joints, base);
    fk_solver.JntToCart(joints, frame);
    for (Eigen::Index v = 0; v < vertices.cols(); ++v)
    {
      const KDL::Vector lever = frame.M * KDL::Vector(vertices(0, v), vertices(1, v), vertices(2, v));
      work = base;
      work.changeRefPoint(lever);
      double* J = out + 18 * v;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 6; ++c)
          J[6 * r + c] = work(r, kPeerIndex[c]);
    }
  }
};
#endif

// ---------------------------------------------------------------------------
// MuJoCo.

#ifdef DRB_BENCH_HAVE_MUJOCO
/// One body with slide x, y, z and hinges z, y, x at its COM; no gravity.
/// Loaded from an MJCF string through a virtual file system.
struct MujocoBody
{
  mjModel* model = nullptr;
  mjData* data = nullptr;
  std::vector<double> dense = std::vector<double>(36);

  MujocoBody(double mass, const Matrix3d& I)
  {
    // mj_fwdPosition warns at every gimbal-lock state (M singular there, as
    // expected): keep the benchmark output readable.
    mju_user_warning = [](const char*) {};
    std::ostringstream xml;
    xml.precision(17);
    xml << "<mujoco><option gravity='0 0 0'/><worldbody><body name='b'>"
        << "<joint name='tx' type='slide' axis='1 0 0'/><joint name='ty' type='slide' axis='0 1 0'/>"
        << "<joint name='tz' type='slide' axis='0 0 1'/>"
        << "<joint name='rz' type='hinge' axis='0 0 1'/><joint name='ry' type='hinge' axis='0 1 0'/>"
        << "<joint name='rx' type='hinge' axis='1 0 0'/>"
        << "<inertial pos='0 0 0' mass='" << mass << "' fullinertia='" << I(0, 0) << " " << I(1, 1) << " " << I(2, 2)
        << " " << I(0, 1) << " " << I(0, 2) << " " << I(1, 2) << "'/>"
        << "</body></worldbody></mujoco>";
    const std::string text = xml.str();
    auto vfs = std::make_unique<mjVFS>();
    mj_defaultVFS(vfs.get());
    if (mj_makeEmptyFileVFS(vfs.get(), "body.xml", static_cast<int>(text.size())) != 0)
      throw std::runtime_error("mujoco: cannot make a VFS file");
    const int index = mj_findFileVFS(vfs.get(), "body.xml");
    std::memcpy(vfs->filedata[index], text.data(), text.size());
    char error[1000] = "";
    model = mj_loadXML("body.xml", vfs.get(), error, sizeof(error));
    mj_deleteVFS(vfs.get());
    if (!model)
      throw std::runtime_error(std::string("mujoco: ") + error);
    data = mj_makeData(model);
  }
  ~MujocoBody()
  {
    mj_deleteData(data);
    mj_deleteModel(model);
  }
  MujocoBody(const MujocoBody&) = delete;
  MujocoBody& operator=(const MujocoBody&) = delete;

  void setState(const Vector6d& q)
  {
    for (int i = 0; i < 6; ++i)
      data->qpos[kPeerIndex[i]] = q[i];
  }

  /// The smallest pipeline that yields M: kinematics, com positions, the
  /// composite rigid body algorithm, dense M.
  void massMatrix(const Vector6d& q, double* out)
  {
    setState(q);
    mj_kinematics(model, data);
    mj_comPos(model, data);
    mj_crb(model, data);
    denseOut(out);
  }

  /// Same through mj_fwdPosition (the whole position stage).
  void massMatrixFwdPosition(const Vector6d& q, double* out)
  {
    setState(q);
    mj_fwdPosition(model, data);
    denseOut(out);
  }

  void denseOut(double* out)
  {
    mj_fullM(model, dense.data(), data->qM);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j)
        out[6 * i + j] = dense[6 * kPeerIndex[i] + kPeerIndex[j]];
  }

  /// mj_jac at each vertex's world position (kinematics once per body).
  void jacobians(const Vector6d& q, const Matrix3Xd& vertices, double* out)
  {
    setState(q);
    mj_kinematics(model, data);
    mj_comPos(model, data);
    double jacp[18];
    const double* xpos = data->xpos + 3;  // body 1
    const double* xmat = data->xmat + 9;
    for (Eigen::Index v = 0; v < vertices.cols(); ++v)
    {
      double point[3];
      for (int r = 0; r < 3; ++r)
        point[r] = xpos[r] + xmat[3 * r] * vertices(0, v) + xmat[3 * r + 1] * vertices(1, v) +
                   xmat[3 * r + 2] * vertices(2, v);
      mj_jac(model, data, jacp, nullptr, point, 1);
      double* J = out + 18 * v;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 6; ++c)
          J[6 * r + c] = jacp[6 * r + kPeerIndex[c]];
    }
  }
};
#endif

// ---------------------------------------------------------------------------
// Jacobians by central differences and by the complex step: p(q) = R(q) p0 + t
// evaluated at perturbed states, the perturbed poses computed once per body.

struct CentralDifferences
{
  void operator()(const Vector6d& q, const Matrix3Xd& vertices, double* out) const
  {
    const double h = 1.0 / 65536.0;  // ~ cbrt(eps): balances truncation and rounding
    Matrix3d Rp[6], Rm[6];
    Eigen::Vector3d tp[6], tm[6];
    double inv_step[6];
    for (int k = 0; k < 6; ++k)
    {
      Vector6d qp = q, qm = q;
      const double step = k < 3 ? h : h * std::max(1.0, std::abs(q[k]));
      qp[k] += step;
      qm[k] -= step;
      inv_step[k] = 1.0 / (qp[k] - qm[k]);  // the step actually taken
      Rp[k] = drb::rpyToMatrix(qp[0], qp[1], qp[2]);
      Rm[k] = drb::rpyToMatrix(qm[0], qm[1], qm[2]);
      tp[k] = qp.tail<3>();
      tm[k] = qm.tail<3>();
    }
    for (Eigen::Index v = 0; v < vertices.cols(); ++v)
    {
      const Eigen::Vector3d p0 = vertices.col(v);
      double* J = out + 18 * v;
      for (int k = 0; k < 6; ++k)
      {
        const Eigen::Vector3d d = ((Rp[k] * p0 + tp[k]) - (Rm[k] * p0 + tm[k])) * inv_step[k];
        J[k] = d[0];
        J[6 + k] = d[1];
        J[12 + k] = d[2];
      }
    }
  }
};

struct ComplexStep
{
  using Complex = std::complex<double>;
  void operator()(const Vector6d& q, const Matrix3Xd& vertices, double* out) const
  {
    const double h = 1e-30;
    drb::Matrix3<Complex> Rc[3];
    for (int k = 0; k < 3; ++k)
    {
      drb::Vector6<Complex> qc = q.cast<Complex>();
      qc[k] += Complex(0.0, h);
      Rc[k] = drb::rpyToMatrix(qc[0], qc[1], qc[2]);
    }
    const Eigen::Matrix<Complex, 3, 1> t = q.tail<3>().cast<Complex>();
    for (Eigen::Index v = 0; v < vertices.cols(); ++v)
    {
      const Eigen::Matrix<Complex, 3, 1> p0 = vertices.col(v).cast<Complex>();
      double* J = out + 18 * v;
      for (int k = 0; k < 3; ++k)
      {
        const Eigen::Matrix<Complex, 3, 1> p = Rc[k] * p0 + t;
        J[k] = p[0].imag() / h;
        J[6 + k] = p[1].imag() / h;
        J[12 + k] = p[2].imag() / h;
      }
      // d/dt of R p0 + t by the complex step is exactly e_k.
      J[3] = 1, J[4] = 0, J[5] = 0, J[9] = 0, J[10] = 1, J[11] = 0, J[15] = 0, J[16] = 0, J[17] = 1;
    }
  }
};

// ---------------------------------------------------------------------------
// Backprop by forming J and multiplying.

/// J_i formed per vertex (in registers) and J_i^T g_i accumulated.
inline Vector6d backpropFormJ(const drb::BodyPose<double>& pose, const Matrix3Xd& vertices, const double* g)
{
  Vector6d sum = Vector6d::Zero();
  for (Eigen::Index v = 0; v < vertices.cols(); ++v)
  {
    const drb::Matrix36<double> J = drb::vertexJacobian(pose, Eigen::Vector3d(vertices.col(v)));
    sum.noalias() += J.transpose() * Eigen::Map<const Eigen::Vector3d>(g + 3 * v);
  }
  return sum;
}

/// All J written to a buffer (as get_vertex_jacobians returns them), then
/// multiplied: what a client of that service does.
inline Vector6d backpropViaBuffer(const drb::BodyPose<double>& pose, const Matrix3Xd& vertices, const double* g,
                                  double* buffer)
{
  drb::vertexPositionsAndJacobians<double>(pose, vertices, {}, nullptr, buffer);
  Vector6d sum = Vector6d::Zero();
  for (Eigen::Index v = 0; v < vertices.cols(); ++v)
  {
    const Eigen::Map<const Eigen::Matrix<double, 3, 6, Eigen::RowMajor>> J(buffer + 18 * v);
    sum.noalias() += J.transpose() * Eigen::Map<const Eigen::Vector3d>(g + 3 * v);
  }
  return sum;
}

}  // namespace drb_bench
