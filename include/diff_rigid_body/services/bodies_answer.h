// ~get_bodies' answer on plain arrays: what each body of a scene is (names,
// masses, inertia, coordinates, joints and links), flattened body after body
// as srv/GetBodies.srv lays it out. ROS-free, so that the node and the
// in-process Python module (diff_rigid_body._local) give the same values.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "diff_rigid_body/parsers/urdf_scene.h"
#include "diff_rigid_body/services/scene_queries.h"

namespace diff_rigid_body
{
/// Per body (n of them), then per joint coordinate and per link, flattened in
/// scene order, named as in srv/GetBodies.srv. Matrices are row-major; units
/// [kg], [kg m^2], [m], [rad or m]. fixed_frame: without any frame prefix;
/// names: each body's root link; masses: the total of its links; inertias (9
/// per body): the root link's group about its COM, root link axes;
/// com_offsets (3 per body): that group's COM in the root link frame; dofs:
/// d = len(x); joint_names: the joints of x, body after body, with
/// joint_counts per body and their limits (+-inf where none); link_names:
/// body after body in vertex order, with link_counts per body and per link its
/// vertices, mass, inertia about its COM in link axes (9) and COM in its own
/// frame (3).
struct BodiesAnswer
{
  DRB_ANSWER(DRB_GetBodies_RESPONSE_FIELDS)
};

/// The answer for every body of `scene`.
BodiesAnswer describeBodies(const Scene& scene);

}  // namespace diff_rigid_body
