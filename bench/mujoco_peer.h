// MuJoCo as a peer of drb_bench_articulated: the robot's URDF
// (body_robots.h) with a <mujoco><compiler/></mujoco> element added, written
// to a temporary folder and read by mj_loadXML. meshdir points at the STL
// collision meshes (strippath keeps only the file names of package:// URIs);
// discardvisual drops the Collada visuals; fusestatic merges the links on
// fixed joints into their parent (composite inertia); inertiafromgeom=false
// takes every <inertial> as given. Armature and damping 0 (URDF defaults),
// gravity (0, 0, -9.81) m/s^2. MuJoCo ignores <mimic>: each finger is its
// own joint. MuJoCo reads binary STL only: a robot whose meshes are ASCII
// STL (the humanoid's box) is given to it without its mesh collision
// elements (no geometry enters M or tau: inertiafromgeom=false). The whole
// tree, every joint:
//   M:    mj_kinematics + mj_comPos + mj_crb + mj_fullM (the smallest
//         pipeline that yields the dense M)
//   tau:  mj_kinematics + mj_comPos + mj_comVel + mj_rne(flg_acc = 1)
//         = M qacc + bias (Coriolis, centrifugal, gravity)
// A `floating` joint becomes MuJoCo's free joint: position of the link
// origin, quaternion (w, x, y, z), linear velocity in world axes, angular in
// the body's. Its qpos is set from our (R(phi, theta, psi), COM t); its
// velocities are not our x' (rows of such a robot are timings only).
#pragma once

#ifdef DRB_BENCH_HAVE_MUJOCO

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include <mujoco/mujoco.h>

#include "body_robots.h"

namespace drb_bench
{
/// `urdf` without its <collision> elements that hold a <mesh>.
inline std::string withoutMeshCollisions(std::string urdf)
{
  for (std::size_t at = urdf.find("<collision"); at != std::string::npos; at = urdf.find("<collision", at))
  {
    const char next = at + 10 < urdf.size() ? urdf[at + 10] : '>';
    if (next != '>' && next != ' ' && next != '\n' && next != '\t')  // <collision_checking>
    {
      at += 10;
      continue;
    }
    const std::size_t end = urdf.find("</collision>", at);
    if (end == std::string::npos)
      break;
    const std::size_t close = end + std::string("</collision>").size();
    if (urdf.substr(at, close - at).find("<mesh") != std::string::npos)
      urdf.erase(at, close - at);
    else
      at = close;
  }
  return urdf;
}

struct MujocoArm
{
  mjModel* model = nullptr;
  mjData* data = nullptr;
  /// Per joint of the model: its coordinate, or for a free joint the first
  /// of its free root's six (multiplier 0 marks it).
  std::vector<JointSource> sources;
  Eigen::Vector3d root_com = Eigen::Vector3d::Zero();  ///< a free root's COM in its link frame [m]
  bool has_free_joint = false;
  std::vector<double> dense, tau;

  explicit MujocoArm(const Robot& robot)
  {
    std::string xml = readText(robot.urdf);
    if (robot.ascii_meshes)
      xml = withoutMeshCollisions(xml);
    const std::size_t open = xml.find("<robot");
    const std::size_t at = open == std::string::npos ? open : xml.find('>', open);
    if (at == std::string::npos)
      throw std::runtime_error("mujoco: no <robot> element in " + robot.urdf);
    xml.insert(at + 1, "<mujoco><compiler meshdir=\"" + robot.mesh_dir +
                           "\" strippath=\"true\" discardvisual=\"true\" fusestatic=\"true\" "
                           "inertiafromgeom=\"false\" balanceinertia=\"false\"/></mujoco>");
    char error[1000] = "";
    {
      const TemporaryFile file(robot.name + ".urdf", xml);
      model = mj_loadXML(file.path().c_str(), nullptr, error, sizeof(error));
    }
    if (!model)
      throw std::runtime_error(std::string("mujoco: ") + error);
    data = mj_makeData(model);
    model->opt.gravity[0] = model->opt.gravity[1] = 0;
    model->opt.gravity[2] = -9.81;
    for (int j = 0; j < model->njnt; ++j)
    {
      const std::string name = mj_id2name(model, mjOBJ_JOINT, j);
      if (model->jnt_type[j] == mjJNT_FREE)
      {
        const int offset = freeRootOffset(robot, name);
        if (offset < 0)
          throw std::runtime_error("mujoco: free joint " + name + " is not a free root of " + robot.name);
        for (const drb::BodyModel& body : robot.bodies())
          if (body.joint_name == name)
            root_com = body.rootComOffset();
        sources.push_back({ offset, 0.0, 0.0 });
        has_free_joint = true;
      }
      else
        sources.push_back(jointSource(robot, name));
    }
    dense.resize(static_cast<std::size_t>(model->nv * model->nv));
    tau.resize(static_cast<std::size_t>(model->nv));
  }
  ~MujocoArm()
  {
    mj_deleteData(data);
    mj_deleteModel(model);
  }
  MujocoArm(const MujocoArm&) = delete;
  MujocoArm& operator=(const MujocoArm&) = delete;

