#include "parsers/urdf_model.h"

#include <memory>
#include <sstream>
#include <string>
#include <utility>

#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include "diff_rigid_body/exceptions.h"
#include "parsers/urdf_topology.h"

namespace diff_rigid_body
{
namespace
{
// Collects urdfdom's console_bridge errors while it parses, so that they can
// be quoted in the exception instead of only reaching stderr.
class CapturedUrdfdomErrors : public console_bridge::OutputHandler
{
public:
  CapturedUrdfdomErrors() { console_bridge::useOutputHandler(this); }
  ~CapturedUrdfdomErrors() override { console_bridge::restorePreviousOutputHandler(); }
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override
  {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR)
      text_ += (text_.empty() ? "" : "; ") + text;
  }
  const std::string& text() const { return text_; }

private:
  std::string text_;
};

}  // namespace

namespace detail
{
namespace
{
// link_index from link_order.
void indexLinks(UrdfDescription& description)
{
  description.link_index.clear();
  for (std::size_t i = 0; i < description.link_order.size(); ++i)
    description.link_index.emplace(description.link_order[i], i);
}
}  // namespace

urdf::ModelInterfaceSharedPtr parseUrdfModel(const std::string& urdf_xml)
{
  CapturedUrdfdomErrors errors;
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(urdf_xml);
  if (!model || !errors.text().empty())
    throw SceneDescriptionError("urdfdom rejected it: " +
                                (errors.text().empty() ? std::string("(no reason given)") : errors.text()));
  return model;
}

std::vector<std::string> namesInDocumentOrder(const std::string& urdf_xml, const char* element)
{
  tinyxml2::XMLDocument document;
  if (document.Parse(urdf_xml.c_str(), urdf_xml.size()) != tinyxml2::XML_SUCCESS)
  {
    std::ostringstream why;
    why << "malformed XML at line " << document.ErrorLineNum() << ": " << document.ErrorStr();
    throw SceneDescriptionError(why.str());
  }
  const tinyxml2::XMLElement* robot = document.FirstChildElement("robot");
  if (!robot)
    throw SceneDescriptionError("no <robot> element");
  std::vector<std::string> names;
  for (const tinyxml2::XMLElement* child = robot->FirstChildElement(element); child;
       child = child->NextSiblingElement(element))
  {
    const char* name = child->Attribute("name");
    if (name)
      names.emplace_back(name);
  }
  return names;
}

UrdfDescription readUrdfDescription(const std::string& urdf_xml, const std::string& source)
{
  UrdfDescription description;
  try
  {
    description.link_order = namesInDocumentOrder(urdf_xml, "link");
    description.joint_order = namesInDocumentOrder(urdf_xml, "joint");
    description.model = parseUrdfModel(urdf_xml);
    std::vector<JointEdge> edges;
    for (const std::string& name : description.joint_order)
      if (const urdf::JointConstSharedPtr joint = description.model->getJoint(name))
        edges.push_back({ name, joint->parent_link_name, joint->child_link_name });
    checkTreeTopology(description.link_order, edges);
    if (!description.model->getRoot())
      throw SceneDescriptionError("no root link");
  }
  catch (const SceneDescriptionError& e)
  {
    throw SceneDescriptionError(source + ": " + e.what());
  }
  indexLinks(description);
  return description;
}

void addFloatingRoot(UrdfDescription& description, const std::string& frame)
{
  urdf::ModelInterface& model = *description.model;
  const urdf::LinkSharedPtr root = model.root_link_;
  if (model.links_.count(frame))
    throw SceneDescriptionError("parameter fixed_frame: '" + frame + "' is a link of the URDF" +
                                (frame == root->name ? " (its root)" : "") +
                                "; with floating_base the fixed frame is a new frame above the root link '" +
                                root->name + "': name one that is not a link (~fixed_frame)");
  std::string joint_name = "floating_base";
  for (int i = 1; model.joints_.count(joint_name); ++i)
    joint_name = "floating_base_" + std::to_string(i);

  auto world = std::make_shared<urdf::Link>();
  world->name = frame;
  auto joint = std::make_shared<urdf::Joint>();  // origin at the identity, no axis or limits
  joint->name = joint_name;
  joint->type = urdf::Joint::FLOATING;
  joint->parent_link_name = frame;
  joint->child_link_name = root->name;
  root->parent_joint = joint;
  root->setParent(world);
  world->child_joints.push_back(joint);
  world->child_links.push_back(root);
  model.links_[frame] = world;
  model.joints_[joint_name] = joint;
  model.root_link_ = world;

  description.link_order.insert(description.link_order.begin(), frame);
  description.joint_order.insert(description.joint_order.begin(), joint_name);
  indexLinks(description);
}

bool movesOneCoordinate(int joint_type)
{
  return joint_type == urdf::Joint::REVOLUTE || joint_type == urdf::Joint::CONTINUOUS ||
         joint_type == urdf::Joint::PRISMATIC;
}

Eigen::Isometry3d toIsometry(const urdf::Pose& pose)
{
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  X.translation() << pose.position.x, pose.position.y, pose.position.z;
  return X;
}

const char* jointTypeName(int type)
{
  static const std::pair<int, const char*> kNames[] = {
    { urdf::Joint::REVOLUTE, "revolute" }, { urdf::Joint::CONTINUOUS, "continuous" },
    { urdf::Joint::PRISMATIC, "prismatic" }, { urdf::Joint::FLOATING, "floating" },
    { urdf::Joint::PLANAR, "planar" },     { urdf::Joint::FIXED, "fixed" },
  };
  for (const auto& [value, name] : kNames)
    if (value == type)
      return name;
  return "unknown";
}
}  // namespace detail
}  // namespace diff_rigid_body
