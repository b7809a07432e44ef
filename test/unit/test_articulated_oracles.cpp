// Articulated bodies (docs/interface.md, "Version 2") against independent oracles,
// on the fixture robots (UR5, the three double pendulums, the Panda with its
// mimic fingers) and a floating-base tree (two legs, a mimic knee, a
// prismatic slider, a massless wrist):
//   - the coordinates (joint names, limits) are the URDF's, in document order;
//   - M against KDL: TreeIdSolver_RNE on the whole tree, column by column
//     (qdd = e_i, qdot = 0, g = 0), contracted with the mimic map
//     (M = P^T M_kdl P), and ChainDynParam::JntToMass on the chains that
//     carry all of the body's mass;
//   - M against the kinetic energy of the links, from an independent forward
//     kinematics and central differences (articulated_oracles.h);
//   - dM/dx and dp/dx against the complex step through the templated
//     kernels; backprop against J^T g with the complex-step J.
// Errors are relative to the largest entry of the compared matrix.
#include <cmath>
#include <complex>
#include <cstdio>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "../support/articulated_fixtures.h"
#include "../support/body_models.h"

namespace drb = diff_rigid_body;
using namespace drb_test;
using namespace drb_test::articulated;
using drb_test::core_body::massMatrixAt;

namespace
{
// KDL (double) vs crba (double): two O(depth) sums of
// rounded products; each is a few eps of max|M| from the exact M.
// Measured: 3.7 eps (RNE, Panda), 4.3 eps (ChainDynParam). 16 eps.
constexpr double kKdlTol = 16 * kEps;
// Central differences of link poses, h = 1e-5: truncation h^2/6 |p'''| ~
// 2e-11 m per m of reach, rounding eps |p| / h ~ 2e-11; squared in 2T and
// polarised. Measured 2e-10 of max|M| (M) and 4.1e-10 relative (2T);
// 1e-8 of max|M| (and of xdot^T M xdot for 2T).
constexpr double kFdStep = 1e-5;
constexpr double kFdTol = 1e-8;
// Complex step vs exact-to-rounding derivatives: a few eps of the largest
// entry. Measured: J 2.2 eps. 8 eps.
constexpr double kComplexStepTol = 8 * kEps;
// Positions against the independent forward kinematics: Eigen's AngleAxis
// against the kernel's Rodrigues, depth up to 9 products of O(1) matrices,
// relative to max(1 m, |p|). Measured 1.3 eps. 8 eps.
constexpr double kPositionTol = 8 * kEps;

using MatrixXc = Eigen::Matrix<Complex, Eigen::Dynamic, Eigen::Dynamic>;

Eigen::MatrixXd massMatrix(const drb::BodyModel& body, const Eigen::VectorXd& x)
{
  return massMatrixAt(body, x.data());
}

/// x + i h e_j.
Eigen::VectorXcd complexStepped(const Eigen::VectorXd& x, Eigen::Index j)
{
  Eigen::VectorXcd xc = x.cast<Complex>();
  xc[j] += Complex(0.0, kComplexStepH);
  return xc;
}

Eigen::VectorXd randomVector(Random& rng, Eigen::Index n)
{
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i)
    v[i] = rng.uniform(-1.0, 1.0);
  return v;
}

/// Every k-th vertex of the body (and its last), so that each segment is sampled.
std::vector<std::uint32_t> sampledVertices(const drb::BodyModel& body, std::uint32_t k)
{
  std::vector<std::uint32_t> vertices;
  const auto n = static_cast<std::uint32_t>(body.vertices.cols());
  for (std::uint32_t v = 0; v < n; v += k)
    vertices.push_back(v);
  for (const drb::Segment& s : body.segments)
    if (s.vertex_count > 0)
      vertices.push_back(s.vertex_begin + s.vertex_count - 1);
  return vertices;
}
}  // namespace

TEST(ArticulatedOracles, CoordinatesAreTheUrdfJointsInDocumentOrder)
{
  for (const LoadedBody& b : loadedBodies())
  {
    const drb::BodyModel& body = b.body();
    EXPECT_EQ(body.hasFreeRoot(), b.model.floating_root) << b.name;
    EXPECT_EQ(body.joint_names, b.model.joint_names) << b.name;
    EXPECT_EQ(body.joint_lower, b.model.lower) << b.name;
    EXPECT_EQ(body.joint_upper, b.model.upper) << b.name;
    ASSERT_EQ(body.coordinates, b.model.dofs()) << b.name;
    double mass = 0;
    for (const auto& link : b.model.links)
      mass += linkMass(*link).mass;
    EXPECT_NEAR(body.mass(), mass, 4 * kEps * mass) << b.name << ": total mass";
  }
}

