#include "parsers/body_coordinates.h"

#include <limits>
#include <unordered_map>

#include "diff_rigid_body/exceptions.h"

namespace diff_rigid_body
{
namespace detail
{
namespace
{
/// Each joint segment's mimic master segment, or -1 for an independent joint.
std::vector<int> mimicMasters(const UrdfDescription& description, const BodyModel& body, LoadContext& context)
{
  std::unordered_map<std::string, int> by_joint;
  for (std::size_t s = 0; s < body.segments.size(); ++s)
    if (body.segments[s].joint_type != JointType::Free)
      by_joint.emplace(body.segments[s].joint, static_cast<int>(s));
  std::vector<int> master(body.segments.size(), -1);
  for (std::size_t s = 0; s < body.segments.size(); ++s)
  {
    const Segment& segment = body.segments[s];
    if (segment.joint_type == JointType::Free)
      continue;
    const urdf::JointMimicSharedPtr& mimic = description.joint(segment.joint).mimic;
    if (!mimic)
      continue;
    const auto found = by_joint.find(mimic->joint_name);
    if (found == by_joint.end() || mimic->joint_name == segment.joint)
      context.warnings.push_back("joint '" + segment.joint + "': mimics '" + mimic->joint_name +
                                 "', which is not another joint of body '" + body.name +
                                 "'; modelled as an independent joint");
    else
      master[s] = found->second;
  }
  return master;
}
}  // namespace

std::vector<JointCoordinate> assignCoordinates(const UrdfDescription& description, BodyModel& body,
                                               LoadContext& context)
{
  const std::vector<int> master = mimicMasters(description, body, context);
  std::unordered_map<std::string, std::size_t> segment_of_joint;
  for (std::size_t s = 0; s < body.segments.size(); ++s)
    if (body.segments[s].joint_type != JointType::Free)
      segment_of_joint.emplace(body.segments[s].joint, s);
  std::vector<JointCoordinate> coordinates(body.segments.size());
  for (const std::string& name : description.joint_order)  // independent joints, document order
  {
    const auto found = segment_of_joint.find(name);
    if (found == segment_of_joint.end() || master[found->second] >= 0)
      continue;
    coordinates[found->second].coordinate = static_cast<int>(body.rootCoordinates() + body.joint_names.size());
    const urdf::Joint& joint = description.joint(name);
    const bool limited = joint.type != urdf::Joint::CONTINUOUS && joint.limits;
    body.joint_names.push_back(name);
    body.joint_lower.push_back(limited ? joint.limits->lower : -std::numeric_limits<double>::infinity());
    body.joint_upper.push_back(limited ? joint.limits->upper : std::numeric_limits<double>::infinity());
  }
  for (std::size_t s = 0; s < body.segments.size(); ++s)
  {
    // Follow the chain of masters (at most one step per segment) to an independent joint.
    double multiplier = 1.0, offset = 0.0;
    std::size_t current = s;
    for (std::size_t step = 0; master[current] >= 0; ++step)
    {
      if (step >= body.segments.size())
        throw SceneDescriptionError("joint '" + body.segments[s].joint + "': its <mimic> chain is circular");
      const urdf::JointMimic& mimic = *description.joint(body.segments[current].joint).mimic;
      offset = multiplier * mimic.offset + offset;
      multiplier *= mimic.multiplier;
      current = static_cast<std::size_t>(master[current]);
    }
    coordinates[s] = { coordinates[current].coordinate, multiplier, offset };
  }
  return coordinates;
}

void buildDofs(const std::vector<JointCoordinate>& coordinates, BodyModel& body)
{
  body.dofs.clear();
  for (std::size_t s = 0; s < body.segments.size(); ++s)
  {
    Segment& segment = body.segments[s];
    const int parent_dof =
        segment.parent < 0 ? -1 : [&] {
          const Segment& parent = body.segments[static_cast<std::size_t>(segment.parent)];
          return parent.first_dof + parent.dof_count - 1;
        }();
    segment.first_dof = static_cast<int>(body.dofs.size());
    if (segment.joint_type == JointType::Free)
    {
      // tx, ty, tz (nu = x' there), then wx, wy, wz (nu[0..2] = w): each the
      // parent of the next; the rotations are one block carried by tz.
      static constexpr int kChain[6] = { TX, TY, TZ, 0, 1, 2 };
      segment.dof_count = 6;
      segment.offset = 0.0;
      const int first = segment.first_dof;
      for (int k = 0; k < 6; ++k)
      {
        const int parent = k == 0 ? parent_dof : first + k - 1;
        const bool rotation = k >= 3;
        body.dofs.push_back({ parent, static_cast<int>(s), kChain[k], 1.0, rotation ? first + 2 : parent,
                              rotation ? first + 5 : first + k });
      }
      continue;
    }
    segment.dof_count = 1;
    segment.offset = coordinates[s].offset;
    body.dofs.push_back({ parent_dof, static_cast<int>(s), coordinates[s].coordinate, coordinates[s].multiplier,
                          parent_dof, segment.first_dof });
  }
  body.coordinates = body.rootCoordinates() + body.joint_names.size();
  body.revolute_segments.clear();
  for (std::size_t s = 0; s < body.segments.size(); ++s)
  {
    Segment& segment = body.segments[s];
    segment.angle_slot = segment.joint_type == JointType::Revolute ? static_cast<int>(body.revolute_segments.size()) : -1;
    if (segment.angle_slot >= 0)
      body.revolute_segments.push_back(static_cast<int>(s));
  }
  body.factor_coordinate.clear();
  body.factor_parent.clear();
  const bool one_dof_per_coordinate = body.dofs.size() == body.coordinates;
  for (std::size_t k = 0; k < body.coordinates; ++k)
  {
    body.factor_coordinate.push_back(one_dof_per_coordinate ? body.dofs[k].coordinate : static_cast<int>(k));
    body.factor_parent.push_back(one_dof_per_coordinate ? body.dofs[k].parent : static_cast<int>(k) - 1);
  }
}

void warnIfCoordinatesMoveNoMass(const BodyModel& body, LoadContext& context)
{
  std::vector<double> subtree_mass(body.segments.size(), 0.0);
  for (std::size_t s = body.segments.size(); s-- > 0;)
  {
    subtree_mass[s] += body.segments[s].inertia.mass;
    if (body.segments[s].parent >= 0)
      subtree_mass[static_cast<std::size_t>(body.segments[s].parent)] += subtree_mass[s];
  }
  std::vector<double> moved(body.coordinates, 0.0);
  for (const Dof& dof : body.dofs)
    moved[static_cast<std::size_t>(dof.coordinate)] += subtree_mass[static_cast<std::size_t>(dof.segment)];
  for (std::size_t j = 0; j < body.joint_names.size(); ++j)
    if (!(moved[body.rootCoordinates() + j] > 0.0))
      context.implausible("joint '" + body.joint_names[j] + "' of body '" + body.name +
                              "': moves no mass, so M(x) is singular in its coordinate (set ~density to give links "
                              "without <inertial> a mass from their geometry)",
                          "loaded as given");
  if (body.hasFreeRoot() && !(subtree_mass[0] > 0.0))
    context.implausible("body '" + body.name + "': no mass in any of its links, so M(x) is singular "
                                               "(set ~density to give links without <inertial> a mass from their geometry)",
                        "loaded as given");
}

}  // namespace detail
}  // namespace diff_rigid_body
