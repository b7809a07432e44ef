// The joint graph of a URDF, checked before anything walks it (internal to
// the core).
//
// urdfdom accepts some graphs that are not trees: a joint whose parent and
// child are the same link, a link that is the child of two joints, and
// cycles of joints below or beside the root. A walk of such a graph from the
// root either misses links or never ends, so the graph is checked first.
#pragma once

#include <string>
#include <vector>

namespace diff_rigid_body
{
namespace detail
{
/// One joint of the graph: its name and the names of its parent and child links.
struct JointEdge
{
  std::string name;
  std::string parent;
  std::string child;
};

/// Checks that `joints` join `links` into one tree, and throws
/// SceneDescriptionError naming the joints and links at fault otherwise, for
/// the first of these that it finds (joints in the given order):
///   - a joint whose parent or child is not one of `links`;
///   - a joint whose parent and child are the same link;
///   - a link that is the child of more than one joint;
///   - no root link (every link is a child), or more than one;
///   - a cycle of joints (links that the root does not reach).
/// Linear in the number of links and joints.
void checkTreeTopology(const std::vector<std::string>& links, const std::vector<JointEdge>& joints);

}  // namespace detail
}  // namespace diff_rigid_body
