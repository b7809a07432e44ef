// The rostest fixture scene (test/urdf/fixture_scene.urdf) worked out in the
// test, independently of the library, and the oracles of docs/derivation.md
// evaluated on it.
//
// Everything here is written from the URDF numbers and from docs/derivation.md:
//   - rotations, T(r), M, J and dL/dq from test/support/kinematics_oracles.h
//     (R = Rz(psi) Ry(theta) Rx(phi) from elementary rotations; T column by
//     column from the rotation axes; M = blockdiag(T^T R I_b R^T T, m I3),
//     not the library's A^T I_b A; J = [-[R p0]_x T, I3]);
//   - composite mass properties by the parallel-axis theorem;
//   - primitive tessellations from the documented resolution
//     (mesh_loader.h: box corners x fastest, UV sphere 8 rings x 16
//     segments, cylinder 2 rims x 32 segments);
//   - mesh vertices in "first use by faces" order, read off the fixture files.
// Nothing here calls the library, so agreement with the node is evidence.
#pragma once

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "../support/kinematics_oracles.h"

namespace drb_rostest
{
constexpr double kPi = 3.14159265358979323846;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix36d = Eigen::Matrix<double, 3, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// ---------------------------------------------------------------------------
// docs/derivation.md, written out (test/support/kinematics_oracles.h):
// R = Rz(psi) Ry(theta) Rx(phi) from elementary rotations, T(r) column by
// column from the rotation axes, M = blockdiag(T^T R I_b R^T T, m I3),
// p = R p0 + t, J = [-[R p0]_x T, I3], dL/dq = (T^T sum (R p0_i) x g_i, sum g_i).
using drb_test::refAngularVelocityMatrix;
using drb_test::refBackprop;
using drb_test::refJacobianFromAngularVelocity;
using drb_test::refMassMatrix;
using drb_test::refPosition;
using drb_test::refRotation;

/// A URDF <origin xyz rpy>.
inline Eigen::Isometry3d urdfPose(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy = Eigen::Vector3d::Zero())
{
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = refRotation(rpy.x(), rpy.y(), rpy.z());
  X.translation() = xyz;
  return X;
}

// ---------------------------------------------------------------------------
// Geometry, in the documented vertex order.

/// Box of edge lengths `size` centred at the origin: 8 corners, x fastest.
inline std::vector<Eigen::Vector3d> boxCorners(const Eigen::Vector3d& size)
{
  std::vector<Eigen::Vector3d> v;
  for (int i = 0; i < 8; ++i)
    v.emplace_back((i & 1 ? 0.5 : -0.5) * size.x(), (i & 2 ? 0.5 : -0.5) * size.y(), (i & 4 ? 0.5 : -0.5) * size.z());
  return v;
}

/// UV sphere: north pole, 7 rings of 16 (polar pi k/8, azimuth 2 pi s/16 from +x), south pole.
inline std::vector<Eigen::Vector3d> sphereVertices(double radius)
{
  std::vector<Eigen::Vector3d> v{ { 0, 0, radius } };
  for (int ring = 1; ring < 8; ++ring)
    for (int s = 0; s < 16; ++s)
    {
      const double polar = kPi * ring / 8, azimuth = 2 * kPi * s / 16;
      v.emplace_back(radius * std::sin(polar) * std::cos(azimuth), radius * std::sin(polar) * std::sin(azimuth),
                     radius * std::cos(polar));
    }
  v.emplace_back(0, 0, -radius);
  return v;
}

/// Cylinder along z: bottom rim (z = -l/2) then top rim, 32 each from +x counter-clockwise.
inline std::vector<Eigen::Vector3d> cylinderVertices(double radius, double length)
{
  std::vector<Eigen::Vector3d> v;
  for (int rim = 0; rim < 2; ++rim)
    for (int s = 0; s < 32; ++s)
    {
      const double azimuth = 2 * kPi * s / 32;
      v.emplace_back(radius * std::cos(azimuth), radius * std::sin(azimuth), (rim ? 0.5 : -0.5) * length);
    }
  return v;
}

/// test/meshes/tetrahedron.obj scaled; first use by faces (1 3 2, 1 2 4, ...):
/// v1, v3, v2, v4.
inline std::vector<Eigen::Vector3d> tetrahedronObj(const Eigen::Vector3d& scale)
{
  return { Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, scale.y(), 0), Eigen::Vector3d(scale.x(), 0, 0),
           Eigen::Vector3d(0, 0, scale.z()) };
}