  /// qpos from x; qvel, qacc from x', x'' when given.
  void setState(const double* x, const double* xd, const double* xdd)
  {
    for (std::size_t j = 0; j < sources.size(); ++j)
    {
      const JointSource& s = sources[j];
      double* qpos = data->qpos + model->jnt_qposadr[j];
      const int v = model->jnt_dofadr[j];
      if (s.multiplier == 0.0)  // free joint: link origin t - R c, quaternion of R
      {
        const double* r = x + s.coordinate;
        const Eigen::Quaterniond rotation = Eigen::AngleAxisd(r[drb::PSI], Eigen::Vector3d::UnitZ()) *
                                            Eigen::AngleAxisd(r[drb::THETA], Eigen::Vector3d::UnitY()) *
                                            Eigen::AngleAxisd(r[drb::PHI], Eigen::Vector3d::UnitX());
        const Eigen::Vector3d origin = Eigen::Vector3d(r[drb::TX], r[drb::TY], r[drb::TZ]) - rotation * root_com;
        for (int k = 0; k < 3; ++k)
          qpos[k] = origin[k];
        qpos[3] = rotation.w(), qpos[4] = rotation.x(), qpos[5] = rotation.y(), qpos[6] = rotation.z();
        for (int k = 0; k < 6 && xd; ++k)
        {
          data->qvel[v + k] = xd[s.coordinate + (k + 3) % 6];
          data->qacc[v + k] = xdd[s.coordinate + (k + 3) % 6];
        }
        continue;
      }
      qpos[0] = s.multiplier * x[s.coordinate] + s.offset;
      if (xd)
      {
        data->qvel[v] = s.multiplier * xd[s.coordinate];
        data->qacc[v] = s.multiplier * xdd[s.coordinate];
      }
    }
  }
  void massMatrix(const double* x)
  {
    setState(x, nullptr, nullptr);
    mj_kinematics(model, data);
    mj_comPos(model, data);
    mj_crb(model, data);
    mj_fullM(model, dense.data(), data->qM);
  }
  void inverseDynamics(const double* x, const double* xd, const double* xdd)
  {
    setState(x, xd, xdd);
    mj_kinematics(model, data);
    mj_comPos(model, data);
    mj_comVel(model, data);
    mj_rne(model, data, 1, tau.data());
  }
  /// A (nv x d): A(dof of joint j, c_j) = m_j (robots without a free joint).
  Eigen::MatrixXd selection(std::size_t d) const
  {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(model->nv, static_cast<Eigen::Index>(d));
    for (std::size_t j = 0; j < sources.size(); ++j)
      A(model->jnt_dofadr[j], sources[j].coordinate) = sources[j].multiplier;
    return A;
  }
  /// A^T M A from the last dense M.
  Eigen::MatrixXd massMatrixInCoordinates(std::size_t d) const
  {
    const Eigen::MatrixXd A = selection(d);
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> M(
        dense.data(), model->nv, model->nv);
    return A.transpose() * M * A;
  }
  /// A^T tau from the last inverseDynamics.
  Eigen::VectorXd tauInCoordinates(std::size_t d) const
  {
    return selection(d).transpose() * Eigen::Map<const Eigen::VectorXd>(tau.data(), model->nv);
  }
};

}  // namespace drb_bench

#endif  // DRB_BENCH_HAVE_MUJOCO
