// URDF text for tests, built from small pieces: a robot with a fixed "world"
// root link, links, joints, <inertial>, <collision>/<visual> and geometry.
// Values are strings, so that a test can write "nan", "-0" or "heavy" where
// the parser must meet them. Joint names are "<child>_joint".
#pragma once

#include <string>
#include <vector>

namespace drb_test
{
namespace urdf
{
/// `links_and_joints` inside <robot name="r">, after the root link "world".
inline std::string robot(const std::string& links_and_joints)
{
  return "<?xml version=\"1.0\"?><robot name=\"r\"><link name=\"world\"/>" + links_and_joints + "</robot>";
}

inline std::string link(const std::string& name, const std::string& inner = "")
{
  return "<link name=\"" + name + "\">" + inner + "</link>";
}

/// A joint of `type` ("floating", "fixed", ...) named "<child>_joint".
inline std::string joint(const std::string& type, const std::string& parent, const std::string& child,
                         const std::string& origin = "")
{
  return "<joint name=\"" + child + "_joint\" type=\"" + type + "\"><parent link=\"" + parent +
         "\"/><child link=\"" + child + "\"/>" + origin + "</joint>";
}

inline std::string floatingJoint(const std::string& child, const std::string& origin = "",
                                 const std::string& parent = "world")
{
  return joint("floating", parent, child, origin);
}

/// The six URDF inertia entries in the order ixx, ixy, ixz, iyy, iyz, izz [kg m^2].
using Inertia = std::vector<std::string>;

/// 0.1 kg m^2 on the diagonal.
inline Inertia diagonalInertia(const std::string& ixx = "0.1", const std::string& iyy = "0.1",
                               const std::string& izz = "0.1")
{
  return { ixx, "0", "0", iyy, "0", izz };
}

/// <inertial> with mass [kg], the tensor about the COM, and an optional <origin>.
inline std::string inertial(const std::string& mass = "1", const Inertia& I = diagonalInertia(),
                            const std::string& origin = "")
{
  return "<inertial>" + origin + "<mass value=\"" + mass + "\"/><inertia ixx=\"" + I.at(0) + "\" ixy=\"" + I.at(1) +
         "\" ixz=\"" + I.at(2) + "\" iyy=\"" + I.at(3) + "\" iyz=\"" + I.at(4) + "\" izz=\"" + I.at(5) +
         "\"/></inertial>";
}

inline std::string collision(const std::string& geometry, const std::string& origin = "")
{
  return "<collision>" + origin + "<geometry>" + geometry + "</geometry></collision>";
}

inline std::string visual(const std::string& geometry, const std::string& origin = "")
{
  return "<visual>" + origin + "<geometry>" + geometry + "</geometry></visual>";
}

/// Edge lengths "x y z" [m].
inline std::string boxGeometry(const std::string& size)
{
  return "<box size=\"" + size + "\"/>";
}

inline std::string sphereGeometry(const std::string& radius)
{
  return "<sphere radius=\"" + radius + "\"/>";
}

/// `file`: a path, file:// or package:// URI; `scale`: "sx sy sz" or none.
inline std::string meshGeometry(const std::string& file, const std::string& scale = "")
{
  return "<mesh filename=\"" + file + "\"" + (scale.empty() ? "" : " scale=\"" + scale + "\"") + "/>";
}

/// One floating body "b" with `inner` inside its <link>.
inline std::string oneBody(const std::string& inner, const std::string& joint_origin = "")
{
  return robot(link("b", inner) + floatingJoint("b", joint_origin));
}

/// The two-body scene of the service and state-file tests: "cube" (a 0.2 m
/// box, 8 vertices) at (0, 0, 1) and a sphere of radius 0.1 m (114 vertices)
/// at (1, 0, 1). The fields vary it.
struct TwoBodies
{
  std::string cube_mass = "2";
  Inertia cube_inertia = { "0.1", "0.01", "0.02", "0.2", "-0.03", "0.25" };
  std::string cube_rpy = "";  ///< "r p y" of the cube's joint origin, or none
  std::string ball_name = "ball";
  std::string ball_mass = "1";
};

inline std::string twoBodies(const TwoBodies& scene = {})
{
  const std::string cube_origin =
      "<origin xyz=\"0 0 1\"" + (scene.cube_rpy.empty() ? "" : " rpy=\"" + scene.cube_rpy + "\"") + "/>";
  return robot(link("cube", inertial(scene.cube_mass, scene.cube_inertia) + collision(boxGeometry("0.2 0.2 0.2"))) +
               floatingJoint("cube", cube_origin) +
               link(scene.ball_name, inertial(scene.ball_mass, diagonalInertia("0.004", "0.004", "0.004")) +
                                         collision(sphereGeometry("0.1"))) +
               floatingJoint(scene.ball_name, "<origin xyz=\"1 0 1\"/>"));
}
}  // namespace urdf
}  // namespace drb_test