/// test/meshes/box_2x1x0.5.stl, first use by faces.
inline std::vector<Eigen::Vector3d> boxStl()
{
  return { { -1, -0.5, -0.25 }, { -1, 0.5, -0.25 }, { 1, -0.5, -0.25 }, { 1, 0.5, -0.25 },
           { -1, -0.5, 0.25 },  { 1, -0.5, 0.25 },  { -1, 0.5, 0.25 },  { 1, 0.5, 0.25 } };
}

inline std::vector<Eigen::Vector3d> transformed(const Eigen::Isometry3d& X, const std::vector<Eigen::Vector3d>& v)
{
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& p : v)
    out.push_back(X * p);
  return out;
}

// ---------------------------------------------------------------------------
// The scene.

struct FixtureInertial
{
  double mass = 0.0;                               ///< [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();   ///< in the link frame [m]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about the COM, link axes [kg m^2]
};

/// <inertial> with origin (xyz, rpy) and the URDF tensor: I_link = R_o I R_o^T.
inline FixtureInertial urdfInertial(double mass, const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy, double ixx,
                                    double ixy, double ixz, double iyy, double iyz, double izz)
{
  Eigen::Matrix3d I;
  I << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
  const Eigen::Matrix3d Ro = refRotation(rpy.x(), rpy.y(), rpy.z());
  return { mass, xyz, Ro * I * Ro.transpose() };
}

struct FixtureLink
{
  std::string name;
  Eigen::Isometry3d pose_in_body_link = Eigen::Isometry3d::Identity();  ///< from fixed-joint origins
  std::vector<Eigen::Vector3d> vertices;  ///< link frame: geometry elements in order, then mesh order [m]
  bool has_inertial = false;
  FixtureInertial inertial;
};

struct FixtureBody
{
  std::string name;
  Eigen::Isometry3d initial_link_pose = Eigen::Isometry3d::Identity();  ///< in the fixed frame, from joint origins
  std::vector<FixtureLink> links;  ///< own link, then merged links in document order
  std::size_t expected_vertex_count = 0;  ///< counted by hand, joined corners included

  // Derived by finish():
  double mass = 0.0;                                     ///< [kg]
  Eigen::Vector3d com_offset = Eigen::Vector3d::Zero();  ///< COM in the link frame [m]
  Eigen::Matrix3d inertia_body = Eigen::Matrix3d::Zero();  ///< about the COM, body axes [kg m^2]
  std::vector<Eigen::Vector3d> p0;                         ///< unique vertices, body frame [m]
  std::vector<std::vector<std::size_t>> vertex_index;      ///< [link][vertex] -> index into p0

  /// Composite by the parallel-axis theorem, and the joined vertex list
  /// (positions equal to kJoinTolerance are one vertex; the fixture's
  /// coinciding corners are exact and all others are far apart).
  void finish()
  {
    constexpr double kJoinTolerance = 1e-12;  // m
    mass = 0.0;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    for (const FixtureLink& link : links)
      if (link.has_inertial)
      {
        mass += link.inertial.mass;
        moment += link.inertial.mass * (link.pose_in_body_link * link.inertial.com);
      }
    com_offset = moment / mass;
    inertia_body.setZero();
    for (const FixtureLink& link : links)
      if (link.has_inertial)
      {
        const Eigen::Matrix3d Rk = link.pose_in_body_link.linear();
        const Eigen::Vector3d d = link.pose_in_body_link * link.inertial.com - com_offset;
        inertia_body += Rk * link.inertial.inertia * Rk.transpose() +
                        link.inertial.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
      }
    std::vector<Eigen::Vector3d> unique_in_link;
    vertex_index.assign(links.size(), {});
    for (std::size_t l = 0; l < links.size(); ++l)
      for (const Eigen::Vector3d& v : links[l].vertices)
      {
        const Eigen::Vector3d u = links[l].pose_in_body_link * v;
        std::size_t found = unique_in_link.size();
        for (std::size_t k = 0; k < unique_in_link.size(); ++k)
          if ((unique_in_link[k] - u).norm() < kJoinTolerance)
            found = k;
        if (found == unique_in_link.size())
          unique_in_link.push_back(u);
        vertex_index[l].push_back(found);
      }
    p0.clear();
    for (const Eigen::Vector3d& u : unique_in_link)
      p0.push_back(u - com_offset);
  }
};

struct FixtureStaticLink
{
  std::string name;
  Eigen::Isometry3d pose;  ///< in the fixed frame
};

