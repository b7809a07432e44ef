// Articulated bodies (docs/interface.md, "Version 2") against MuJoCo loading the
// same URDF text (test/support/mujoco_model.h): the floating-base tree of
// articulated_fixtures.h, which KDL cannot check (no floating joint), and
// the UR5 (fixed base). MuJoCo refuses a massless body that has a joint, so
// the tree's wrist gets a mass here (treeUrdf); we load that same text.
//
// MuJoCo's coordinates differ from ours:
//   - the floating root is a free joint: qpos = (o, quaternion of R) with o
//     the root body's origin (its link frame: MuJoCo keeps the URDF link
//     frame as the body frame, the COM at body_ipos), qvel = (do/dt in
//     world axes, w_body = R^T w in body axes); ours x = (phi, theta, psi, t)
//     with t the root COM. With c = the root COM in its link frame (torso
//     and the head fused to it), o = t - R c, so
//         do/dt  = tdot + w x (o - t) = tdot + [R c]x T rdot,
//         w_body = R^T T rdot              (w = T rdot, R = Rz Ry Rx);
//   - MuJoCo ignores <mimic>: the mimic knee is a joint of its own there,
//     set to multiplier x[master] + offset; the prismatic slider is a
//     slide joint.
// So qvel = A xdot (joint rows: the multiplier at the master's column,
// matched by name) and, the kinetic energy being the same, M = A^T M_mj A.
// R, T and the joint drives come from the oracles (kinematics_oracles.h,
// articulated_oracles.h: urdfdom's mimic map), not from the kernels.
// Checked: the free joint's body, mass and COM; qvel = A xdot against
// MuJoCo's own differentiation of its qpos; M at random configurations, the
// limits and pitch 1e-3 from +-pi/2. Errors are relative to max|M|.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "../support/articulated_fixtures.h"
#include "../support/body_models.h"
#include "../support/mujoco_model.h"

namespace drb = diff_rigid_body;
using namespace drb_test;
using namespace drb_test::articulated;