TEST(ArticulatedOracles, MassMatrixMatchesKdlTreeRne)
{
  Random rng(1201);
  for (const LoadedBody& b : loadedBodies())
  {
    if (b.model.floating_root)
      continue;  // KDL has no floating joint
    const KdlOracle kdl(b.model);
    MaxTracker err;
    for (const auto& [label, x] : configurations(b.model, rng, 40))
    {
      const Eigen::MatrixXd M = massMatrix(b.body(), x), M_kdl = kdl.massMatrix(x);
      const double e = maxAbs(M - M_kdl) / maxAbs(M_kdl);
      err.update(e);
      ASSERT_LE(e, kKdlTol) << b.name << ", " << label << ", x = " << row(x) << "\nM =\n" << M << "\nKDL (RNE, P^T M P) =\n"
                            << M_kdl;
    }
    std::printf("[measured] %s: M vs KDL TreeIdSolver_RNE (P^T M_kdl P): %.3g eps of max|M|\n", b.name.c_str(),
                err.value / kEps);
  }
}

TEST(ArticulatedOracles, MassMatrixMatchesKdlChainDynParamOnChainsCarryingAllTheMass)
{
  Random rng(1202);
  for (const LoadedBody& b : loadedBodies())
  {
    if (b.tip.empty())
      continue;  // the Panda: no chain carries both fingers
    const KdlOracle kdl(b.model);
    MaxTracker err;
    for (const auto& [label, x] : configurations(b.model, rng, 40))
    {
      double chain_mass = 0;
      const Eigen::MatrixXd M = massMatrix(b.body(), x);
      const Eigen::MatrixXd M_kdl = kdl.chainMassMatrix(b.model.links.front()->parent_joint->parent_link_name, b.tip, x,
                                                        &chain_mass);
      // The chain (the segments after its root, the static parent) carries every moving link's mass.
      double moving_mass = 0;
      for (const auto& link : b.model.links)
        moving_mass += linkMass(*link).mass;
      ASSERT_NEAR(chain_mass, moving_mass, 1e-12 * moving_mass) << b.name << ": the chain misses links";
      const double e = maxAbs(M - M_kdl) / maxAbs(M_kdl);
      err.update(e);
      ASSERT_LE(e, kKdlTol) << b.name << ", " << label << ", x = " << row(x) << "\nM =\n" << M
                            << "\nKDL ChainDynParam =\n" << M_kdl;
    }
    std::printf("[measured] %s: M vs KDL ChainDynParam::JntToMass: %.3g eps of max|M|\n", b.name.c_str(),
                err.value / kEps);
  }
}

TEST(ArticulatedOracles, MassMatrixIsTheKineticEnergyOfTheLinks)
{
  Random rng(1203);
  for (const LoadedBody& b : loadedBodies())
  {
    MaxTracker err_M, err_T;
    for (const auto& [label, x] : configurations(b.model, rng, 6))
    {
      const Eigen::MatrixXd M = massMatrix(b.body(), x);
      const Eigen::MatrixXd M_fd = finiteDifferenceMassMatrix(b.model, x, kFdStep);
      const double e = maxAbs(M - M_fd) / maxAbs(M);
      err_M.update(e);
      ASSERT_LE(e, kFdTol) << b.name << ", " << label << ", x = " << row(x) << "\nM =\n" << M << "\nfrom 2T =\n" << M_fd;
      for (int k = 0; k < 3; ++k)
      {
        const Eigen::VectorXd xdot = randomVector(rng, x.size());
        const double two_T = twiceKineticEnergy(b.model, x, xdot, kFdStep), quad = xdot.dot(M * xdot);
        const double e_T = std::abs(quad - two_T) / quad;
        err_T.update(e_T);
        ASSERT_LE(e_T, kFdTol) << b.name << ", " << label << ", x = " << row(x) << ", xdot = " << row(xdot)
                               << ": x'^T M x' = " << quad << ", 2T = " << two_T;
      }
    }
    std::printf("[measured] %s: M vs 2T by central differences: %.3g of max|M|; x'^T M x' vs 2T: %.3g relative\n",
                b.name.c_str(), err_M.value, err_T.value);
  }
}

TEST(ArticulatedOracles, MassMatrixDerivativesMatchComplexStep)
{
  Random rng(1204);
  for (const LoadedBody& b : loadedBodies())
  {
    MaxTracker err;
    for (const auto& [label, x] : configurations(b.model, rng, 10))
    {
      const std::vector<Eigen::MatrixXd> dM = drb_test::core_body::massMatrixDerivativesAt(b.body(), x.data());
      ASSERT_EQ(dM.size(), b.body().coordinates) << b.name;
      double scale = 0;
      for (const auto& d : dM)
        scale = std::max(scale, maxAbs(d));
      for (Eigen::Index j = 0; j < x.size(); ++j)
      {
        const Eigen::VectorXcd xc = complexStepped(x, j);
        const MatrixXc Mc = massMatrixAt(b.body(), xc.data());
        const Eigen::MatrixXd dM_cs = Mc.imag() / kComplexStepH;
        // Relative to the larger of max|dM| over all j and max|M| (the
        // pendulums' M does not depend on their first joint: dM/dx_0 = 0).
        const double e = maxAbs(dM[j] - dM_cs) / std::max(scale, maxAbs(Mc.real()));
        err.update(e);
        ASSERT_LE(e, kComplexStepTol) << b.name << ", " << label << ", x = " << row(x) << ", d/dx_" << j
                                      << "\ndM/dx =\n" << dM[j] << "\ncomplex step =\n" << dM_cs;
      }
    }
    std::printf("[measured] %s: dM/dx vs complex step: %.3g eps of max|dM|\n", b.name.c_str(), err.value / kEps);
  }
}