struct FixtureScene
{
  std::string fixed_frame;
  std::vector<FixtureBody> bodies;  ///< in scene (document) order
  std::vector<FixtureStaticLink> static_links;

  const FixtureBody& body(const std::string& name) const
  {
    for (const FixtureBody& b : bodies)
      if (b.name == name)
        return b;
    throw std::out_of_range("no fixture body " + name);
  }
};

/// test/urdf/fixture_scene.urdf, transcribed.
inline FixtureScene fixtureScene()
{
  using V = Eigen::Vector3d;
  FixtureScene scene;
  scene.fixed_frame = "world";
  const Eigen::Isometry3d pedestal = urdfPose(V(0.1, -0.2, 0.05), V(0, 0, 0.25));
  scene.static_links = { { "pedestal", pedestal }, { "pedestal_marker", pedestal * urdfPose(V(0, 0, 0.1), V(0.1, 0, 0)) } };

  FixtureBody brick;
  brick.name = "brick";
  brick.initial_link_pose = urdfPose(V(0.25, -0.5, 1.0));
  {
    FixtureLink own;
    own.name = "brick";
    own.vertices = boxCorners(V(2, 1, 0.5));  // <collision> box, then the same box as an STL: all joined
    for (const V& v : boxStl())
      own.vertices.push_back(v);
    own.has_inertial = true;
    own.inertial = urdfInertial(3.0, V(0.1, -0.05, 0.02), V(0.3, -0.2, 0.5), 0.4, 0.01, -0.02, 0.5, 0.03, 0.6);
    const Eigen::Isometry3d cap_in_brick = urdfPose(V(0, 0, 0.5));
    FixtureLink tip;  // document order: brick_tip's <link> precedes brick_cap's
    tip.name = "brick_tip";
    tip.pose_in_body_link = cap_in_brick * urdfPose(V(0.5, 0.25, 0.5), V(0.4, 0.3, -0.6));
    tip.vertices = transformed(urdfPose(V(0.1, -0.1, 0.05), V(0, 0.5, 0.2)), tetrahedronObj(V(0.5, 0.25, 0.75)));
    tip.has_inertial = true;
    tip.inertial = urdfInertial(0.5, V(0.05, 0.05, 0.05), V(0, 0, 0), 0.002, 0, 0, 0.003, 0, 0.004);
    FixtureLink cap;
    cap.name = "brick_cap";
    cap.pose_in_body_link = cap_in_brick;
    cap.vertices = boxCorners(V(2, 1, 0.5));  // bottom 4 coincide with brick's top 4
    brick.links = { own, tip, cap };
    brick.expected_vertex_count = 8 + 4 + 4;
  }

  FixtureBody tet;
  tet.name = "tet";
  tet.initial_link_pose = urdfPose(V(-0.7, 0.3, 0.9), V(0.2, -0.4, 1.1));
  {
    FixtureLink own;
    own.name = "tet";
    own.vertices = transformed(urdfPose(V(0.01, 0.02, -0.03), V(0.1, 0.2, 0.3)), tetrahedronObj(V(0.2, 0.3, 0.4)));
    for (const V& v : transformed(urdfPose(V(0, 0, 0.2)), sphereVertices(0.05)))
      own.vertices.push_back(v);
    own.has_inertial = true;
    own.inertial = urdfInertial(0.75, V(0.02, 0.03, 0.04), V(-0.3, 0.1, 0.7), 0.003, 0.0002, 0.0001, 0.004, -0.0003,
                                0.005);
    tet.links = { own };
    tet.expected_vertex_count = 4 + 114;
  }

  FixtureBody roller;
  roller.name = "roller";
  roller.initial_link_pose = pedestal * urdfPose(V(0, 0.3, 0.2), V(1.5707963267948966, 0, 0));
  {
    FixtureLink own;
    own.name = "roller";
    own.vertices = transformed(urdfPose(V(0, 0, 0), V(0, 0, 0.1)), cylinderVertices(0.05, 0.2));  // <visual> fallback
    own.has_inertial = true;
    own.inertial = urdfInertial(0.4, V(0, 0, 0), V(0, 0, 0), 0.0015, 0, 0, 0.0015, 0, 0.0005);
    roller.links = { own };
    roller.expected_vertex_count = 64;
  }

  scene.bodies = { brick, tet, roller };
  for (FixtureBody& body : scene.bodies)
    body.finish();
  return scene;
}

}  // namespace drb_rostest
