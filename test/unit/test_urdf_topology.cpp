// The joint graph check (src/core/parsers/urdf_topology.h) on hand-made graphs, and
// loadSceneFromUrdf on the descriptions that aborted or hung the node before
// it (issue 22): each is refused by name, nothing throws anything else, and
// nothing loops.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "../../src/core/parsers/urdf_topology.h"
#include "../support/expect_throws.h"

namespace drb = diff_rigid_body;
using drb::detail::checkTreeTopology;
using drb::detail::JointEdge;

namespace
{
const std::string kUrdfDir = std::string(DRB_TEST_DATA_DIR) + "/urdf";
}  // namespace

TEST(UrdfTopology, TreeIsAccepted)
{
  EXPECT_NO_THROW(checkTreeTopology({ "world", "a", "b", "c" },
                                    { { "ja", "world", "a" }, { "jb", "a", "b" }, { "jc", "a", "c" } }));
  EXPECT_NO_THROW(checkTreeTopology({ "world" }, {}));
}

TEST(UrdfTopology, JointToItselfIsRefused)
{
  DRB_EXPECT_THROWS_MESSAGE(checkTreeTopology({ "world", "c" }, { { "cj", "world", "c" }, { "self", "c", "c" } }),
                            drb::SceneDescriptionError, "joint 'self'", "parent and child are the same link 'c'");
}

TEST(UrdfTopology, UnknownLinkIsRefused)
{
  DRB_EXPECT_THROWS_MESSAGE(checkTreeTopology({ "world" }, { { "j", "world", "ghost" } }),
                            drb::SceneDescriptionError, "joint 'j'", "child link 'ghost' does not exist");
  DRB_EXPECT_THROWS_MESSAGE(checkTreeTopology({ "world" }, { { "j", "ghost", "world" } }),
                            drb::SceneDescriptionError, "joint 'j'", "parent link 'ghost' does not exist");
}

TEST(UrdfTopology, LinkWithTwoParentJointsIsRefused)
{
  // No cycle: a is the child of world and of b.
  DRB_EXPECT_THROWS_MESSAGE(
      checkTreeTopology({ "world", "a", "b" }, { { "ja", "world", "a" }, { "jb", "world", "b" }, { "ba", "b", "a" } }),
      drb::SceneDescriptionError, "link 'a' is the child of two joints, 'ja' (parent 'world') and 'ba' (parent 'b')");
}

TEST(UrdfTopology, CycleBesideTheRootIsRefusedWithItsJointsAndLinks)
{
  DRB_EXPECT_THROWS_MESSAGE(
      checkTreeTopology({ "world", "x", "a", "b", "c" },
                        { { "jx", "world", "x" }, { "ab", "a", "b" }, { "bc", "b", "c" }, { "ca", "c", "a" } }),
      drb::SceneDescriptionError, "joints 'ab', 'bc', 'ca' form a cycle: link 'a' -> 'b' -> 'c' -> 'a'",
      "apart from the root link 'world'");
}

TEST(UrdfTopology, BranchBelowACycleNamesTheCycle)
{
  // d hangs below the cycle a <-> b; the message names the cycle, not d.
  DRB_EXPECT_THROWS_MESSAGE(checkTreeTopology({ "world", "d", "a", "b" },
                                              { { "ad", "a", "d" }, { "ab", "a", "b" }, { "ba", "b", "a" } }),
                            drb::SceneDescriptionError, "joints 'ab', 'ba' form a cycle: link 'a' -> 'b' -> 'a'");
}

TEST(UrdfTopology, NoRootOrTwoRootsAreRefused)
{
  DRB_EXPECT_THROWS_MESSAGE(checkTreeTopology({ "a", "b" }, { { "ab", "a", "b" }, { "ba", "b", "a" } }),
                            drb::SceneDescriptionError, "no root link", "joints 'ab', 'ba' form a cycle");
  DRB_EXPECT_THROWS_MESSAGE(checkTreeTopology({ "world", "a", "b" }, { { "ja", "world", "a" } }),
                            drb::SceneDescriptionError, "more than one root link", "'world' and 'b'");
  DRB_EXPECT_THROWS_MESSAGE(checkTreeTopology({}, {}), drb::SceneDescriptionError, "no links");
}

// The three descriptions of issue 22 through the whole loader.
TEST(UrdfTopology, SelfParentDescriptionIsRefused)
{
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdfFile(kUrdfDir + "/bad_self_parent.urdf"),
                            drb::SceneDescriptionError, "joint 'c_j'", "parent and child are the same link 'c'");
}

TEST(UrdfTopology, CycleBesideTheRootDescriptionIsRefused)
{
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdfFile(kUrdfDir + "/bad_cycle_beside_root.urdf"),
                            drb::SceneDescriptionError,
                            "joints 'a_to_b', 'b_to_a' form a cycle: link 'a' -> 'b' -> 'a'");
}

TEST(UrdfTopology, TwoParentsInACycleDescriptionIsRefused)
{
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdfFile(kUrdfDir + "/bad_two_parents_cycle.urdf"),
                            drb::SceneDescriptionError,
                            "link 'a' is the child of two joints, 'world_to_a' (parent 'world') and 'b_to_a'");
}
