#include "parsers/link_tree.h"

#include "diff_rigid_body/exceptions.h"

namespace diff_rigid_body
{
namespace detail
{
LinkTree placeLinks(const UrdfDescription& description)
{
  LinkTree tree;
  const std::size_t n = description.link_order.size();
  tree.pose_in_root.assign(n, Eigen::Isometry3d::Identity());
  tree.owner.assign(n, "");
  struct Pending
  {
    const urdf::Link* link;
    Eigen::Isometry3d pose;
    std::string owner;
  };
  std::vector<Pending> stack{ { description.model->getRoot().get(), Eigen::Isometry3d::Identity(), "" } };
  while (!stack.empty())
  {
    const Pending next = std::move(stack.back());
    stack.pop_back();
    const std::size_t index = description.link_index.at(next.link->name);
    tree.pose_in_root[index] = next.pose;
    tree.owner[index] = next.owner;
    // Children pushed in reverse, so that they are visited in order.
    for (auto joint = next.link->child_joints.rbegin(); joint != next.link->child_joints.rend(); ++joint)
    {
      const Eigen::Isometry3d child_pose = next.pose * toIsometry((*joint)->parent_to_joint_origin_transform);
      if (!child_pose.matrix().allFinite())
        throw SceneDescriptionError("joint '" + (*joint)->name + "': <origin> is not finite");
      const bool fixed = (*joint)->type == urdf::Joint::FIXED;
      stack.push_back({ &description.link((*joint)->child_link_name), child_pose,
                        fixed ? next.owner : (*joint)->child_link_name });
    }
  }
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::string& name = description.link_order[i];
    if (tree.owner[i] == name)
      tree.moving_links.push_back(name);
    else if (!tree.owner[i].empty())
      tree.merged_links[tree.owner[i]].push_back(name);
  }
  return tree;
}

}  // namespace detail
}  // namespace diff_rigid_body
