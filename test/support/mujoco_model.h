// MuJoCo (mj_loadXML) loading a URDF given as text, for the tests that
// compare our joint-space mass matrix with MuJoCo's.
//
// The URDF is copied with every <visual> and <collision> removed (no meshes
// to find; with inertiafromgeom="false" geometry has no effect on M) and
// <mujoco><compiler fusestatic="true" inertiafromgeom="false"
// balanceinertia="false"/></mujoco> added: links on fixed joints are merged
// into their parent (composite inertia), every <inertial> is taken as given.
// The copy is read from MuJoCo's in-memory file system. No gravity; armature
// and damping 0 (URDF defaults). MuJoCo ignores <mimic>: a mimic joint is a
// joint of its own there.
//
// A MuJoCo joint j has qvel index dof(j) = jnt_dofadr[j] and, for a 1-dof
// joint, qpos index jnt_qposadr[j]. mj_kinematics, mj_comPos, mj_crb and
// mj_fullM give the dense nv x nv M with 2T = qvel^T M qvel.
#pragma once

#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <mujoco/mujoco.h>
#include <tinyxml2.h>

namespace drb_test
{
namespace mujoco
{
/// The URDF text MuJoCo reads: geometry removed, the compiler element added.
inline std::string mujocoUrdf(const std::string& urdf)
{
  tinyxml2::XMLDocument doc;
  if (doc.Parse(urdf.c_str()) != tinyxml2::XML_SUCCESS)
    throw std::runtime_error("mujocoUrdf: bad XML");
  tinyxml2::XMLElement* robot = doc.RootElement();
  for (tinyxml2::XMLElement* link = robot->FirstChildElement("link"); link; link = link->NextSiblingElement("link"))
    for (const char* geometry : { "visual", "collision" })
      while (tinyxml2::XMLElement* e = link->FirstChildElement(geometry))
        link->DeleteChild(e);
  tinyxml2::XMLElement* mujoco = doc.NewElement("mujoco");
  tinyxml2::XMLElement* compiler = doc.NewElement("compiler");
  compiler->SetAttribute("fusestatic", "true");
  compiler->SetAttribute("inertiafromgeom", "false");
  compiler->SetAttribute("balanceinertia", "false");
  mujoco->InsertEndChild(compiler);
  robot->InsertFirstChild(mujoco);
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

/// A MuJoCo model of a URDF and its data, gravity off.
class Model
{
public:
  explicit Model(const std::string& urdf)
  {
    const std::string text = mujocoUrdf(urdf);
    const auto vfs = std::make_unique<mjVFS>();  // ~2 MB: not on the stack
    mj_defaultVFS(vfs.get());
    const char* file = "model.urdf";
    if (mj_makeEmptyFileVFS(vfs.get(), file, static_cast<int>(text.size())) != 0)
      throw std::runtime_error("mujoco: cannot make the in-memory file");
    std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), file)], text.data(), text.size());
    char error[1000] = "";
    model_ = mj_loadXML(file, vfs.get(), error, sizeof(error));
    mj_deleteVFS(vfs.get());
    if (!model_)
      throw std::runtime_error(std::string("mujoco: ") + error);
    model_->opt.gravity[0] = model_->opt.gravity[1] = model_->opt.gravity[2] = 0;
    data_ = mj_makeData(model_);
  }
  ~Model()
  {
    mj_deleteData(data_);
    mj_deleteModel(model_);
  }
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  const mjModel& model() const { return *model_; }
  /// For tests that set gravity or clear passive forces.
  mjModel& mutableModel() { return *model_; }
  mjData& data() { return *data_; }

  /// Index of the joint named `name`, or -1.
  int joint(const std::string& name) const { return mj_name2id(model_, mjOBJ_JOINT, name.c_str()); }
  /// Index of the body named `name` (a URDF link that is not fused away), or -1.
  int body(const std::string& name) const { return mj_name2id(model_, mjOBJ_BODY, name.c_str()); }

  /// The dense M (nv x nv) at the qpos currently in data().
  Eigen::MatrixXd massMatrix()
  {
    mj_kinematics(model_, data_);
    mj_comPos(model_, data_);
    mj_crb(model_, data_);
    std::vector<mjtNum> dense(static_cast<std::size_t>(model_->nv * model_->nv));
    mj_fullM(model_, dense.data(), data_->qM);
    return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        dense.data(), model_->nv, model_->nv);
  }

private:
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
};

}  // namespace mujoco
}  // namespace drb_test
