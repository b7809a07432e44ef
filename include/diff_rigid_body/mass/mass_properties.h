// Mass properties: composites by the parallel-axis theorem
// (src/core/mass/composite_mass_properties.cpp), closed-form primitives
// (primitive_mass_properties.cpp) and the exact polyhedral integral of a
// closed mesh (mesh_mass_properties.cpp). Formulas: docs/derivation.md,
// "Inertia". The seed paper's particle sum (eq. 17), a reference for tests
// and benchmarks, is in test/reference/particle_mass_properties.h.
//
// Conventions (all functions):
//   MassProperties.mass     [kg]
//   MassProperties.com      COM in the stated frame [m]
//   MassProperties.inertia  about the COM, axes of the stated frame [kg m^2]
//   I = integral rho (|x|^2 I3 - x x^T) dV, x measured from the COM.
//   density rho [kg/m^3]; lengths [m].
// Nothing here includes a ROS header.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "diff_rigid_body/mass/mass_property_checks.h"
#include "diff_rigid_body/mass/triangle_mesh.h"

namespace diff_rigid_body
{
/// Inertia of a point mass about a point at offset d from it (the
/// parallel-axis term):  m (|d|^2 I3 - d d^T).
/// \param mass    [kg]
/// \param offset  d [m]
/// \return        [kg m^2]
Eigen::Matrix3d pointMassInertia(double mass, const Eigen::Vector3d& offset);

/// Re-expresses mass properties given in a frame A in a frame B, where
/// X_BA = (R, p) is the pose of A in B:
///   com_B = R com_A + p,   I_B = R I_A R^T,   mass unchanged.
/// The inertia stays about the COM (only its axes rotate).
MassProperties transformMassProperties(const Eigen::Isometry3d& X_BA, const MassProperties& in_A);

/// Composite of rigidly joined parts (e.g. links welded by fixed joints).
/// Part k is (X_k, P_k): P_k is given in its own frame, X_k = (R_k, p_k) is
/// that frame's pose in the target frame. With c_k = R_k com_k + p_k:
///   m   = sum_k m_k
///   com = (1/m) sum_k m_k c_k
///   I   = sum_k [ R_k I_k R_k^T + m_k (|d_k|^2 I3 - d_k d_k^T) ],  d_k = c_k - com
/// Parts of zero mass are allowed (their R_k I_k R_k^T is still added).
/// Throws InvalidInertiaError naming `where` and the part index if the list
/// is empty, a mass is negative or non-finite, a COM, inertia or pose is
/// non-finite, a pose's rotation is not orthonormal (to 1e-9), or the total
/// mass is not > 0. The result is not validated
/// (call validateMassProperties on it).
MassProperties combineMassProperties(const std::vector<std::pair<Eigen::Isometry3d, MassProperties>>& parts,
                                     const std::string& where = "composite");

/// Solid box centred at the origin, edges along the axes (URDF <box size>).
/// With size (a, b, c) and m = rho a b c:
///   I = m/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2).
/// Throws InvalidArgumentError unless density and every size are finite and > 0.
MassProperties boxMassProperties(double density, const Eigen::Vector3d& size);

/// Solid sphere centred at the origin (URDF <sphere radius>).
/// m = rho 4/3 pi r^3,  I = 2/5 m r^2 I3.
/// Throws InvalidArgumentError unless density and radius are finite and > 0.
MassProperties sphereMassProperties(double density, double radius);

/// Solid cylinder centred at the origin, axis along z (URDF <cylinder>).
/// With m = rho pi r^2 l:
///   Ixx = Iyy = m (3 r^2 + l^2) / 12,   Izz = m r^2 / 2.
/// Throws InvalidArgumentError unless density, radius and length are finite and > 0.
MassProperties cylinderMassProperties(double density, double radius, double length);

/// Volume integrals of a closed triangle mesh, by signed tetrahedra from a
/// reference point r (the vertex centroid): with a, b, c the triangle's
/// vertices minus r,
///   V_t = a . (b x c) / 6,
///   F_t = V_t (a + b + c) / 4                    (= integral of x over the tetrahedron),
///   S_t = V_t/20 [a a^T + b b^T + c c^T + s s^T],  s = a + b + c
///                                                (= integral of x x^T),
/// summed over the triangles (the divergence theorem makes the sum
/// independent of r for a closed mesh). Subtracting r first keeps the result
/// exact to rounding even when the mesh lies far from the origin.
struct MeshVolumeIntegrals
{
  double volume = 0.0;                                       ///< V [m^3]
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();        ///< F / V, in mesh coordinates [m]
  Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero();   ///< integral (x - centroid)(x - centroid)^T dV [m^5]
};

/// Checks that a mesh can bound a solid, and throws MeshLoadError naming
/// `where` and the offending element otherwise:
///   - at least one vertex and one triangle;
///   - every vertex finite;
///   - every index < number of vertices;
///   - closed and consistently oriented: after welding vertices at identical
///     positions, every edge a->b is matched by as many edges b->a (the
///     boundary of the surface is empty, which is what the divergence theorem
///     needs).
void validateClosedMesh(const TriangleMesh& mesh, const std::string& where = "mesh");

/// Exact volume integrals of a closed mesh (see MeshVolumeIntegrals).
/// Orientation: triangles counter-clockwise seen from outside give V > 0.
/// A consistently inward-oriented mesh gives V < 0; it is accepted and every
/// integral is sign-flipped, i.e. it is treated as the same solid.
/// Throws MeshLoadError (validateClosedMesh) and, if |V| is zero to rounding
/// (|V| <= 64 DBL_EPSILON sum_t |V_t|), a MeshLoadError saying the mesh
/// encloses no volume.
MeshVolumeIntegrals meshVolumeIntegrals(const TriangleMesh& mesh, const std::string& where = "mesh");

/// Mass properties of a homogeneous solid bounded by a closed mesh, in the
/// mesh's frame:
///   m = rho V,  com = F / V,  I = rho (tr(S_c) I3 - S_c),
/// S_c the second moment about the COM (MeshVolumeIntegrals). Exact up to
/// rounding (Mirtich 1996; Eberly, "Polyhedral mass properties").
/// Throws InvalidArgumentError for a density that is not finite and > 0,
/// MeshLoadError as meshVolumeIntegrals, and InvalidInertiaError if the
/// result fails validateMassProperties (e.g. a self-intersecting mesh).
MassProperties meshMassProperties(double density, const TriangleMesh& mesh, const std::string& where = "mesh");

}  // namespace diff_rigid_body
