// The robots of drb_bench_articulated (bench_articulated.cpp) and what every
// row measures them at: the Panda, the UR5 and simple_humanoid of
// test/robots/drb_example_robot_data in model mode (JointHandling::Model), the
// humanoid twice, on its fixed base and with a floating root.
//
// A robot is every body of its scene (body_model.h), its x the bodies' x
// concatenated in scene order (as SceneQueries takes q for all bodies):
//   Panda                 1 body,  8 coordinates (9 dofs: the right finger mimics the left)
//   UR5                   1 body,  6 coordinates
//   humanoid (fixed)      3 bodies (waist with torso and arms 17, each leg 6) = 29
//                         coordinates: BODY is welded to base_link, so each
//                         chain below it is a fixed-base body
//   humanoid (floating)   1 body, 35 coordinates: the URDF with its `waist`
//                         joint made `floating` (written to a temporary file),
//                         BODY a free root with the 29 joints below it
// Peers' joints are matched to ours by name (jointSource): a peer joint takes
// the value m x[c] + o (mimic multiplier and offset, else 1 and 0).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include <Eigen/Core>

#include "diff_rigid_body/multibody/body_workspace.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body/parsers/urdf_scene.h"

namespace drb_bench
{
namespace drb = diff_rigid_body;

/// Where a peer joint's value comes from: multiplier x[coordinate] + offset,
/// coordinate indexing the robot's x.
struct JointSource
{
  int coordinate = -1;
  double multiplier = 1.0;
  double offset = 0.0;
};

/// One configuration with its rates and forces, d values each: x [rad, m],
/// x' [rad/s, m/s], x'' [rad/s^2, m/s^2], tau [N m, N].
struct RobotState
{
  std::vector<double> x, xd, xdd, tau;
};

/// A robot: our scene and what the peers load.
struct Robot
{
  std::string name;   ///< "panda", "ur5", "humanoid", "humanoid_floating"
  std::string label;  ///< for the report
  std::string urdf;   ///< the URDF our model, MuJoCo and Pinocchio's oracle read
  std::string mesh_dir;  ///< its STL collision meshes (MuJoCo's meshdir)
  bool ascii_meshes = false;  ///< its STL files are ASCII (MuJoCo reads binary STL only)
  /// KDL's chain: the URDF it reads (the fixed-base one for the humanoid) and its ends.
  std::string kdl_urdf, kdl_base, kdl_tip;
  /// Pinocchio: the timing model (its own FreeFlyer for a floating robot) and
  /// the oracle of the errors (EulerZYX: our free root as a chain).
  std::string pinocchio_timing_urdf;
  bool floating = false;
  std::shared_ptr<const drb::SceneQueries> queries;  ///< the whole scene, as the node holds it
  std::vector<std::size_t> offsets;                  ///< per body: its first coordinate in x
  std::size_t coordinates = 0;                       ///< d = len(x)
  std::vector<RobotState> states;                    ///< 256, uniform within the joint limits

