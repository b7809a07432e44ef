// No heap allocation per query in steady state: every SceneQueries call the
// node serves (M, dM/dx, J, compact J, backprop, inverse and forward
// dynamics with derivatives, link poses for tf) on the Panda, after one
// warm-up call on the same thread with the same output buffers, allocates
// nothing. The count comes from this binary's global operator new, which
// counts while a test has it switched on.
#include <atomic>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body/parsers/urdf_scene.h"

namespace
{
std::atomic<bool> counting{ false };
std::atomic<long> allocations{ 0 };
}  // namespace

void* operator new(std::size_t size)
{
  if (counting.load(std::memory_order_relaxed))
    allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size ? size : 1))
    return p;
  throw std::bad_alloc();
}

void operator delete(void* p) noexcept
{
  std::free(p);
}

void operator delete(void* p, std::size_t) noexcept
{
  std::free(p);
}

namespace
{
namespace drb = diff_rigid_body;

const std::string kRobots = std::string(DRB_TEST_DATA_DIR) + "/robots/drb_example_robot_data";

/// Allocations made by `call` (run once before, to warm up its buffers).
template <typename Call>
long allocationsOf(Call&& call)
{
  call();
  allocations = 0;
  counting = true;
  call();
  counting = false;
  return allocations.load();
}

class Allocations : public ::testing::Test
{
protected:
  Allocations()
    : queries_(drb::loadSceneFromUrdfFile(kRobots + "/robots/panda_description/urdf/panda.urdf", options()))
    , current_(queries_.initialState())
    , body_(queries_.body(0).name)
    , names_{ body_ }
  {
    const std::size_t d = queries_.dofs(0);
    for (std::size_t k = 0; k < 3 * d; ++k)  // three configurations
    {
      q_.push_back(0.1 * double(k % d) - 0.3);
      qdot_.push_back(0.2 - 0.05 * double(k % 7));
    }
    gradients_.assign(3 * 3 * queries_.body(0).vertexCount(), 0.25);
  }

  static drb::SceneOptions options()
  {
    drb::SceneOptions options;
    options.find_package = [](const std::string&) { return kRobots; };
    return options;
  }

  drb::SceneQueries queries_;
  drb::SceneState current_;
  std::string body_;
  std::vector<std::string> names_;
  std::vector<double> q_, qdot_, gradients_;
};
}  // namespace

TEST_F(Allocations, MassMatricesAndDerivatives)
{
  drb::MassMatrixAnswer answer;
  EXPECT_EQ(allocationsOf([&] { queries_.massMatrices(current_, names_, q_, false, answer); }), 0);
  EXPECT_EQ(allocationsOf([&] { queries_.massMatrices(current_, names_, q_, true, answer); }), 0);
  EXPECT_EQ(allocationsOf([&] { queries_.massMatrices(current_, {}, {}, true, answer); }), 0);
}

TEST_F(Allocations, VertexJacobiansAndBackprop)
{
  std::vector<double> positions, jacobians, gradient;
  std::vector<float> positions32, jacobians32;
  const std::vector<std::uint32_t> some{ 3, 500, 17, 1100 };
  EXPECT_EQ(allocationsOf([&] { queries_.vertexJacobians(current_, body_, {}, q_, positions, jacobians); }), 0);
  EXPECT_EQ(allocationsOf([&] { queries_.vertexJacobians(current_, body_, some, {}, positions, jacobians); }), 0);
  EXPECT_EQ(allocationsOf([&] {
              queries_.vertexRotationJacobians<float>(current_, body_, {}, q_, false, positions32, jacobians32);
            }),
            0);
  EXPECT_EQ(allocationsOf([&] { queries_.backpropConfigurations(current_, body_, {}, gradients_, q_, gradient); }), 0);
}

TEST_F(Allocations, InverseAndForwardDynamicsWithDerivatives)
{
  drb::InverseDynamicsAnswer inverse;
  drb::ForwardDynamicsAnswer forward;
  EXPECT_EQ(allocationsOf([&] { queries_.inverseDynamics(current_, names_, q_, qdot_, qdot_, true, true, inverse); }),
            0);
  EXPECT_EQ(allocationsOf([&] { queries_.forwardDynamics(current_, names_, q_, qdot_, qdot_, true, forward); }), 0);
}

TEST_F(Allocations, FrameJacobiansAndCenterOfMass)
{
  drb::FrameJacobianAnswer frames;
  drb::CenterOfMassAnswer com;
  const std::vector<std::string> tip{ queries_.body(0).links.back().name };
  EXPECT_EQ(allocationsOf([&] { queries_.frameJacobians(current_, body_, tip, q_, {}, 2, false, frames); }), 0);
  EXPECT_EQ(allocationsOf([&] { queries_.frameJacobians(current_, body_, {}, q_, qdot_, 0, true, frames); }), 0);
  EXPECT_EQ(allocationsOf([&] { queries_.centerOfMass(current_, names_, q_, qdot_, true, com); }), 0);
}

TEST_F(Allocations, LinkPosesForTf)
{
  std::vector<Eigen::Isometry3d> poses;
  const Eigen::VectorXd x = current_[0];
  EXPECT_EQ(allocationsOf([&] { queries_.linkPoses(0, x, poses); }), 0);
}

TEST_F(Allocations, CounterSeesAnAllocation)  // the check above can fail
{
  EXPECT_GT(allocationsOf([] { std::vector<double>* v = new std::vector<double>(10); delete v; }), 0);
}
