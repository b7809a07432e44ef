// Articulated-body test fixtures: the robots of test/robots (package://
// resolved there), a floating-base tree written here, labelled
// configurations (zero, stretched, at the limits, random within them) and
// the bodies loaded once in model mode with their URDF models
// (articulated_oracles.h).
#pragma once

#include <algorithm>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "diff_rigid_body/parsers/urdf_scene.h"
#include "articulated_oracles.h"
#include "urdf_builders.h"

namespace drb_test
{
namespace articulated
{
const std::string kRobotsDir = std::string(DRB_TEST_DATA_DIR) + "/robots";
const std::string kErd = kRobotsDir + "/drb_example_robot_data/robots";

struct Fixture
{
  const char* name;
  std::string path;  ///< URDF file
  const char* root;  ///< the body's root link
  const char* tip;   ///< a chain tip for ChainDynParam, "" for none
};

/// The fixed-base chain fixtures: the body's root link and a tip link.
inline std::vector<Fixture> fixedBaseFixtures()
{
  const std::string dp = kErd + "/double_pendulum_description/urdf/";
  return { { "ur5", kErd + "/ur_description/urdf/ur5_robot.urdf", "shoulder_link", "tool0" },
           { "double_pendulum", dp + "double_pendulum.urdf", "link1", "link2" },
           { "double_pendulum_continuous", dp + "double_pendulum_continuous.urdf", "link1", "link2" },
           { "double_pendulum_simple", dp + "double_pendulum_simple.urdf", "link1", "link3" },
           { "panda", kErd + "/panda_description/urdf/panda.urdf", "panda_link1", "" } };
}

inline std::string readText(const std::string& path)
{
  std::ifstream file(path);
  if (!file)
    throw std::runtime_error("cannot read " + path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

/// package://drb_example_robot_data and package://urdf_tutorial from test/robots.
inline diff_rigid_body::SceneOptions robotOptions(diff_rigid_body::JointHandling joints)
{
  diff_rigid_body::SceneOptions options;
  options.joints = joints;
  options.find_package = [](const std::string& package) {
    return package == "drb_example_robot_data" || package == "urdf_tutorial" ? kRobotsDir + "/" + package : "";
  };
  return options;
}

/// A 1-dof joint named "<child>_joint"; `extra` holds <mimic> etc.
inline std::string oneDofJoint(const std::string& type, const std::string& parent, const std::string& child,
                               const std::string& xyz, const std::string& rpy, const std::string& axis,
                               const std::string& lower = "-3", const std::string& upper = "3",
                               const std::string& extra = "")
{
  return "<joint name=\"" + child + "_joint\" type=\"" + type + "\"><parent link=\"" + parent +
         "\"/><child link=\"" + child + "\"/><origin xyz=\"" + xyz + "\" rpy=\"" + rpy + "\"/><axis xyz=\"" + axis +
         "\"/>" + (type == "continuous" ? "" : "<limit lower=\"" + lower + "\" upper=\"" + upper +
                                                    "\" effort=\"1\" velocity=\"1\"/>") + extra + "</joint>";
}

/// A floating torso (with a head fixed to it), two revolute legs (the right
/// knee mimics the left, multiplier -0.7, offset 0.3), a prismatic slider
/// carrying a massless revolute wrist and a hand with a zero-mass tool.
/// Independent joints: left_thigh, left_shin, right_thigh, slider, wrist, hand.
inline std::string floatingTreeUrdf()
{
  using namespace urdf;
  const auto box = [](const std::string& size) { return collision(boxGeometry(size)); };
  const auto at = [](const std::string& xyz, const std::string& rpy = "0 0 0") {
    return "<origin xyz=\"" + xyz + "\" rpy=\"" + rpy + "\"/>";
  };
  return robot(
      link("torso", inertial("5", { "0.3", "0.01", "-0.02", "0.25", "0.03", "0.2" }, at("0.02 -0.01 0.05", "0.1 -0.2 0.3")) +
                        box("0.3 0.2 0.4")) +
      floatingJoint("torso", at("0.5 -0.3 1.2", "0.2 0.4 -0.6")) +
      link("head", inertial("1.5", diagonalInertia("0.01", "0.012", "0.008"), at("0 0.01 0.05")) +
                       collision(sphereGeometry("0.1"))) +
      joint("fixed", "torso", "head", at("0 0 0.3", "0 0 0.4")) +
      link("left_thigh", inertial("2", { "0.03", "0.001", "0", "0.03", "-0.002", "0.004" }, at("0 0 -0.2")) +
                             box("0.08 0.08 0.4")) +
      oneDofJoint("revolute", "torso", "left_thigh", "0 0.12 -0.25", "0.1 0 0", "0 1 0", "-1.5", "1.5") +
      link("left_shin", inertial("1.2", diagonalInertia("0.02", "0.021", "0.002"), at("0.01 0 -0.2")) +
                            box("0.06 0.06 0.4")) +
      oneDofJoint("revolute", "left_thigh", "left_shin", "0 0 -0.4", "0 0 0", "1 0 0", "-2", "0.1") +
      link("right_thigh", inertial("2", { "0.03", "0", "0.001", "0.031", "0", "0.004" }, at("0 0 -0.2")) +
                              box("0.08 0.08 0.4")) +
      oneDofJoint("continuous", "torso", "right_thigh", "0 -0.12 -0.25", "-0.1 0.05 0", "0 0.6 0.8") +
      link("right_shin", inertial("1.1", diagonalInertia("0.02", "0.02", "0.002"), at("0 0 -0.2")) +
                             box("0.06 0.06 0.4")) +
      oneDofJoint("revolute", "right_thigh", "right_shin", "0 0 -0.4", "0 0 0", "1 0 0", "-2", "1",
                  "<mimic joint=\"left_shin_joint\" multiplier=\"-0.7\" offset=\"0.3\"/>") +
      link("slider", inertial("0.8", diagonalInertia("0.002", "0.003", "0.004"), at("0.01 0 0")) + box("0.1 0.05 0.05")) +
      oneDofJoint("prismatic", "torso", "slider", "0.15 0 0.1", "0 0.3 0", "0 0 1", "-0.1", "0.2") +
      link("wrist") + oneDofJoint("revolute", "slider", "wrist", "0.1 0 0", "0 0 0", "0 0 1") +
      link("hand", inertial("0.4", diagonalInertia("0.001", "0.0012", "0.0009"), at("0.05 0 0")) + box("0.1 0.04 0.02")) +
      oneDofJoint("revolute", "wrist", "hand", "0.05 0 0", "0 0 0.2", "0 1 0") +
      link("tool", inertial("0", diagonalInertia("0", "0", "0"))) + joint("fixed", "hand", "tool", at("0.1 0 0")));
}

// ---------------------------------------------------------------------------
// Configurations.

/// A joint's sampling range: its limits, or [-pi, pi] when it has none or
/// they are empty (the double pendulums give lower = upper = 0).
inline std::pair<double, double> sampleRange(const BodyModel& b, std::size_t k)
{
  if (std::isfinite(b.lower[k]) && std::isfinite(b.upper[k]) && b.lower[k] < b.upper[k])
    return { b.lower[k], b.upper[k] };
  return { -kPi, kPi };
}

/// Labelled configurations: zero, stretched (every joint at the value in
/// its range nearest 0), all joints at lower, at upper, alternating, then
/// `random` uniform within the ranges. A floating root gets random angles
/// in (-pi, pi] and a translation in [-2, 2]^3 m.
inline std::vector<std::pair<std::string, Eigen::VectorXd>> configurations(const BodyModel& b, Random& rng,
                                                                          int random)
{
  const std::size_t first = b.floating_root ? 6 : 0;
  const auto make = [&](const std::function<double(std::size_t)>& joint) {
    Eigen::VectorXd x(static_cast<Eigen::Index>(b.dofs()));
    for (std::size_t i = 0; i < first; ++i)
      x[i] = i < 3 ? rng.uniform(-kPi, kPi) : rng.uniform(-2, 2);
    for (std::size_t k = 0; k < b.joint_names.size(); ++k)
      x[first + k] = joint(k);
    return x;
  };
  std::vector<std::pair<std::string, Eigen::VectorXd>> out;
  out.emplace_back("zero", make([](std::size_t) { return 0.0; }));
  out.emplace_back("stretched", make([&](std::size_t k) {
                     const auto r = sampleRange(b, k);
                     return std::min(std::max(0.0, r.first), r.second);
                   }));
  out.emplace_back("at lower limits", make([&](std::size_t k) { return sampleRange(b, k).first; }));
  out.emplace_back("at upper limits", make([&](std::size_t k) { return sampleRange(b, k).second; }));
  out.emplace_back("alternating limits", make([&](std::size_t k) {
                     const auto r = sampleRange(b, k);
                     return k % 2 ? r.first : r.second;
                   }));
  for (int s = 0; s < random; ++s)
    out.emplace_back("random " + std::to_string(s), make([&](std::size_t k) {
                       const auto r = sampleRange(b, k);
                       return rng.uniform(r.first, r.second);
                     }));
  return out;
}

/// The body of a model-mode scene rooted at `root` (a tree: not a free object).
inline const diff_rigid_body::BodyModel& bodyRootedAt(const diff_rigid_body::Scene& scene, const std::string& root)
{
  for (const auto& body : scene.bodies)
    if (!body.closedFormKernels() && body.segments.front().link == root)
      return body;
  throw std::runtime_error("no articulated body rooted at " + root);
}

/// A fixture (or the floating tree) loaded in model mode, with its URDF
/// model: `model` is the oracle's (articulated_oracles.h), body() the core's.
struct LoadedBody
{
  std::string name;
  std::string tip;  ///< chain tip for ChainDynParam, "" for none
  BodyModel model;
  diff_rigid_body::BodyModel core;
  const diff_rigid_body::BodyModel& body() const { return core; }
};

/// The fixed-base fixtures and the floating tree, loaded once.
inline const std::vector<LoadedBody>& loadedBodies()
{
  static const std::vector<LoadedBody> bodies = [] {
    std::vector<LoadedBody> out;
    const auto options = robotOptions(diff_rigid_body::JointHandling::Model);
    for (const Fixture& f : fixedBaseFixtures())
    {
      const std::string xml = readText(f.path);
      const diff_rigid_body::Scene scene = diff_rigid_body::loadSceneFromUrdfFile(f.path, options);
      out.push_back({ f.name, f.tip, bodyModel(xml, f.root), bodyRootedAt(scene, f.root) });
    }
    const std::string xml = floatingTreeUrdf();
    const diff_rigid_body::Scene scene = diff_rigid_body::loadSceneFromUrdf(xml, options);
    out.push_back({ "floating_tree", "", bodyModel(xml, "torso"), bodyRootedAt(scene, "torso") });
    return out;
  }();
  return bodies;
}

template <typename Derived>
std::string row(const Eigen::MatrixBase<Derived>& v)
{
  std::ostringstream s;
  s.precision(17);
  s << v.transpose();
  return s.str();
}

}  // namespace articulated
}  // namespace drb_test
