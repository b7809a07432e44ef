#include "parsers/urdf_topology.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>

#include "diff_rigid_body/exceptions.h"

namespace diff_rigid_body
{
namespace detail
{
namespace
{
[[noreturn]] void refuse(const std::string& why)
{
  throw SceneDescriptionError(why + " (a URDF must be a tree of links)");
}

std::string quoted(const std::string& name)
{
  return "'" + name + "'";
}

/// The cycle that following parent joints from `start` ends in, as
/// "joints 'ab', 'ba' form a cycle: link 'a' -> 'b' -> 'a'" (parent to child).
std::string describeCycle(const std::string& start,
                          const std::unordered_map<std::string, const JointEdge*>& parent_joint)
{
  // Walk up until a link repeats: that link is on the cycle.
  std::unordered_set<std::string> seen;
  std::string link = start;
  while (seen.insert(link).second)
    link = parent_joint.at(link)->parent;
  std::vector<const JointEdge*> cycle;  // child to parent
  std::string on_cycle = link;
  do
  {
    cycle.push_back(parent_joint.at(on_cycle));
    on_cycle = cycle.back()->parent;
  } while (on_cycle != link);
  std::reverse(cycle.begin(), cycle.end());  // parent to child
  std::string joints, links = "link " + quoted(cycle.front()->parent);
  for (const JointEdge* joint : cycle)
  {
    joints += (joints.empty() ? "" : ", ") + quoted(joint->name);
    links += " -> " + quoted(joint->child);
  }
  return "joints " + joints + " form a cycle: " + links;
}
}  // namespace

void checkTreeTopology(const std::vector<std::string>& links, const std::vector<JointEdge>& joints)
{
  if (links.empty())
    refuse("no links");
  const std::unordered_set<std::string> known(links.begin(), links.end());
  std::unordered_map<std::string, const JointEdge*> parent_joint;  // child link -> its joint
  std::unordered_map<std::string, std::vector<std::string>> children;
  for (const JointEdge& joint : joints)
  {
    for (const std::string* end : { &joint.parent, &joint.child })
      if (!known.count(*end))
        refuse("joint " + quoted(joint.name) + ": its " + (end == &joint.parent ? "parent" : "child") + " link " +
               quoted(*end) + " does not exist");
    if (joint.parent == joint.child)
      refuse("joint " + quoted(joint.name) + ": its parent and child are the same link " + quoted(joint.child));
    const auto [first, inserted] = parent_joint.emplace(joint.child, &joint);
    if (!inserted)
      refuse("link " + quoted(joint.child) + " is the child of two joints, " + quoted(first->second->name) +
             " (parent " + quoted(first->second->parent) + ") and " + quoted(joint.name) + " (parent " +
             quoted(joint.parent) + ")");
    children[joint.parent].push_back(joint.child);
  }
  std::vector<std::string> roots;
  for (const std::string& link : links)
    if (!parent_joint.count(link))
      roots.push_back(link);
  if (roots.empty())
    refuse("no root link: every link is the child of a joint; " + describeCycle(links.front(), parent_joint));
  if (roots.size() > 1)
    refuse("more than one root link (a link that is no joint's child): " + quoted(roots[0]) + " and " +
           quoted(roots[1]));
  // Every link the root reaches; each has one parent, so a link left over is
  // on a cycle or below one.
  std::unordered_set<std::string> reached{ roots.front() };
  std::vector<std::string> pending{ roots.front() };
  while (!pending.empty())
  {
    const std::string link = std::move(pending.back());
    pending.pop_back();
    for (const std::string& child : children[link])
      if (reached.insert(child).second)
        pending.push_back(child);
  }
  for (const std::string& link : links)
    if (!reached.count(link))
      refuse(describeCycle(link, parent_joint) + ", apart from the root link " + quoted(roots.front()));
}

}  // namespace detail
}  // namespace diff_rigid_body
