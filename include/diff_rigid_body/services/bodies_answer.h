// ~get_bodies' answer on plain arrays: what each body of a scene is (names,
// masses, inertia, coordinates, joints and links), flattened body after body
// as srv/GetBodies.srv lays it out. ROS-free, so that the node and the
// in-process Python module (diff_rigid_body._local) give the same values.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "diff_rigid_body/parsers/urdf_scene.h"

namespace diff_rigid_body
{
/// Per body (n of them), then per joint coordinate and per link, flattened in
/// scene order. Matrices are row-major; units [kg], [kg m^2], [m], [rad or m].
struct BodiesAnswer
{
  std::string fixed_frame;               ///< without any frame prefix
  std::vector<std::string> names;        ///< per body: its root link
  std::vector<double> masses;            ///< per body: the total of its links
  std::vector<double> inertias;          ///< 9 per body: the root link's group about its COM, root link axes
  std::vector<double> com_offsets;       ///< 3 per body: that group's COM in the root link frame
  std::vector<std::uint32_t> vertex_counts;
  std::vector<std::uint32_t> dofs;       ///< per body: d = len(x)
  std::vector<std::string> joint_names;  ///< the joints of x, body after body
  std::vector<std::uint32_t> joint_counts;
  std::vector<double> joint_lower;       ///< per joint: -inf where none
  std::vector<double> joint_upper;       ///< per joint: +inf where none
  std::vector<std::string> link_names;   ///< body after body, in vertex order
  std::vector<std::uint32_t> link_counts;
  std::vector<std::uint32_t> link_vertex_counts;
  std::vector<double> link_masses;
  std::vector<double> link_inertias;     ///< 9 per link: about its COM, link axes
  std::vector<double> link_com_offsets;  ///< 3 per link: its COM in its own frame
};

/// The answer for every body of `scene`.
BodiesAnswer describeBodies(const Scene& scene);

}  // namespace diff_rigid_body