namespace
{
// Floating tree: MuJoCo's compiler replaces each body's inertia tensor by
// its principal moments and axes (body_inertia, body_iquat, from an
// iterative eigen-solver) and mj_crb rebuilds the tensor from them; our
// kernel uses the tensor as written. For the full tensors of the torso (with
// the head fused), the left thigh and the wrist the rebuilt tensor differs
// by 7e-10 .. 5e-9 of the body's largest entry, which is 1.4e-10 of max|M|
// (measured, 27 configurations). Tolerance 1e-9. With MuJoCo's rebuilt
// tensors in our body (withMujocoInertias) the rest agrees to rounding:
// measured 0.84 eps of max|M|, tolerance 8 eps.
constexpr double kTreeTol = 1e-9;
constexpr double kSameInertiaTol = 8 * kEps;
// UR5: diagonal inertias, nothing to rebuild: two O(depth) sums of rounded
// products. Measured 7.7 eps of max|M| (45 configurations; the benchmark
// measured 8 eps on 256). Tolerance 16 eps.
constexpr double kUr5Tol = 16 * kEps;
// MuJoCo's qvel by central differences of its qpos (mj_differentiatePos),
// step h = 1e-6: truncation ~h^2, rounding ~eps/h. Measured 2.5e-10
// relative. Tolerance 1e-8.
constexpr double kQvelStep = 1e-6;
constexpr double kQvelTol = 1e-8;

const LoadedBody& ur5()
{
  for (const LoadedBody& b : loadedBodies())
    if (b.name == "ur5")
      return b;
  throw std::runtime_error("no fixture ur5");
}

/// The floating tree with a mass on its wrist: MuJoCo refuses a massless
/// body with a joint ("mass and inertia of moving bodies must be larger
/// than mjMINVAL"). A full tensor, off the joint axis, tilted.
std::string treeUrdf()
{
  const std::string wrist = drb_test::urdf::link("wrist");
  std::string xml = floatingTreeUrdf();
  const std::size_t at = xml.find(wrist);
  if (at == std::string::npos)
    throw std::runtime_error("the floating tree has no massless wrist link");
  return xml.replace(at, wrist.size(),
                     drb_test::urdf::link("wrist", drb_test::urdf::inertial("0.3", { "0.002", "0.0003", "-0.0002", "0.0015", "0.0001", "0.001" },
                                                        "<origin xyz=\"0.02 0.01 -0.01\" rpy=\"0.3 -0.1 0.5\"/>")));
}

/// treeUrdf() loaded by us in model mode, with its URDF model.
const LoadedBody& tree()
{
  static const LoadedBody b = [] {
    const std::string xml = treeUrdf();
    const drb::Scene scene = drb::loadSceneFromUrdf(xml, robotOptions(drb::JointHandling::Model));
    return LoadedBody{ "floating_tree (wrist with mass)", "", bodyModel(xml, "torso"), bodyRootedAt(scene, "torso") };
  }();
  return b;
}

/// MuJoCo's free joint and its body (the floating root), or (-1, -1).
std::pair<int, int> freeJoint(const mujoco::Model& mj)
{
  const mjModel& m = mj.model();
  for (int j = 0; j < m.njnt; ++j)
    if (m.jnt_type[j] == mjJNT_FREE)
      return { j, m.jnt_bodyid[j] };
  return { -1, -1 };
}

/// The root COM c in its link frame, as MuJoCo compiled it.
Eigen::Vector3d rootCom(const mujoco::Model& mj)
{
  const mjtNum* c = mj.model().body_ipos + 3 * freeJoint(mj).second;
  return Eigen::Vector3d(c[0], c[1], c[2]);
}

/// MuJoCo's qpos at our x.
Eigen::VectorXd qposAt(const mujoco::Model& mj, const BodyModel& b, const Eigen::VectorXd& x)
{
  const mjModel& m = mj.model();
  Eigen::VectorXd qpos = Eigen::VectorXd::Zero(m.nq);
  for (int j = 0; j < m.njnt; ++j)
  {
    const int adr = m.jnt_qposadr[j];
    if (m.jnt_type[j] == mjJNT_FREE)
    {
      const Eigen::Matrix3d R = refRotation(x[0], x[1], x[2]);
      const Eigen::Quaterniond q(R);
      qpos.segment<3>(adr) = x.segment<3>(3) - R * rootCom(mj);
      qpos.segment<4>(adr + 3) << q.w(), q.x(), q.y(), q.z();
      continue;
    }
    const Drive& d = b.drives.at(mj_id2name(&m, mjOBJ_JOINT, j));
    qpos[adr] = d.multiplier * x[d.coordinate] + d.offset;
  }
  return qpos;
}

/// A (nv x dofs) with qvel = A xdot at x (see the file comment).
Eigen::MatrixXd qvelMap(const mujoco::Model& mj, const BodyModel& b, const Eigen::VectorXd& x)
{
  const mjModel& m = mj.model();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(m.nv, static_cast<Eigen::Index>(b.dofs()));
  for (int j = 0; j < m.njnt; ++j)
  {
    const int dof = m.jnt_dofadr[j];
    if (m.jnt_type[j] == mjJNT_FREE)
    {
      const Eigen::Matrix3d R = refRotation(x[0], x[1], x[2]);
      const Eigen::Matrix3d T = refAngularVelocityMatrix(x[0], x[1], x[2]);
      A.block<3, 3>(dof, 0) = skew(Eigen::Vector3d(R * rootCom(mj))) * T;
      A.block<3, 3>(dof, 3).setIdentity();
      A.block<3, 3>(dof + 3, 0) = R.transpose() * T;
      continue;
    }
    const Drive& d = b.drives.at(mj_id2name(&m, mjOBJ_JOINT, j));
    A(dof, d.coordinate) = d.multiplier;
  }
  return A;
}

/// max|A^T M_mj A - M| / max|M| over `xs`, asserting each against `tol`.
double compareMassMatrices(const drb::BodyModel& body, const BodyModel& model, mujoco::Model& mj,
                           const std::vector<std::pair<std::string, Eigen::VectorXd>>& xs, double tol,
                           const char* why)
{
  MaxTracker err;
  for (const auto& [label, x] : xs)
  {
    const Eigen::VectorXd qpos = qposAt(mj, model, x);
    Eigen::Map<Eigen::VectorXd>(mj.data().qpos, mj.model().nq) = qpos;
    const Eigen::MatrixXd A = qvelMap(mj, model, x);
    const Eigen::MatrixXd M_mj = A.transpose() * mj.massMatrix() * A;
    const Eigen::MatrixXd M = drb_test::core_body::massMatrixAt(body, x.data());
    const double e = maxAbs(M - M_mj) / maxAbs(M);
    err.update(e);
    EXPECT_LE(e, tol) << body.name << ", " << label << ": A^T M_mujoco A differs from M by more than " << why
                      << "\nx = " << row(x) << "\nM =\n" << M << "\nA^T M_mujoco A =\n" << M_mj;
  }
  return err.value;
}

/// A copy of `body` with each segment's inertia about its COM replaced by
/// MuJoCo's compiled one: body_iquat diag(body_inertia) body_iquat^T, the
/// segment matched by its link's name (MuJoCo fuses the same links).
drb::BodyModel withMujocoInertias(const drb::BodyModel& body, const mujoco::Model& mj)
{
  const mjModel& m = mj.model();
  drb::BodyModel copy = body;
  for (drb::Segment& s : copy.segments)
  {
    const int id = mj.body(s.link);
    if (id < 0)
      throw std::runtime_error("MuJoCo has no body " + s.link);
    const mjtNum* q = m.body_iquat + 4 * id;
    const Eigen::Matrix3d Ri = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
    s.inertia.inertia = Ri * Eigen::Vector3d(m.body_inertia + 3 * id).asDiagonal() * Ri.transpose();
  }
  return copy;
}

/// The fixture's labelled configurations, plus (floating root) pitch 1e-3
/// from +-pi/2, where T is nearly singular.
std::vector<std::pair<std::string, Eigen::VectorXd>> testConfigurations(const LoadedBody& b, Random& rng, int random)
{
  auto xs = configurations(b.model, rng, random);
  if (b.model.floating_root)
    for (const double theta : { kHalfPi - 1e-3, -kHalfPi + 1e-3 })
    {
      Eigen::VectorXd x = xs.back().second;
      x[1] = theta;
      xs.emplace_back("pitch " + std::to_string(theta), x);
    }
  return xs;
}

}  // namespace