  const std::vector<drb::BodyModel>& bodies() const { return queries->scene().bodies; }
  std::size_t vertexCount() const
  {
    std::size_t n = 0;
    for (const drb::BodyModel& b : bodies())
      n += b.vertexCount();
    return n;
  }
};

inline std::string readText(const std::string& path)
{
  std::ifstream in(path);
  if (!in)
    throw std::runtime_error("cannot read " + path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The peer joint `joint` in the robot's coordinates; throws if it is not a
/// 1-dof joint of the robot.
inline JointSource jointSource(const Robot& robot, const std::string& joint)
{
  for (std::size_t b = 0; b < robot.bodies().size(); ++b)
    for (const drb::Segment& s : robot.bodies()[b].segments)
      if (s.joint == joint && s.joint_type != drb::JointType::Free)
      {
        const drb::Dof& dof = robot.bodies()[b].dofs[static_cast<std::size_t>(s.first_dof)];
        return { static_cast<int>(robot.offsets[b]) + dof.coordinate, dof.multiplier, s.offset };
      }
  throw std::runtime_error("joint " + joint + " is not a coordinate of robot " + robot.name);
}

/// The first coordinate of the free root whose URDF joint is `joint` (-1 if none).
inline int freeRootOffset(const Robot& robot, const std::string& joint)
{
  for (std::size_t b = 0; b < robot.bodies().size(); ++b)
    if (robot.bodies()[b].hasFreeRoot() && robot.bodies()[b].joint_name == joint)
      return static_cast<int>(robot.offsets[b]);
  return -1;
}

/// `count` states, fixed seed: every joint uniform in [lower, upper]
/// ([-pi, pi] where a limit is infinite); a free root's phi, psi in
/// [-pi, pi], theta in [-1.2, 1.2] (away from gimbal lock, where M is
/// singular), its COM in [-1, 1]^3 m; x' in [-2, 2], x'' and tau in [-3, 3].
inline std::vector<RobotState> robotStates(const Robot& robot, std::size_t count, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<RobotState> states(count);
  for (RobotState& s : states)
  {
    s.x.assign(robot.coordinates, 0.0);
    for (std::size_t b = 0; b < robot.bodies().size(); ++b)
    {
      const drb::BodyModel& body = robot.bodies()[b];
      double* x = s.x.data() + robot.offsets[b];
      if (body.hasFreeRoot())
      {
        x[drb::PHI] = M_PI * unit(rng);
        x[drb::THETA] = 1.2 * unit(rng);
        x[drb::PSI] = M_PI * unit(rng);
        for (int k = drb::TX; k <= drb::TZ; ++k)
          x[k] = unit(rng);
      }
      for (std::size_t k = 0; k < body.joint_names.size(); ++k)
      {
        const double lo = std::isfinite(body.joint_lower[k]) ? body.joint_lower[k] : -M_PI;
        const double hi = std::isfinite(body.joint_upper[k]) ? body.joint_upper[k] : M_PI;
        x[body.rootCoordinates() + k] = std::uniform_real_distribution<double>(lo, hi)(rng);
      }
    }
    for (std::vector<double>* v : { &s.xd, &s.xdd, &s.tau })
    {
      const double scale = v == &s.xd ? 2.0 : 3.0;
      v->resize(robot.coordinates);
      for (double& value : *v)
        value = scale * unit(rng);
    }
  }
  return states;
}

/// A file in a temporary folder, removed with it when this is destroyed.
class TemporaryFile
{
public:
  TemporaryFile(const std::string& name, const std::string& text)
  {
    char folder[] = "/tmp/drb_bench_XXXXXX";
    if (!mkdtemp(folder))
      throw std::runtime_error("cannot make a temporary folder");
    folder_ = folder;
    path_ = folder_ + "/" + name;
    std::ofstream(path_) << text;
  }
  ~TemporaryFile()
  {
    std::remove(path_.c_str());
    rmdir(folder_.c_str());
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  const std::string& path() const { return path_; }

private:
  std::string folder_, path_;
};

inline std::string robotDir()
{
#ifdef DRB_ROBOT_DIR
  return DRB_ROBOT_DIR;
#else
  return "(DRB_ROBOT_DIR not defined by the build)";
#endif
}

/// Loads robot.urdf in model mode and draws its states.
inline void loadModel(Robot& robot)
{
  const std::string root = robotDir();
  drb::SceneOptions options;
  options.joints = drb::JointHandling::Model;
  options.find_package = [root](const std::string& package) {
    return package == "drb_example_robot_data" ? root : std::string();
  };
  robot.queries = std::make_shared<const drb::SceneQueries>(drb::loadSceneFromUrdfFile(robot.urdf, options));
  for (const drb::BodyModel& body : robot.bodies())
  {
    robot.offsets.push_back(robot.coordinates);
    robot.coordinates += body.coordinates;
  }
  robot.states = robotStates(robot, 256, 17);
}

/// simple_humanoid with its `waist` joint floating (see the header).
inline const TemporaryFile& floatingHumanoidUrdf()
{
  static const TemporaryFile file = [] {
    const std::string path = robotDir() + "/robots/simple_humanoid_description/urdf/simple_humanoid.urdf";
    std::string text = readText(path);
    const std::string fixed = "<joint name=\"waist\" type=\"fixed\">";
    const std::size_t at = text.find(fixed);
    if (at == std::string::npos)
      throw std::runtime_error(path + ": no fixed joint 'waist'");
    text.replace(at, fixed.size(), "<joint name=\"waist\" type=\"floating\">");
    return TemporaryFile("simple_humanoid_floating.urdf", text);
  }();
  return file;
}

inline const std::vector<Robot>& robots()
{
  static const std::vector<Robot> all = [] {
    const std::string erd = robotDir() + "/robots/";
    const std::string humanoid = erd + "simple_humanoid_description/urdf/simple_humanoid.urdf";
    const std::string humanoid_meshes = erd + "simple_humanoid_description/meshes";
    std::vector<Robot> r(4);
    r[0].name = "panda", r[0].label = "Panda";
    r[0].urdf = erd + "panda_description/urdf/panda.urdf";
    r[0].mesh_dir = erd + "panda_description/meshes/collision";
    r[0].kdl_base = "panda_link0", r[0].kdl_tip = "panda_leftfinger";
    r[1].name = "ur5", r[1].label = "UR5";
    r[1].urdf = erd + "ur_description/urdf/ur5_robot.urdf";
    r[1].mesh_dir = erd + "ur_description/meshes/ur5/collision";
    r[1].kdl_base = "base_link", r[1].kdl_tip = "wrist_3_link";
    r[2].name = "humanoid", r[2].label = "humanoid (fixed base)";
    r[2].urdf = humanoid;
    r[3].name = "humanoid_floating", r[3].label = "humanoid (floating root)";
    r[3].urdf = floatingHumanoidUrdf().path();
    r[3].floating = true;
    for (std::size_t i = 0; i < r.size(); ++i)
    {
      if (i >= 2)  // the longest chain: waist, chest, left arm (10 joints)
      {
        r[i].mesh_dir = humanoid_meshes;
        r[i].ascii_meshes = true;
        r[i].kdl_base = "base_link", r[i].kdl_tip = "l_wrist";
      }
      r[i].kdl_urdf = i == 3 ? humanoid : r[i].urdf;
      r[i].pinocchio_timing_urdf = i == 3 ? humanoid : r[i].urdf;
      loadModel(r[i]);
    }
    return r;
  }();
  return all;
}

/// A copy of `bodies` in which the segments whose link is not in `links`
/// have no mass: the mass a peer's chain covers.
inline std::vector<drb::BodyModel> massOnlyIn(const std::vector<drb::BodyModel>& bodies,
                                              const std::vector<std::string>& links)
{
  std::vector<drb::BodyModel> copy = bodies;
  for (drb::BodyModel& body : copy)
    for (drb::Segment& s : body.segments)
      if (std::find(links.begin(), links.end(), s.link) == links.end())
        s.inertia = drb::MassProperties();
  return copy;
}

/// One workspace per body of a robot (the node keeps one per thread and body).
template <typename Scalar>
std::vector<drb::BodyWorkspace<Scalar>> workspaces(const std::vector<drb::BodyModel>& bodies)
{
  std::vector<drb::BodyWorkspace<Scalar>> out;
  for (const drb::BodyModel& body : bodies)
    out.emplace_back(body);
  return out;
}

}  // namespace drb_bench
