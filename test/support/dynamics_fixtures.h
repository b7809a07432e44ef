// Bodies and motions for the dynamics tests: the fixed-base fixtures and the
// floating tree of articulated_fixtures.h, the floating 35-coordinate
// simple_humanoid, and an asymmetric free object; random states
// (x, x', x'') and generalized forces, fixed seed.
#pragma once

#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "diff_rigid_body/parsers/urdf_scene.h"
#include "articulated_fixtures.h"
#include "urdf_builders.h"

namespace drb_test
{
namespace dynamics
{
namespace drb = diff_rigid_body;

const std::string kHumanoid = articulated::kErd + "/simple_humanoid_description/urdf/simple_humanoid.urdf";

/// simple_humanoid with its waist floating: BODY is a free root with the 29
/// revolute joints below it, 35 coordinates.
inline std::string floatingHumanoidUrdf()
{
  std::string text = articulated::readText(kHumanoid);
  const std::string fixed = "<joint name=\"waist\" type=\"fixed\">";
  text.replace(text.find(fixed), fixed.size(), "<joint name=\"waist\" type=\"floating\">");
  return text;
}

/// A free box with a full inertia tensor (unequal principal moments, axes
/// turned from the link's), its COM off the link origin.
inline std::string asymmetricFreeBodyUrdf()
{
  using namespace urdf;
  return robot(link("brick", inertial("2.5", { "0.3", "0.02", "-0.04", "0.2", "0.05", "0.1" },
                                      "<origin xyz=\"0.05 -0.02 0.1\" rpy=\"0.3 -0.2 0.7\"/>") +
                                 collision(boxGeometry("0.4 0.3 0.2"))) +
               floatingJoint("brick", "<origin xyz=\"1 2 3\" rpy=\"0.1 0.2 0.3\"/>"));
}

struct DynamicsBody
{
  std::string name;
  drb::Scene scene;  ///< bodies[index] is the body under test
  std::size_t index = 0;
  const drb::BodyModel& model() const { return scene.bodies[index]; }
};

inline std::size_t indexOf(const drb::Scene& scene, const std::string& root)
{
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    if (scene.bodies[i].name == root)
      return i;
  throw std::runtime_error("no body " + root);
}

/// Every dynamics fixture, loaded once in model mode.
inline const std::vector<DynamicsBody>& dynamicsBodies()
{
  static const std::vector<DynamicsBody> bodies = [] {
    const drb::SceneOptions options = articulated::robotOptions(drb::JointHandling::Model);
    std::vector<DynamicsBody> out;
    for (const articulated::Fixture& f : articulated::fixedBaseFixtures())
    {
      drb::Scene scene = drb::loadSceneFromUrdfFile(f.path, options);
      const std::size_t index = indexOf(scene, f.root);
      out.push_back({ f.name, std::move(scene), index });
    }
    out.push_back({ "floating_tree", drb::loadSceneFromUrdf(articulated::floatingTreeUrdf(), options), 0 });
    out.push_back({ "floating_humanoid", drb::loadSceneFromUrdf(floatingHumanoidUrdf(), options), 0 });
    out.push_back({ "free_brick", drb::loadSceneFromUrdf(asymmetricFreeBodyUrdf(), options), 0 });
    return out;
  }();
  return bodies;
}

/// x, x', x'' and tau of d values each: angles of a free root in [-1.2, 1.2]
/// rad (away from gimbal lock), everything else in [-1, 1] (rates [-2, 2],
/// accelerations and forces [-3, 3]).
struct Motion
{
  Eigen::VectorXd x, xd, xdd, tau;
};

inline Motion randomMotion(const drb::BodyModel& model, std::mt19937_64& rng)
{
  const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Motion m{ Eigen::VectorXd(d), Eigen::VectorXd(d), Eigen::VectorXd(d), Eigen::VectorXd(d) };
  for (Eigen::Index i = 0; i < d; ++i)
  {
    m.x[i] = (model.hasFreeRoot() && i < 3 ? 1.2 : 1.0) * unit(rng);
    m.xd[i] = 2.0 * unit(rng);
    m.xdd[i] = 3.0 * unit(rng);
    m.tau[i] = 3.0 * unit(rng);
  }
  return m;
}

/// max|a - b| / max(max|b|, tiny).
inline double relativeDifference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b)
{
  const double scale = std::max(b.cwiseAbs().maxCoeff(), 1e-300);
  return (a - b).cwiseAbs().maxCoeff() / scale;
}

}  // namespace dynamics
}  // namespace drb_test
