// Inputs and peers of drb_bench_articulated (bench_articulated.cpp): the
// Panda and the UR5 of test/robots/example-robot-data loaded in model mode
// (JointHandling::Model), and the same URDFs loaded by KDL (kdl_parser) and
// MuJoCo (mj_loadXML). Peers' joints are matched to our coordinates by joint
// name; a peer joint j takes the value m_j x[c_j] + o_j (multiplier and
// offset of a mimic joint, else 1 and 0), so with A(j, c_j) = m_j the peer's
// M in our coordinates is A^T M_peer A.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include <Eigen/Core>

#include "diff_rigid_body/articulated_kinematics.h"
#include "diff_rigid_body/scene_queries.h"
#include "diff_rigid_body/urdf_scene.h"

#ifdef DRB_BENCH_HAVE_KDL_PARSER
#include <kdl/chaindynparam.hpp>
#include <kdl_parser/kdl_parser.hpp>
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

namespace drb_bench
{
namespace drb = diff_rigid_body;

/// A robot of test/robots: our model and what the peers need to load it.
struct Robot
{
  std::string name;      ///< "panda", "ur5"
  std::string urdf;      ///< URDF file
  std::string mesh_dir;  ///< its STL collision meshes (MuJoCo's meshdir)
  std::string kdl_base, kdl_tip;
  std::shared_ptr<const drb::ArticulatedBody> body;
  std::string body_name;                            ///< its name in the scene
  std::shared_ptr<const drb::SceneQueries> queries;  ///< the whole scene, as the node holds it
  std::vector<std::vector<double>> states;  ///< configurations x, uniform within the joint limits
};

/// Where a peer joint's value comes from: x[coordinate] * multiplier + offset.
struct JointSource
{
  int coordinate = -1;
  double multiplier = 1.0;
  double offset = 0.0;
};

inline JointSource jointSource(const drb::ArticulatedBody& body, const std::string& joint)
{
  for (const drb::Segment& s : body.segments)
    if (s.joint == joint && s.coordinate >= 0)
      return { s.coordinate, s.multiplier, s.offset };
  throw std::runtime_error("joint " + joint + " is not a coordinate of body " + body.name);
}

/// `count` configurations, joint k uniform in [lower_k, upper_k] ([-pi, pi]
/// where a limit is infinite). Fixed seed.
inline std::vector<std::vector<double>> jointStates(const drb::ArticulatedBody& body, std::size_t count,
                                                    unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::vector<std::vector<double>> states(count, std::vector<double>(body.dofs(), 0.0));
  for (std::vector<double>& x : states)
    for (std::size_t k = 0; k < body.joint_names.size(); ++k)
    {
      const double lo = std::isfinite(body.joint_lower[k]) ? body.joint_lower[k] : -M_PI;
      const double hi = std::isfinite(body.joint_upper[k]) ? body.joint_upper[k] : M_PI;
      x[body.rootCoordinates() + k] = std::uniform_real_distribution<double>(lo, hi)(rng);
    }
  return states;
}

/// Loads `file` (relative to DRB_ROBOT_DIR, the example-robot-data folder)
/// in model mode; the URDF must give exactly one articulated body.
inline Robot loadRobot(const std::string& name, const std::string& file, const std::string& meshes,
                       const std::string& kdl_base, const std::string& kdl_tip)
{
#ifdef DRB_ROBOT_DIR
  const std::string root = DRB_ROBOT_DIR;
#else
  const std::string root = "(DRB_ROBOT_DIR not defined by the build)";
#endif
  Robot robot{ name, root + "/" + file, root + "/" + meshes, kdl_base, kdl_tip, nullptr, "", nullptr, {} };
  drb::SceneOptions options;
  options.joints = drb::JointHandling::Model;
  options.find_package = [root](const std::string& package) {
    return package == "example-robot-data" ? root : std::string();
  };
  const drb::Scene scene = drb::loadSceneFromUrdfFile(robot.urdf, options);
  for (const drb::SceneBody& b : scene.bodies)
    if (b.articulated)
    {
      if (robot.body)
        throw std::runtime_error(robot.urdf + " has more than one articulated body");
      robot.body = b.articulated;
      robot.body_name = b.body.name;
    }
  if (!robot.body)
    throw std::runtime_error(robot.urdf + " gave no articulated body in model mode");
  robot.queries = std::make_shared<const drb::SceneQueries>(scene);
  robot.states = jointStates(*robot.body, 256, 17);
  return robot;
}

inline const std::vector<Robot>& robots()
{
  static const std::vector<Robot> all = [] {
    std::vector<Robot> r;
    r.push_back(loadRobot("panda", "robots/panda_description/urdf/panda.urdf",
                          "robots/panda_description/meshes/collision", "panda_link0", "panda_leftfinger"));
    r.push_back(loadRobot("ur5", "robots/ur_description/urdf/ur5_robot.urdf", "robots/ur_description/meshes/ur5/collision",
                          "base_link", "wrist_3_link"));
    return r;
  }();
  return all;
}

inline std::string readText(const std::string& path)
{
  std::ifstream in(path);
  if (!in)
    throw std::runtime_error("cannot read " + path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// A copy of `body` in which the segments whose link is not in `links` have
/// no mass: the mass a peer's chain covers.
inline drb::ArticulatedBody massOnlyIn(const drb::ArticulatedBody& body, const std::vector<std::string>& links)
{
  drb::ArticulatedBody copy = body;
  for (drb::Segment& s : copy.segments)
    if (std::find(links.begin(), links.end(), s.link) == links.end())
      s.mass_properties = drb::MassProperties();
  return copy;
}

// ---------------------------------------------------------------------------
// KDL: ChainDynParam::JntToMass on the chain kdl_base .. kdl_tip of the tree
// kdl_parser builds from the URDF.

#ifdef DRB_BENCH_HAVE_KDL_PARSER
struct KdlArm
{
  KDL::Chain chain;
  std::unique_ptr<KDL::ChainDynParam> dyn;
  KDL::JntArray joints;
  KDL::JntSpaceInertiaMatrix H;
  std::vector<JointSource> sources;  ///< per chain joint
  std::vector<std::string> links;    ///< the chain's segments (links)

  explicit KdlArm(const Robot& robot)
  {
    KDL::Tree tree;
    if (!kdl_parser::treeFromString(readText(robot.urdf), tree) ||
        !tree.getChain(robot.kdl_base, robot.kdl_tip, chain))
      throw std::runtime_error("kdl_parser: no chain " + robot.kdl_base + ".." + robot.kdl_tip);
    for (const KDL::Segment& segment : chain.segments)
    {
      links.push_back(segment.getName());
      if (segment.getJoint().getType() != KDL::Joint::None)
        sources.push_back(jointSource(*robot.body, segment.getJoint().getName()));
    }
    dyn = std::make_unique<KDL::ChainDynParam>(chain, KDL::Vector::Zero());
    joints.resize(chain.getNrOfJoints());
    H.resize(chain.getNrOfJoints());
  }
  void massMatrix(const double* x)
  {
    for (std::size_t j = 0; j < sources.size(); ++j)
      joints(j) = sources[j].multiplier * x[sources[j].coordinate] + sources[j].offset;
    dyn->JntToMass(joints, H);
  }
  /// A^T H A in our coordinates (dofs x dofs).
  Eigen::MatrixXd inCoordinates(std::size_t dofs) const
  {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(sources.size()), static_cast<Eigen::Index>(dofs));
    for (std::size_t j = 0; j < sources.size(); ++j)
      A(static_cast<Eigen::Index>(j), sources[j].coordinate) = sources[j].multiplier;
    return A.transpose() * H.data * A;
  }
};
#endif

// ---------------------------------------------------------------------------
// MuJoCo: the URDF with a <mujoco><compiler/></mujoco> element added, written
// to a temporary folder and read by mj_loadXML. meshdir points at the STL
// collision meshes (strippath keeps only the file names of package:// URIs);
// discardvisual drops the Collada visuals; fusestatic merges the links on
// fixed joints into their parent (composite inertia); inertiafromgeom=false
// takes every <inertial> as given. No gravity; armature, damping 0 (URDF
// defaults). MuJoCo ignores <mimic>: each finger is its own joint.

#ifdef DRB_BENCH_HAVE_MUJOCO
struct MujocoArm
{
  mjModel* model = nullptr;
  mjData* data = nullptr;
  std::vector<JointSource> sources;  ///< per joint of the model
  std::vector<double> dense;

  explicit MujocoArm(const Robot& robot)
  {
    std::string xml = readText(robot.urdf);
    const std::size_t open = xml.find("<robot");
    const std::size_t at = open == std::string::npos ? open : xml.find('>', open);
    if (at == std::string::npos)
      throw std::runtime_error("mujoco: no <robot> element in " + robot.urdf);
    xml.insert(at + 1, "<mujoco><compiler meshdir=\"" + robot.mesh_dir +
                           "\" strippath=\"true\" discardvisual=\"true\" fusestatic=\"true\" "
                           "inertiafromgeom=\"false\" balanceinertia=\"false\"/></mujoco>");
    char folder[] = "/tmp/drb_bench_mujoco_XXXXXX";
    if (!mkdtemp(folder))
      throw std::runtime_error("mujoco: cannot make a temporary folder");
    const std::string path = std::string(folder) + "/" + robot.name + ".urdf";
    std::ofstream(path) << xml;
    char error[1000] = "";
    model = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
    std::remove(path.c_str());
    rmdir(folder);
    if (!model)
      throw std::runtime_error(std::string("mujoco: ") + error);
    data = mj_makeData(model);
    model->opt.gravity[0] = model->opt.gravity[1] = model->opt.gravity[2] = 0;
    for (int j = 0; j < model->njnt; ++j)
      sources.push_back(jointSource(*robot.body, mj_id2name(model, mjOBJ_JOINT, j)));
    dense.resize(static_cast<std::size_t>(model->nv * model->nv));
  }
  ~MujocoArm()
  {
    mj_deleteData(data);
    mj_deleteModel(model);
  }
  MujocoArm(const MujocoArm&) = delete;
  MujocoArm& operator=(const MujocoArm&) = delete;

  void setState(const double* x)
  {
    for (std::size_t j = 0; j < sources.size(); ++j)
      data->qpos[model->jnt_qposadr[j]] = sources[j].multiplier * x[sources[j].coordinate] + sources[j].offset;
  }
  /// The smallest pipeline that yields the dense M.
  void massMatrix(const double* x)
  {
    setState(x);
    mj_kinematics(model, data);
    mj_comPos(model, data);
    mj_crb(model, data);
    mj_fullM(model, dense.data(), data->qM);
  }
  /// The whole position stage, then the dense M.
  void massMatrixFwdPosition(const double* x)
  {
    setState(x);
    mj_fwdPosition(model, data);
    mj_fullM(model, dense.data(), data->qM);
  }
  /// A^T M A in our coordinates (dofs x dofs), from the last dense M.
  Eigen::MatrixXd inCoordinates(std::size_t dofs) const
  {
    const Eigen::Index nv = model->nv;
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(nv, static_cast<Eigen::Index>(dofs));
    for (std::size_t j = 0; j < sources.size(); ++j)
      A(model->jnt_dofadr[j], sources[j].coordinate) = sources[j].multiplier;
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> M(dense.data(),
                                                                                                      nv, nv);
    return A.transpose() * M * A;
  }
};
#endif

}  // namespace drb_bench