TEST(ArticulatedMujoco, FloatingTreeRootIsAFreeJointOnTheTorsoLinkFrame)
{
  const LoadedBody& b = tree();
  const mujoco::Model mj(treeUrdf());
  const mjModel& m = mj.model();
  const auto [free_joint, root] = freeJoint(mj);
  ASSERT_GE(free_joint, 0) << "MuJoCo gave the floating torso no free joint";
  EXPECT_EQ(std::string(mj_id2name(&m, mjOBJ_BODY, root)), "torso");
  // One free joint (6 dofs) and one MuJoCo joint per 1-dof URDF joint, the mimic knee included.
  EXPECT_EQ(m.njnt, 1 + static_cast<int>(b.model.drives.size()));
  EXPECT_EQ(m.nv, 6 + static_cast<int>(b.model.drives.size()));
  // The torso body: torso and head fused; its frame is the torso link frame
  // iff its COM there is the one we compute.
  const drb::MassProperties& ours = b.body().segments.front().inertia;
  const Eigen::Vector3d our_com = b.body().rootComOffset();
  EXPECT_NEAR(m.body_mass[root], ours.mass, 4 * kEps * ours.mass) << "torso + head mass";
  EXPECT_LE((rootCom(mj) - our_com).norm(), 4 * kEps) << "root COM in the torso link frame: MuJoCo "
                                                        << row(rootCom(mj)) << ", ours " << row(our_com);
}

TEST(ArticulatedMujoco, QvelMapIsTheDerivativeOfMujocosQpos)
{
  // qvel = A xdot against mj_differentiatePos of qpos(x -+ h xdot): checks
  // MuJoCo's free-joint velocity convention (origin velocity in world axes,
  // angular velocity in body axes) and the mimic and slide rows.
  const LoadedBody& b = tree();
  const mujoco::Model mj(treeUrdf());
  Random rng(1291);
  MaxTracker err;
  for (const auto& [label, x] : testConfigurations(b, rng, 10))
  {
    Eigen::VectorXd xdot(x.size());
    for (Eigen::Index i = 0; i < x.size(); ++i)
      xdot[i] = rng.uniform(-1, 1);
    const Eigen::VectorXd minus = qposAt(mj, b.model, x - kQvelStep * xdot), plus = qposAt(mj, b.model, x + kQvelStep * xdot);
    Eigen::VectorXd qvel(mj.model().nv);
    mj_differentiatePos(&mj.model(), qvel.data(), 2 * kQvelStep, minus.data(), plus.data());
    const Eigen::VectorXd predicted = qvelMap(mj, b.model, x) * xdot;
    const double e = maxAbs(qvel - predicted) / maxAbs(predicted);
    err.update(e);
    EXPECT_LE(e, kQvelTol) << label << ": central difference of MuJoCo's qpos vs A xdot\nx = " << row(x)
                           << "\nxdot = " << row(xdot) << "\ndifference " << row(qvel) << "\nA xdot     "
                           << row(predicted);
  }
  std::printf("[measured] floating_tree: qvel by central differences vs A xdot: %.3g relative\n", err.value);
}

TEST(ArticulatedMujoco, FloatingTreeMassMatrixMatchesMujoco)
{
  const LoadedBody& b = tree();
  mujoco::Model mj(treeUrdf());
  Random rng(1292);
  const auto xs = testConfigurations(b, rng, 20);
  const double e = compareMassMatrices(b.body(), b.model, mj, xs, kTreeTol,
                                       "kTreeTol (MuJoCo re-diagonalises the full inertia tensors)");
  // With MuJoCo's compiled inertias in our body the rest agrees to rounding.
  const double e_same = compareMassMatrices(withMujocoInertias(b.body(), mj), b.model, mj, xs, kSameInertiaTol,
                                            "kSameInertiaTol (rounding; same inertia tensors on both sides)");
  std::printf("[measured] floating_tree: M vs MuJoCo A^T M A: %.3g of max|M|; with MuJoCo's inertias: %.3g eps\n", e,
              e_same / kEps);
}

TEST(ArticulatedMujoco, Ur5MassMatrixMatchesMujoco)
{
  const LoadedBody& b = ur5();
  mujoco::Model mj(readText(fixedBaseFixtures().front().path));
  ASSERT_EQ(mj.model().nv, static_cast<int>(b.model.dofs())) << "UR5: one MuJoCo dof per joint";
  Random rng(1293);
  const double e =
      compareMassMatrices(b.body(), b.model, mj, testConfigurations(b, rng, 40), kUr5Tol, "kUr5Tol (rounding of two O(depth) sums)");
  std::printf("[measured] ur5: M vs MuJoCo A^T M A: %.3g eps of max|M|\n", e / kEps);
}