TEST(ArticulatedOracles, VertexJacobiansMatchComplexStepAndForwardKinematics)
{
  Random rng(1205);
  for (const LoadedBody& b : loadedBodies())
  {
    const drb::BodyModel& body = b.body();
    const std::vector<std::uint32_t> vertices = sampledVertices(body, 37);
    ASSERT_GT(vertices.size(), 0u) << b.name;
    const Eigen::Index n = static_cast<Eigen::Index>(body.coordinates), nv = static_cast<Eigen::Index>(vertices.size());
    MaxTracker err_J, err_p;
    for (const auto& [label, x] : configurations(b.model, rng, 5))
    {
      std::vector<double> positions(3 * nv), jacobians(3 * nv * n);
      drb_test::core_body::vertexJacobiansAt(body, false, vertices, x.data(), positions.data(), jacobians.data());
      // Positions: the link poses of the independent forward kinematics.
      std::map<std::string, Eigen::Isometry3d> link_pose;
      const auto poses = linkPoses(b.model, x);
      for (std::size_t i = 0; i < poses.size(); ++i)
        link_pose[b.model.links[i]->name] = poses[i];
      for (Eigen::Index i = 0; i < nv; ++i)
      {
        const std::uint32_t v = vertices[i];
        const Eigen::Vector3d p =
            link_pose.at(body.segments[body.segmentOfVertex(v)].link) * drb_test::core_body::vertexInLinkFrame(body, v);
        const double e = (Eigen::Map<const Eigen::Vector3d>(&positions[3 * i]) - p).cwiseAbs().maxCoeff() /
                         std::max(1.0, p.cwiseAbs().maxCoeff());
        err_p.update(e);
        ASSERT_LE(e, kPositionTol) << b.name << ", " << label << ", vertex " << v << ", x = " << row(x);
      }
      // Jacobians: column j by the complex step of forwardKinematics<complex>.
      Eigen::MatrixXd J_cs(3 * nv, n);
      for (Eigen::Index j = 0; j < n; ++j)
      {
        const Eigen::VectorXcd xc = complexStepped(x, j);
        const drb::BodyWorkspace<Complex> pose = drb_test::core_body::kinematicsAt(body, xc.data());
        for (Eigen::Index i = 0; i < nv; ++i)
          J_cs.block(3 * i, j, 3, 1) =
              drb_test::core_body::vertexPosition(body, pose, vertices[i]).imag() / kComplexStepH;
      }
      const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(
          jacobians.data(), 3 * nv, n);
      const double e = maxAbs(J - J_cs) / maxAbs(J_cs);
      err_J.update(e);
      ASSERT_LE(e, kComplexStepTol) << b.name << ", " << label << ", x = " << row(x) << "\nJ =\n" << J
                                    << "\ncomplex step =\n" << J_cs;
      // Selected columns (the compact transport drops a floating root's
      // translation columns): the same bits as those columns of J.
      std::vector<int> columns;
      for (int c = 0; c < n; ++c)
        if (!body.hasFreeRoot() || c < 3 || c > 5)
          columns.push_back(c);
      const drb::JacobianColumns compact_columns = drb::JacobianColumns::compact(body);
      ASSERT_EQ(compact_columns.width, columns.size()) << b.name;
      for (std::size_t c = 0; c < columns.size(); ++c)
        ASSERT_EQ(compact_columns.of_coordinate[columns[c]], static_cast<int>(c))
            << b.name << ", column " << columns[c];
      std::vector<double> compact(3 * nv * columns.size()), unused(3 * nv);
      drb_test::core_body::vertexJacobiansAt(body, true, vertices, x.data(), unused.data(), compact.data());
      for (Eigen::Index i = 0; i < 3 * nv; ++i)
        for (std::size_t c = 0; c < columns.size(); ++c)
          ASSERT_EQ(compact[i * columns.size() + c], J(i, columns[c]))
              << b.name << ", " << label << ": row " << i << ", column " << columns[c] << " of the selected columns";
      // Backprop: sum_v J_v^T g_v with the complex-step J.
      const Eigen::VectorXd g = randomVector(rng, 3 * nv);
      Eigen::VectorXd grad(n);
      drb_test::core_body::backpropAt(body, vertices, g.data(), x.data(), grad.data());
      const Eigen::VectorXd expected = J_cs.transpose() * g;
      const double scale = (J_cs.cwiseAbs().transpose() * g.cwiseAbs()).maxCoeff();
      const double e_b = maxAbs(grad - expected) / scale;
      ASSERT_LE(e_b, kComplexStepTol * std::sqrt(double(nv))) << b.name << ", " << label << ", x = " << row(x)
                                                              << "\nbackprop " << row(grad) << "\nJ^T g " << row(expected);
    }
    std::printf("[measured] %s: J vs complex step %.3g eps; positions vs independent FK %.3g eps\n", b.name.c_str(),
                err_J.value / kEps, err_p.value / kEps);
  }
}
