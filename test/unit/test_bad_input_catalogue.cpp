// The bad-input catalogue of docs/robustness.md, one gtest per row: URDF
// descriptions (U), mesh files (M), service requests (R), state files (S)
// and the dynamics services (D, test_dynamics_catalogue.cpp).
// (Node parameters and the ROS transport are rostests: P and T rows.)
//
// Each row runs one input through the ROS-free core and checks
//   - that it is refused with the expected error type and a message naming
//     the problem (or accepted, for the rows marked so), and
//   - that docs/robustness.md quotes the exact message on the row's line
//     (paths under the test folder written as <test>), so the catalogue
//     cannot drift from the code.
// DRB_CATALOGUE_MARKDOWN=<file> appends each row's table line to <file>.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <regex>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass/mesh_loader.h"
#include "diff_rigid_body/mass/mass_property_checks.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body/state/state_file.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "../support/catalogue_row.h"
#include "../support/plumbing_scenes.h"
#include "../support/state_files.h"
#include "../support/urdf_builders.h"

namespace drb = diff_rigid_body;
using drb_test::replacedOnce;
using drb_test::reseal;
using drb_test::withoutTrailer;
using drb_test::urdf::collision;
using drb_test::urdf::floatingJoint;
using drb_test::urdf::inertial;
using drb_test::urdf::joint;
using drb_test::urdf::meshGeometry;
using drb_test::urdf::oneBody;
using drb_test::urdf::robot;

namespace
{
const std::string kTestDir = DRB_TEST_DATA_DIR;
const std::string kMeshDir = kTestDir + "/meshes";
const std::string kDoc = kTestDir + "/../docs/robustness.md";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

using drb_test::catalogue::Expect;
using drb_test::catalogue::Row;

std::string errorType(const drb::Error& e)
{
  if (dynamic_cast<const drb::InvalidInertiaError*>(&e))
    return "InvalidInertiaError";
  if (dynamic_cast<const drb::SceneDescriptionError*>(&e))
    return "SceneDescriptionError";
  if (dynamic_cast<const drb::MeshLoadError*>(&e))
    return "MeshLoadError";
  if (dynamic_cast<const drb::InvalidArgumentError*>(&e))
    return "InvalidArgumentError";
  if (dynamic_cast<const drb::StateFileError*>(&e))
    return "StateFileError";
  return "Error";
}

std::string replaceAll(std::string text, const std::string& from, const std::string& to)
{
  for (std::size_t at = text.find(from); !from.empty() && at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

const std::string& tempPrefix();

// Paths under the test folder as "<test>/...", and temporary files as
// "<tmp>/...", as the doc writes them.
std::string portable(const std::string& message)
{
  char real[4096];
  std::string text = replaceAll(replaceAll(message, tempPrefix(), "<tmp>/"), kTestDir, "<test>");
  if (::realpath(kTestDir.c_str(), real))
    text = replaceAll(text, real, "<test>");
  // Scene fingerprints hash floating-point bits: shown as <hash> (they may
  // differ between compilers and optimisation levels).
  return std::regex_replace(text, std::regex("\\b[0-9a-f]{16}\\b"), "<hash>");
}

drb::SceneOptions withPackages(drb::SceneOptions options = {})
{
  options.find_package = [](const std::string& package) {
    return package == "diff_rigid_body" ? kTestDir + "/.." : std::string();
  };
  return options;
}

std::function<std::string()> load(const std::string& xml, drb::SceneOptions options = withPackages())
{
  return [xml, options] {
    const drb::Scene scene = drb::loadSceneFromUrdf(xml, options);
    return std::to_string(scene.bodies.size()) + " bodies";
  };
}

drb::SceneOptions floatingBase()
{
  drb::SceneOptions options = withPackages();
  options.floating_base = true;
  return options;
}

drb::SceneOptions strict()
{
  drb::SceneOptions options = withPackages();
  options.strict_inertia = true;
  return options;
}

/// Loads a description that must load with at least one warning; the outcome
/// quotes the first.
std::function<std::string()> loadWithWarning(const std::string& xml)
{
  return [xml] {
    const drb::Scene scene = drb::loadSceneFromUrdf(xml, withPackages());
    EXPECT_FALSE(scene.warnings.empty()) << "loaded without a warning";
    return "loaded with a warning: " + (scene.warnings.empty() ? std::string("(none)") : scene.warnings.front());
  };
}

drb::SceneOptions density(double value)
{
  drb::SceneOptions options = withPackages();
  options.density = value;
  return options;
}

std::string inertiaWith(int entry, const std::string& value)
{
  std::vector<std::string> I = { "0.1", "0", "0", "0.1", "0", "0.1" };
  I[entry] = value;
  return oneBody(inertial("1", I));
}

const char* const kInertiaNames[] = { "ixx", "ixy", "ixz", "iyy", "iyz", "izz" };

std::vector<Row> urdfRows()
{
  const std::string box = collision("<box size=\"1 1 1\"/>");
  const std::string I = inertial();
  std::vector<Row> rows = {
    { "U01", "empty description", Expect::Refused, "SceneDescriptionError", "malformed XML", load("") },
    { "U02", "text that is not XML", Expect::Refused, "SceneDescriptionError", "malformed XML",
      load("this is not a robot") },
    { "U03", "unclosed element", Expect::Refused, "SceneDescriptionError", "malformed XML at line 1",
      load("<robot name=\"r\"><link name=\"world\"></robot>") },
    { "U04", "root element is not <robot>", Expect::Refused, "SceneDescriptionError", "no <robot> element",
      load("<robat name=\"r\"><link name=\"world\"/></robat>") },
    { "U05", "<link> without a name", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(robot("<link>" + I + "</link>")) },
    { "U06", "two links with the same name", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(robot("<link name=\"b\">" + I + "</link><link name=\"b\">" + I + "</link>" + floatingJoint("b"))) },
    { "U07", "two joints with the same name", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(robot("<link name=\"b\">" + I + "</link><link name=\"c\">" + I + "</link>" +
                 "<joint name=\"j\" type=\"floating\"><parent link=\"world\"/><child link=\"b\"/></joint>" +
                 "<joint name=\"j\" type=\"floating\"><parent link=\"world\"/><child link=\"c\"/></joint>")) },
    { "U08", "joint whose child link does not exist", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(robot(floatingJoint("ghost"))) },
    { "U09", "joint whose parent link does not exist", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(robot("<link name=\"b\">" + I + "</link>" + floatingJoint("b", "", "ghost"))) },
    { "U10", "two root links (a link joined to nothing)", Expect::Refused, "SceneDescriptionError",
      "urdfdom rejected it", load(robot("<link name=\"b\">" + I + "</link><link name=\"c\"/>" + floatingJoint("b"))) },
    { "U11", "a joint loop (no root link)", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(robot("<link name=\"b\">" + I + "</link>" + floatingJoint("b") + floatingJoint("world", "", "b"))) },
    { "U12", "no body (only fixed joints)", Expect::Refused, "SceneDescriptionError", "no body",
      load(robot("<link name=\"b\">" + I +
                 "</link><joint name=\"j\" type=\"fixed\"><parent link=\"world\"/><child link=\"b\"/></joint>")) },
    { "U13", "unknown joint type", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(robot("<link name=\"b\">" + I +
                 "</link><joint name=\"j\" type=\"spherical\"><parent link=\"world\"/><child link=\"b\"/></joint>")) },
    { "U14", "joint <origin xyz> with NaN", Expect::Refused, "SceneDescriptionError", "component [nan]",
      load(oneBody(I, "<origin xyz=\"nan 0 0\"/>")) },
    { "U15", "joint <origin xyz> with Inf", Expect::Refused, "SceneDescriptionError", "component [inf]",
      load(oneBody(I, "<origin xyz=\"0 inf 0\"/>")) },
    { "U16", "joint <origin rpy> with NaN", Expect::Refused, "SceneDescriptionError", "component [nan]",
      load(oneBody(I, "<origin rpy=\"0 0 nan\"/>")) },
    { "U17", "joint <origin xyz> with two numbers", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(oneBody(I, "<origin xyz=\"1 2\"/>")) },
    { "U18", "joint <origin xyz> that is not a number", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(oneBody(I, "<origin xyz=\"a b c\"/>")) },
    { "U19", "joint origins so far away that the body's position overflows (1e308 + 1e308)", Expect::Refused,
      "SceneDescriptionError", "initial state is not finite",
      load(oneBody(inertial("1", { "0.1", "0", "0", "0.1", "0", "0.1" }, "<origin xyz=\"1e308 0 0\"/>"),
                   "<origin xyz=\"1e308 0 0\"/>")) },
    { "U20", "<inertial><origin xyz> with NaN", Expect::Refused, "SceneDescriptionError",
      "Could not parse inertial element for Link [b]",
      load(oneBody(inertial("1", { "0.1", "0", "0", "0.1", "0", "0.1" }, "<origin xyz=\"0 nan 0\"/>"))) },
    { "U21", "<inertial><origin rpy> with Inf", Expect::Refused, "SceneDescriptionError",
      "Could not parse inertial element for Link [b]",
      load(oneBody(inertial("1", { "0.1", "0", "0", "0.1", "0", "0.1" }, "<origin rpy=\"inf 0 0\"/>"))) },
    { "U22", "mass NaN", Expect::Refused, "SceneDescriptionError", "mass [nan] is not a float",
      load(oneBody(inertial("nan"))) },
    { "U23", "mass +Inf", Expect::Refused, "SceneDescriptionError", "mass [inf] is not a float",
      load(oneBody(inertial("inf"))) },
    { "U24", "mass -Inf", Expect::Refused, "SceneDescriptionError", "mass [-inf] is not a float",
      load(oneBody(inertial("-inf"))) },
    { "U25", "mass 0, with ~strict_inertia", Expect::Refused, "InvalidInertiaError", "mass must be > 0",
      load(oneBody(inertial("0")), strict()) },
    { "U26", "mass -0, with ~strict_inertia", Expect::Refused, "InvalidInertiaError", "mass must be > 0",
      load(oneBody(inertial("-0")), strict()) },
    { "U27", "mass negative", Expect::Refused, "InvalidInertiaError", "mass must be > 0",
      load(oneBody(inertial("-1"))) },
    { "U28", "mass subnormal (4.9e-324)", Expect::Refused, "InvalidInertiaError", "mass must be a normal number",
      load(oneBody(inertial("4.9e-324"))) },
    { "U29", "mass subnormal with a COM offset (1e-310 kg at x = 0.3 m: m x rounds, the COM would be wrong)",
      Expect::Refused, "InvalidInertiaError", "mass must be a normal number",
      load(oneBody(inertial("1e-310", { "0.1", "0", "0", "0.1", "0", "0.1" }, "<origin xyz=\"0.3 0 0\"/>"))) },
    { "U30", "<mass> without a value", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(oneBody("<inertial><mass/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/>"
                   "</inertial>")) },
    { "U31", "mass that is not a number", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(oneBody(inertial("heavy"))) },
  };
  for (int entry = 0; entry < 6; ++entry)
  {
    char id[8];
    std::snprintf(id, sizeof id, "U%02d", 32 + entry);
    rows.push_back({ id, std::string("inertia ") + kInertiaNames[entry] + " NaN", Expect::Refused,
                     "SceneDescriptionError",
                     std::string("inertia element ") + kInertiaNames[entry] + " is not a valid double",
                     load(inertiaWith(entry, "nan")) });
  }
  std::vector<Row> more = {
    { "U38", "inertia ixx +Inf", Expect::Refused, "SceneDescriptionError", "inertia element ixx is not a valid double",
      load(inertiaWith(0, "inf")) },
    { "U39", "inertia iyz -Inf", Expect::Refused, "SceneDescriptionError", "inertia element iyz is not a valid double",
      load(inertiaWith(4, "-inf")) },
    { "U40", "inertia all zero, with ~strict_inertia", Expect::Refused, "InvalidInertiaError",
      "must be positive-definite", load(oneBody(inertial("1", { "0", "0", "0", "0", "0", "0" })), strict()) },
    { "U41", "inertia with a negative diagonal entry", Expect::Refused, "InvalidInertiaError",
      "must be positive-definite", load(inertiaWith(3, "-0.1")) },
    { "U42", "inertia indefinite (large off-diagonal)", Expect::Refused, "InvalidInertiaError",
      "must be positive-definite", load(inertiaWith(1, "0.5")) },
    { "U43", "principal moments break the triangle inequality (1, 1, 3), with ~strict_inertia", Expect::Refused,
      "InvalidInertiaError", "triangle inequality",
      load(oneBody(inertial("1", { "1", "0", "0", "1", "0", "3" })), strict()) },
    { "U44", "inertia subnormal (1e-320 on the diagonal)", Expect::Refused, "InvalidInertiaError",
      "principal moments must be normal numbers",
      load(oneBody(inertial("1", { "1e-320", "0", "0", "1e-320", "0", "1e-320" }))) },
    { "U45", "inertia not symmetric (core API; URDF cannot express it)", Expect::Refused, "InvalidInertiaError",
      "inertia must be symmetric",
      [] {
        Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();
        inertia(0, 1) = 0.1;
        drb::validateMassProperties("link 'b' <inertial>", 1.0, inertia);
        return std::string("accepted");
      } },
    { "U46", "no <inertial> and no ~density, with ~strict_inertia", Expect::Refused, "InvalidInertiaError",
      "no <inertial>", load(oneBody(box), strict()) },
    { "U47", "~density NaN", Expect::Refused, "SceneDescriptionError", "parameter density",
      load(oneBody(box), density(kNaN)) },
    { "U48", "~density 0", Expect::Refused, "SceneDescriptionError", "parameter density",
      load(oneBody(box), density(0.0)) },
    { "U49", "~density negative", Expect::Refused, "SceneDescriptionError", "parameter density",
      load(oneBody(box), density(-1000.0)) },
    { "U50", "~density +Inf", Expect::Refused, "SceneDescriptionError", "parameter density",
      load(oneBody(box), density(kInf)) },
    { "U51", "~density so small that the mass is subnormal", Expect::Refused, "InvalidInertiaError",
      "must be a normal number", load(oneBody(box), density(1e-320)) },
    { "U52", "~density so large that the mass overflows", Expect::Refused, "InvalidInertiaError", "mass must be finite",
      load(oneBody(collision("<box size=\"1e100 1e100 1e100\"/>")), density(1e300)) },
    { "U53", "~density with an open mesh (no volume)", Expect::Refused, "InvalidInertiaError",
      "cannot compute inertia from its geometry",
      load(oneBody(collision(meshGeometry(kMeshDir + "/bad_open_surface.obj"))), density(1000.0)) },
    { "U54", "box size with NaN", Expect::Refused, "SceneDescriptionError",
      "Could not parse collision element for Link [b]", load(oneBody(I + collision("<box size=\"nan 1 1\"/>"))) },
    { "U55", "box size 0", Expect::Refused, "SceneDescriptionError", "box size y must be finite and > 0",
      load(oneBody(I + collision("<box size=\"1 0 1\"/>"))) },
    { "U56", "box size negative", Expect::Refused, "SceneDescriptionError", "box size z must be finite and > 0",
      load(oneBody(I + collision("<box size=\"1 1 -1\"/>"))) },
    { "U57", "box size +Inf", Expect::Refused, "SceneDescriptionError", "component [inf]",
      load(oneBody(I + collision("<box size=\"inf 1 1\"/>"))) },
    { "U58", "box size with two numbers", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(oneBody(I + collision("<box size=\"1 1\"/>"))) },
    { "U59", "sphere radius NaN", Expect::Refused, "SceneDescriptionError", "radius [nan]",
      load(oneBody(I + collision("<sphere radius=\"nan\"/>"))) },
    { "U60", "sphere radius 0", Expect::Refused, "SceneDescriptionError", "sphere radius must be finite and > 0",
      load(oneBody(I + collision("<sphere radius=\"0\"/>"))) },
    { "U61", "sphere radius negative", Expect::Refused, "SceneDescriptionError", "sphere radius must be finite and > 0",
      load(oneBody(I + collision("<sphere radius=\"-1\"/>"))) },
    { "U62", "cylinder radius NaN", Expect::Refused, "SceneDescriptionError", "radius [nan]",
      load(oneBody(I + collision("<cylinder radius=\"nan\" length=\"1\"/>"))) },
    { "U63", "cylinder length 0", Expect::Refused, "SceneDescriptionError", "cylinder length must be finite and > 0",
      load(oneBody(I + collision("<cylinder radius=\"1\" length=\"0\"/>"))) },
    { "U64", "cylinder length -Inf", Expect::Refused, "SceneDescriptionError", "length [-inf]",
      load(oneBody(I + collision("<cylinder radius=\"1\" length=\"-inf\"/>"))) },
    { "U65", "geometry <origin> with NaN", Expect::Refused, "SceneDescriptionError",
      "Could not parse collision element for Link [b]",
      load(oneBody(I + collision("<box size=\"1 1 1\"/>", "<origin xyz=\"0 0 nan\"/>"))) },
    { "U66", "<geometry> without a shape", Expect::Refused, "SceneDescriptionError", "urdfdom rejected it",
      load(oneBody(I + "<collision><geometry/></collision>")) },
    { "U67", "geometry so far out that the vertices overflow", Expect::Refused, "SceneDescriptionError",
      "vertex coordinates overflow",
      load(oneBody(I + collision("<box size=\"1e308 1 1\"/>", "<origin xyz=\"1.7e308 0 0\"/>"))) },
    { "U68", "mesh scale with NaN", Expect::Refused, "SceneDescriptionError",
      "Mesh scale was specified, but could not be parsed",
      load(oneBody(I + collision(meshGeometry(kMeshDir + "/tetrahedron.obj", "1 nan 1")))) },
    { "U69", "mesh scale 0", Expect::Refused, "MeshLoadError", "scale must be finite and non-zero",
      load(oneBody(I + collision(meshGeometry(kMeshDir + "/tetrahedron.obj", "1 1 0")))) },
    { "U70", "mesh scale +Inf", Expect::Refused, "SceneDescriptionError",
      "Mesh scale was specified, but could not be parsed",
      load(oneBody(I + collision(meshGeometry(kMeshDir + "/tetrahedron.obj", "inf 1 1")))) },
    { "U71", "mesh scale negative (a mirror image)", Expect::Accepted, "", "",
      [] {
        const drb::Scene scene = drb::loadSceneFromUrdf(
            oneBody(collision(meshGeometry(kMeshDir + "/tetrahedron.obj", "-1 1 1"))), density(1000.0));
        // Mirrored, with its winding flipped: still a solid of volume 1/6 m^3.
        EXPECT_NEAR(scene.bodies.at(0).mass(), 1000.0 / 6.0, 1e-9);
        EXPECT_EQ(scene.bodies.at(0).vertices.cols(), 4);
        return std::string("accepted: mirrored, winding flipped (mass from ~density stays positive)");
      } },
    { "U72", "mesh from an unknown package", Expect::Refused, "MeshLoadError", "cannot find package 'nope'",
      load(oneBody(I + collision(meshGeometry("package://nope/meshes/part.stl")))) },
    { "U73", "relative mesh path with no base folder (robot_description)", Expect::Refused, "MeshLoadError",
      "relative path with no base folder", load(oneBody(I + collision(meshGeometry("meshes/part.stl")))) },
    { "U74", "mesh file that does not exist", Expect::Refused, "MeshLoadError", "no such file",
      load(oneBody(I + collision(meshGeometry("/nonexistent/part.stl")))) },
    { "U75", "~bodies names an unknown body", Expect::Refused, "SceneDescriptionError",
      "parameter bodies: unknown body 'ghost'",
      [I] {
        drb::SceneOptions options = withPackages();
        options.bodies = { "b", "ghost" };
        drb::loadSceneFromUrdf(oneBody(I), options);
        return std::string("accepted");
      } },
    { "U76", "~bodies names a body twice", Expect::Accepted, "", "",
      [I] {
        drb::SceneOptions options = withPackages();
        options.bodies = { "b", "b" };
        EXPECT_EQ(drb::loadSceneFromUrdf(oneBody(I), options).bodies.size(), 1u);
        return std::string("accepted: the body is modelled once");
      } },
    { "U77", "~fixed_frame names an unknown link", Expect::Refused, "SceneDescriptionError",
      "parameter fixed_frame: 'ghost'",
      [I] {
        drb::SceneOptions options = withPackages();
        options.fixed_frame = "ghost";
        drb::loadSceneFromUrdf(oneBody(I), options);
        return std::string("accepted");
      } },
    { "U78", "~fixed_frame names a body", Expect::Refused, "SceneDescriptionError", "parameter fixed_frame: 'b'",
      [I] {
        drb::SceneOptions options = withPackages();
        options.fixed_frame = "b";
        drb::loadSceneFromUrdf(oneBody(I), options);
        return std::string("accepted");
      } },
    { "U79", "a chain of 100 000 fixed links (deep tree)", Expect::Accepted, "", "",
      [I] {
        std::string body = "<link name=\"b\">" + I + "</link>" + floatingJoint("b");
        std::string parent = "b";
        for (int i = 0; i < 100000; ++i)
        {
          const std::string name = "l" + std::to_string(i);
          body += "<link name=\"" + name + "\"/><joint name=\"j" + name + "\" type=\"fixed\"><parent link=\"" +
                  parent + "\"/><child link=\"" + name + "\"/></joint>";
          parent = name;
        }
        const drb::Scene scene = drb::loadSceneFromUrdf(robot(body));
        EXPECT_EQ(scene.bodies.at(0).links.size(), 100001u);
        return std::string("accepted: one body with 100 000 merged links (no recursion, linear time)");
      } },
    { "U80", "20 000 floating bodies (wide tree)", Expect::Accepted, "", "",
      [I] {
        std::string body;
        for (int i = 0; i < 20000; ++i)
          body += "<link name=\"b" + std::to_string(i) + "\">" + I + "</link>" + floatingJoint("b" + std::to_string(i));
        const auto start = std::chrono::steady_clock::now();
        const drb::Scene scene = drb::loadSceneFromUrdf(robot(body));
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_EQ(scene.bodies.size(), 20000u);
        EXPECT_LT(seconds, 60.0) << "loading is not linear in the bodies any more";
        return std::string("accepted: linear time");
      } },
    { "U81", "mass 0 (a massless frame)", Expect::Accepted, "", "", loadWithWarning(oneBody(inertial("0"))) },
    { "U82", "inertia all zero", Expect::Accepted, "", "",
      loadWithWarning(oneBody(inertial("1", { "0", "0", "0", "0", "0", "0" }))) },
    { "U83", "principal moments break the triangle inequality (1, 1, 3)", Expect::Accepted, "", "",
      loadWithWarning(oneBody(inertial("1", { "1", "0", "0", "1", "0", "3" }))) },
    { "U84", "no <inertial> and no ~density", Expect::Accepted, "", "", loadWithWarning(oneBody(box)) },
    { "U85", "a floating body that starts at pitch pi/2 (gimbal lock)", Expect::Accepted, "", "",
      loadWithWarning(oneBody(I, "<origin rpy=\"0 1.5707963267948966 0\"/>")) },
    // Joint graphs that urdfdom accepts but that are not trees (urdf_topology.h).
    { "U86", "a fixed joint whose parent and child are the same link", Expect::Refused, "SceneDescriptionError",
      "parent and child are the same link 'c'",
      load(robot("<link name=\"b\">" + I + "</link>" + floatingJoint("b") + "<link name=\"c\"/>" +
                 "<joint name=\"c_j\" type=\"fixed\"><parent link=\"c\"/><child link=\"c\"/></joint>")) },
    { "U87", "two links, each the other's parent, beside the root", Expect::Refused, "SceneDescriptionError",
      "form a cycle",
      load(robot("<link name=\"b\">" + I + "</link>" + floatingJoint("b") + "<link name=\"c\">" + I +
                 "</link><link name=\"d\">" + I + "</link>" + joint("fixed", "d", "c") + joint("fixed", "c", "d"))) },
    { "U88", "a link with two parent joints, in a cycle (world -> a -> b -> a)", Expect::Refused,
      "SceneDescriptionError", "is the child of two joints",
      load(robot("<link name=\"a\">" + I + "</link><link name=\"b\">" + I + "</link>" + floatingJoint("a") +
                 joint("fixed", "a", "b") + "<joint name=\"back\" type=\"fixed\"><parent link=\"b\"/>" +
                 "<child link=\"a\"/></joint>")) },
    { "U89", "package:// mesh whose file does not exist", Expect::Refused, "MeshLoadError",
      "mesh 'package://diff_rigid_body/test/meshes/no_such_part.stl': mesh '",
      load(oneBody(I + collision(meshGeometry("package://diff_rigid_body/test/meshes/no_such_part.stl")))) },
    { "U90", "~floating_base with the fixed frame a link of the URDF (default 'world', its root here)",
      Expect::Refused, "SceneDescriptionError", "parameter fixed_frame: 'world' is a link of the URDF (its root)",
      load(oneBody(I), floatingBase()) },
  };
  rows.insert(rows.end(), more.begin(), more.end());
  return rows;
}

// ---------------------------------------------------------------------------
// Mesh files, through loadMeshFile.

std::function<std::string()> mesh(const std::string& path, const Eigen::Vector3d& scale = Eigen::Vector3d::Ones())
{
  return [path, scale] {
    const drb::TriangleMesh loaded = drb::loadMeshFile(path, scale);
    return std::to_string(loaded.vertices.cols()) + " vertices";
  };
}

std::vector<Row> meshRows()
{
  return {
    { "M01", "file that does not exist", Expect::Refused, "MeshLoadError", "cannot be read",
      mesh("/nonexistent/part.stl") },
    { "M02", "a folder", Expect::Refused, "MeshLoadError", "cannot be read", mesh(kMeshDir) },
    { "M03", "empty file (0 bytes)", Expect::Refused, "MeshLoadError", "cannot be read",
      mesh(kMeshDir + "/bad_empty.stl") },
    { "M04", "garbage bytes with a mesh extension", Expect::Refused, "MeshLoadError", "cannot be read",
      mesh(kMeshDir + "/bad_garbage.stl") },
    { "M05", "points and lines only (no triangle)", Expect::Refused, "MeshLoadError", "",
      mesh(kMeshDir + "/bad_no_triangles.obj") },
    { "M06", "every triangle degenerate (two equal corners)", Expect::Refused, "MeshLoadError",
      "all triangles are degenerate", mesh(kMeshDir + "/bad_degenerate.obj") },
    { "M07", "a NaN vertex coordinate", Expect::Refused, "MeshLoadError", "",
      mesh(kMeshDir + "/bad_nan_vertex.obj") },
    { "M08", "scale 0 in one axis", Expect::Refused, "MeshLoadError", "scale must be finite and non-zero",
      mesh(kMeshDir + "/tetrahedron.obj", Eigen::Vector3d(1, 0, 1)) },
    { "M09", "scale NaN", Expect::Refused, "MeshLoadError", "scale must be finite and non-zero",
      mesh(kMeshDir + "/tetrahedron.obj", Eigen::Vector3d(kNaN, 1, 1)) },
    { "M10", "scale -Inf", Expect::Refused, "MeshLoadError", "scale must be finite and non-zero",
      mesh(kMeshDir + "/tetrahedron.obj", Eigen::Vector3d(1, 1, -kInf)) },
    { "M11", "scale that makes coordinates overflow (1e300 x 1e10)", Expect::Refused, "MeshLoadError",
      "non-finite vertex coordinates", mesh(kMeshDir + "/bad_huge.obj", Eigen::Vector3d(1e10, 1, 1)) },
    { "M12", "subnormal scale (1e-320)", Expect::Accepted, "", "",
      [] {
        EXPECT_EQ(mesh(kMeshDir + "/tetrahedron.obj", Eigen::Vector3d(1e-320, 1e-320, 1e-320))(), "4 vertices");
        return std::string("accepted: 4 distinct, finite vertices (a ~density mass from it is refused, U51)");
      } },
  };
}

// ---------------------------------------------------------------------------
// Requests, on SceneQueries over two bodies (cube: 8 vertices, ball: 114).

const drb::SceneQueries& twoBodies()
{
  static const drb::SceneQueries queries(drb::loadSceneFromUrdf(drb_test::urdf::twoBodies()));
  return queries;
}

drb::NamedState named(const std::string& name, const drb::Vector6<double>& q = drb::Vector6<double>::Zero())
{
  return { name, q };
}

drb::Vector6<double> qWith(int index, double value)
{
  drb::Vector6<double> q = drb::Vector6<double>::Constant(0.1);
  q[index] = value;
  return q;
}

std::vector<double> sixWith(int index, double value)
{
  std::vector<double> q(6, 0.1);
  q[index] = value;
  return q;
}

// Runs `call` for NaN, +Inf and -Inf at each of 6 positions: every case must
// be refused naming the position; returns the message of the last one.
std::string everyNonFinite(const std::function<void(int, double)>& call)
{
  std::string last;
  for (int index = 0; index < 6; ++index)
    for (double value : { kNaN, kInf, -kInf })
    {
      try
      {
        call(index, value);
        ADD_FAILURE() << "accepted " << value << " at " << index;
      }
      catch (const drb::InvalidArgumentError& e)
      {
        last = e.what();
        EXPECT_NE(last.find("[" + std::to_string(index) + "]: not finite"), std::string::npos) << last;
      }
    }
  throw drb::InvalidArgumentError(last);
}

// ~get_vertex_jacobians_compact of every vertex of a box body "b" of `size`
// [m] at `q`, stored as Out (float: single_precision). A refusal must leave
// the outputs untouched; an answer must be finite.
template <typename Out>
std::string compactOfBox(const std::string& size, const std::vector<double>& q)
{
  const drb::SceneQueries queries(
      drb::loadSceneFromUrdf(oneBody(inertial() + collision("<box size=\"" + size + "\"/>"))));
  std::vector<Out> positions{ Out(42) }, rotation_jacobians{ Out(42) };
  try
  {
    queries.vertexRotationJacobians(queries.initialState(), "b", {}, q, false, positions, rotation_jacobians);
  }
  catch (const drb::Error&)
  {
    EXPECT_EQ(positions, std::vector<Out>{ Out(42) }) << "outputs written by a refused request";
    EXPECT_EQ(rotation_jacobians, std::vector<Out>{ Out(42) }) << "outputs written by a refused request";
    throw;
  }
  for (const std::vector<Out>* field : { &positions, &rotation_jacobians })
    for (Out value : *field)
      EXPECT_TRUE(std::isfinite(value));
  return std::to_string(positions.size() / 3) + " vertices";
}

// joint_states on the plumbing scene (arm: shoulder, elbow, slide, mimic finger_joint).
std::string joints(const std::vector<std::string>& names, const std::vector<double>& positions)
{
  static const drb::SceneQueries queries(drb_test::plumbing::scene());
  std::vector<std::string> unknown;
  queries.applyJointPositions(queries.initialState(), names, positions, unknown);
  std::string listed;
  for (const std::string& name : unknown)
    listed += (listed.empty() ? "" : ", ") + name;
  return "unknown: " + listed;
}

std::vector<Row> requestRows()
{
  const drb::SceneState current = twoBodies().initialState();
  auto jac = [current](const std::string& body, const std::vector<std::uint32_t>& vertices,
                       const std::vector<double>& q) {
    std::vector<double> positions{ 42.0 }, jacobians{ 42.0 };
    try
    {
      twoBodies().vertexJacobians(current, body, vertices, q, positions, jacobians);
    }
    catch (const drb::Error&)
    {
      EXPECT_EQ(positions, std::vector<double>{ 42.0 }) << "outputs written by a refused request";
      throw;
    }
    return std::to_string(positions.size() / 3) + " vertices";
  };
  auto grad = [current](const std::string& body, const std::vector<std::uint32_t>& vertices,
                        const std::vector<double>& gradients, const std::vector<double>& q) {
    // The node's entry point (K configurations; K = 1 here unless q holds more).
    const std::vector<double> gradient = twoBodies().backpropConfigurations(current, body, vertices, gradients, q);
    return std::to_string(gradient.size() / 6) + " gradients";
  };
  auto set = [current](const std::vector<drb::NamedState>& updates) {
    twoBodies().applyStates(current, updates);
    return std::string("accepted");
  };
  auto mass = [current](const std::vector<std::string>& bodies, const std::vector<double>& q, bool derivatives) {
    const drb::MassMatrixAnswer answer = twoBodies().massMatrices(current, bodies, q, derivatives);
    return std::to_string(answer.cos_theta.size()) + " matrices";
  };
  return {
    { "R01", "set_state: unknown body", Expect::Refused, "InvalidArgumentError", "states[1].name: unknown body",
      [=] { return set({ named("cube"), named("ghost") }); } },
    { "R02", "set_state: the same body twice", Expect::Refused, "InvalidArgumentError", "appears more than once",
      [=] { return set({ named("cube"), named("ball"), named("cube") }); } },
    { "R03", "set_state: empty body name", Expect::Refused, "InvalidArgumentError", "unknown body ''",
      [=] { return set({ named("") }); } },
    { "R04", "set_state: NaN, +Inf or -Inf in any of q[0..5] (18 requests; the last shown)", Expect::Refused,
      "InvalidArgumentError", "not finite",
      [=] {
        return everyNonFinite([=](int i, double v) { set({ named("ball"), named("cube", qWith(i, v)) }); });
      } },
    { "R05", "set_state: more than 100 000 states", Expect::Refused, "InvalidArgumentError", "at most 100000 states",
      [=] { return set(std::vector<drb::NamedState>(drb::RequestLimits::kMaxStates + 1, named("cube"))); } },
    { "R06", "set_state: empty request (no states)", Expect::Accepted, "", "",
      [=] {
        const drb::SceneState next = twoBodies().applyStates(current, {});
        for (std::size_t i = 0; i < next.size(); ++i)
          EXPECT_EQ(std::memcmp(next[i].data(), current[i].data(), sizeof(double) * 6), 0);
        return std::string("accepted: nothing changes (all or nothing of nothing)");
      } },
    { "R07", "set_state: -0, subnormal and huge finite values", Expect::Accepted, "", "",
      [=] {
        drb::Vector6<double> q;
        q << -0.0, 5e-324, -1e-310, 1e308, -1.7976931348623157e308, 1e300;
        const drb::SceneState next = twoBodies().applyStates(current, { named("cube", q) });
        EXPECT_EQ(std::memcmp(next[0].data(), q.data(), sizeof(double) * 6), 0);
        return std::string("accepted: stored bit for bit");
      } },
    { "R08", "get_state: unknown body", Expect::Refused, "InvalidArgumentError", "bodies[0]: unknown body 'ghost'",
      [=] {
        twoBodies().getStates(current, { "ghost" });
        return std::string("accepted");
      } },
    { "R09", "get_state: more than 100 000 names", Expect::Refused, "InvalidArgumentError", "at most 100000 names",
      [=] {
        twoBodies().getStates(current, std::vector<std::string>(drb::RequestLimits::kMaxStates + 1, "cube"));
        return std::string("accepted");
      } },
    { "R10", "get_state: a name of 1 MB (the message quotes 64 bytes of it)", Expect::Refused,
      "InvalidArgumentError", "unknown body 'xxxx",
      [=] {
        twoBodies().getStates(current, { std::string(1 << 20, 'x') });
        return std::string("accepted");
      } },
    { "R11", "get_mass_matrix: unknown body", Expect::Refused, "InvalidArgumentError", "bodies[1]: unknown body",
      [=] { return mass({ "cube", "ghost" }, {}, false); } },
    { "R12", "get_mass_matrix: q of the wrong length (7 for one body)", Expect::Refused, "InvalidArgumentError",
      "q: expected a multiple of 6 x 1 bodies", [=] { return mass({ "cube" }, std::vector<double>(7, 0.0), false); } },
    { "R13", "get_mass_matrix: NaN, +Inf or -Inf in any q value (18 requests; the last shown)", Expect::Refused,
      "InvalidArgumentError", "not finite",
      [=] { return everyNonFinite([=](int i, double v) { mass({ "ball" }, sixWith(i, v), true); }); } },
    { "R14", "get_mass_matrix: more than 10^6 matrices", Expect::Refused, "InvalidArgumentError",
      "at most 1000000 matrices",
      [=] {
        return mass({ "cube" }, std::vector<double>(6 * (drb::RequestLimits::kMaxMassMatrices + 1), 0.0), false);
      } },
    { "R15", "get_mass_matrix: more than 10^5 matrices with derivatives", Expect::Refused, "InvalidArgumentError",
      "at most 100000 matrices",
      [=] {
        return mass({ "cube" },
                    std::vector<double>(6 * (drb::RequestLimits::kMaxMassMatricesWithDerivatives + 1), 0.0), true);
      } },
    { "R16", "get_mass_matrix: empty request", Expect::Accepted, "", "",
      [=] {
        EXPECT_EQ(mass({}, {}, false), "2 matrices");
        return std::string("accepted: every body at the current state");
      } },
    { "R17", "get_mass_matrix: theta = pi/2 (gimbal lock) and angles of 1e300", Expect::Accepted, "", "",
      [=] {
        const drb::MassMatrixAnswer answer = twoBodies().massMatrices(
            current, { "cube" }, { 1e300, 1.5707963267948966, -1e300, 0, 0, 0, 0.1, -1.5707963267948966, 0, 0, 0, 0 },
            true);
        for (double value : answer.mass_matrices)
          EXPECT_TRUE(std::isfinite(value));
        for (double value : answer.derivatives)
          EXPECT_TRUE(std::isfinite(value));
        return std::string("accepted: finite (M is singular, never inverted; cos_theta reports it)");
      } },
    { "R18", "get_vertex_jacobians: empty request (no body)", Expect::Refused, "InvalidArgumentError",
      "body: unknown body ''", [=] { return jac("", {}, {}); } },
    { "R19", "get_vertex_jacobians: vertex index out of range", Expect::Refused, "InvalidArgumentError",
      "vertices[1]: index 8 out of range for body 'cube' with 8 vertices", [=] { return jac("cube", { 0, 8 }, {}); } },
    { "R20", "get_vertex_jacobians: vertex index 2^32 - 1", Expect::Refused, "InvalidArgumentError",
      "index 4294967295 out of range", [=] { return jac("ball", { 4294967295u }, {}); } },
    { "R21", "get_vertex_jacobians: q of 5 values", Expect::Refused, "InvalidArgumentError", "q: expected 6 values",
      [=] { return jac("cube", {}, std::vector<double>(5, 0.0)); } },
    { "R22", "get_vertex_jacobians: q of 7 values", Expect::Refused, "InvalidArgumentError", "q: expected 6 values",
      [=] { return jac("cube", {}, std::vector<double>(7, 0.0)); } },
    { "R23", "get_vertex_jacobians: NaN, +Inf or -Inf in any of q[0..5] (18 requests; the last shown)",
      Expect::Refused, "InvalidArgumentError", "not finite",
      [=] { return everyNonFinite([=](int i, double v) { jac("cube", {}, sixWith(i, v)); }); } },
    { "R24", "get_vertex_jacobians: q with a translation of 1.7e308 on a small body", Expect::Accepted, "", "",
      [=] {
        EXPECT_EQ(jac("ball", {}, { 0, 0, 0, 1.7e308, 0, 0 }), "114 vertices");
        return std::string("accepted: finite positions (1.7e308 + 0.1 rounds to 1.7e308)");
      } },
    { "R25", "get_vertex_jacobians: a body 1e300 m wide at a translation of 1.7e308 (positions would overflow)",
      Expect::Refused, "InvalidArgumentError", "position too large",
      [] {
        const drb::SceneQueries giant(drb::loadSceneFromUrdf(
            oneBody(inertial() + collision("<box size=\"1e300 1 1\"/>"))));
        std::vector<double> positions, jacobians;
        giant.vertexJacobians(giant.initialState(), "b", {}, { 0, 0, 0, 1.7e308, 0, 0 }, positions, jacobians);
        return std::string("accepted");
      } },
    { "R26", "get_vertex_jacobians: more than 2^22 vertex indices", Expect::Refused, "InvalidArgumentError",
      "at most 4194304 vertices",
      [=] { return jac("cube", std::vector<std::uint32_t>(drb::RequestLimits::kMaxVertices + 1, 0), {}); } },
    { "R27", "get_vertex_jacobians: the same vertex many times", Expect::Accepted, "", "",
      [=] {
        EXPECT_EQ(jac("cube", std::vector<std::uint32_t>(1000, 3), {}), "1000 vertices");
        return std::string("accepted: one answer per index");
      } },
    { "R28", "backprop: gradients of the wrong length", Expect::Refused, "InvalidArgumentError",
      "gradients: expected 3 per vertex = 6, got 5 values", [=] { return grad("cube", { 1, 2 }, { 1, 2, 3, 4, 5 }, {}); } },
    { "R29", "backprop: NaN, +Inf or -Inf in any gradient value (18 requests; the last shown)", Expect::Refused,
      "InvalidArgumentError", "not finite",
      [=] { return everyNonFinite([=](int i, double v) { grad("cube", { 0, 1 }, sixWith(i, v), {}); }); } },
    { "R30", "backprop: gradients of 1e308 (the sum overflows)", Expect::Refused, "InvalidArgumentError",
      "result gradient", [=] { return grad("cube", {}, std::vector<double>(24, 1e308), {}); } },
    { "R31", "backprop: NaN in q", Expect::Refused, "InvalidArgumentError", "q[4]: not finite",
      [=] { return grad("cube", { 0 }, { 1, 2, 3 }, sixWith(4, kNaN)); } },
    { "R32", "backprop: empty request (no body)", Expect::Refused, "InvalidArgumentError", "body: unknown body ''",
      [=] { return grad("", {}, {}, {}); } },
    { "R33", "backprop: more than 2^22 vertex indices", Expect::Refused, "InvalidArgumentError",
      "at most 4194304 vertices",
      [=] { return grad("cube", std::vector<std::uint32_t>(drb::RequestLimits::kMaxVertices + 1, 0), {}, {}); } },
    { "R34", "get_vertex_jacobians_compact: a body 1e300 m wide at a translation of 1.7e308 (positions would overflow)",
      Expect::Refused, "InvalidArgumentError", "position too large",
      [] { return compactOfBox<double>("1e300 1 1", { 0, 0, 0, 1.7e308, 0, 0 }); } },
    { "R35", "get_vertex_jacobians_compact, single_precision: a translation of 3.5e38 (beyond float32's 3.4e38)",
      Expect::Refused, "InvalidArgumentError", "overflow float32",
      [] { return compactOfBox<float>("0.2 0.2 0.2", { 0, 0, 0, 0, 0, -3.5e38 }); } },
    { "R36", "get_vertex_jacobians_compact, single_precision: a body 1e38 m wide at a translation of 3e38 "
             "(each fits float32, their sum does not)",
      Expect::Refused, "InvalidArgumentError", "overflow float32",
      [] { return compactOfBox<float>("1e38 1 1", { 0, 0, 0, 3e38, 0, 0 }); } },
    { "R37", "get_vertex_jacobians_compact, single_precision: a translation of 3.4e38 on a small body",
      Expect::Accepted, "", "",
      [] {
        EXPECT_EQ(compactOfBox<float>("0.2 0.2 0.2", { 0, 0, 0, 3.4e38, 0, 0 }), "8 vertices");
        return std::string("accepted: finite float32 positions (3.4e38 + 0.1 rounds to 3.4e38)");
      } },
    { "R38", "get_vertex_jacobians: q of 13 values (two configurations and one value)", Expect::Refused,
      "InvalidArgumentError", "q: expected 6 values per configuration",
      [=] { return jac("cube", {}, std::vector<double>(13, 0.0)); } },
    { "R39", "get_vertex_jacobians: 3 configurations of 2 vertices", Expect::Accepted, "", "",
      [=] {
        EXPECT_EQ(jac("cube", { 0, 7 }, std::vector<double>(18, 0.5)), "6 vertices");
        return std::string("accepted: 3 blocks of 2 vertices, configuration-major");
      } },
    { "R40", "get_vertex_jacobians: configurations x vertices over 2^22 (36793 configurations of the 114 of ball)",
      Expect::Refused, "InvalidArgumentError", "q, vertices: expected at most 4194304 vertices over all configurations",
      [=] { return jac("ball", {}, std::vector<double>(6 * (drb::RequestLimits::kMaxVertices / 114 + 1), 0.0)); } },
    { "R41", "backprop: gradients for one configuration, q for two", Expect::Refused, "InvalidArgumentError",
      "gradients: expected 3 per vertex and configuration", [=] { return grad("cube", { 1, 2 }, std::vector<double>(6, 1.0), std::vector<double>(12, 0.0)); } },
    { "R42", "get_vertex_jacobians_compact, single_precision: configuration 1 of 2 at a translation of 3.5e38",
      Expect::Refused, "InvalidArgumentError", "q (configuration 1): position too large",
      [] { return compactOfBox<float>("0.2 0.2 0.2", { 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, -3.5e38 }); } },
    { "R43", "set_state: q of 5 values for a 6-dof body", Expect::Refused, "InvalidArgumentError",
      "states[0].q (body 'cube'): expected 6 values (the body's dofs), got 5 values",
      [=] { return set({ { "cube", Eigen::VectorXd::Zero(5) } }); } },
    { "R44", "joint_states: a NaN position (the message is dropped whole)", Expect::Refused, "InvalidArgumentError",
      "position[1] (joint 'slide'): not finite",
      [] { return joints({ "elbow", "slide" }, { 0.5, kNaN }); } },
    { "R45", "joint_states: 2 names, 1 position", Expect::Refused, "InvalidArgumentError",
      "position: expected 2 values (one per name), got 1 values",
      [] { return joints({ "elbow", "slide" }, { 0.5 }); } },
    { "R46", "joint_states: unknown and mimic joint names", Expect::Accepted, "", "",
      [] {
        EXPECT_EQ(joints({ "ghost", "finger_joint", "elbow" }, { 1.0, 2.0, 3.0 }), "unknown: ghost");
        return std::string("accepted: elbow set; finger_joint (mimic) ignored; ghost ignored and reported");
      } },
  };
}

// ---------------------------------------------------------------------------
// State files, through parseStateFile, readStateFile and writeStateFile.

std::string stateText()
{
  drb::SceneState state = twoBodies().initialState();
  state[0] << 0.5, -0.25, 1.0 / 3.0, -0.0, 1e-310, 2.0;
  return drb::formatStateFile(twoBodies().scene(), state);
}

std::function<std::string()> parse(const std::string& text)
{
  return [text] {
    drb::parseStateFile(text, twoBodies().scene());
    return std::string("accepted");
  };
}

/// `text` with its trailer recomputed for the two bodies.
std::string resealed(const std::string& text)
{
  return reseal(withoutTrailer(text), 2);
}

// Temporary files of this process; messages show them as "<tmp>/name".
const std::string& tempPrefix()
{
  static const std::string prefix = ::testing::TempDir() + "drb_catalogue_" + std::to_string(::getpid()) + "_";
  return prefix;
}

std::string tempPath(const std::string& name)
{
  return tempPrefix() + name;
}

std::vector<Row> stateFileRows()
{
  const std::string good = stateText();
  std::string flipped = good;
  flipped[good.find("\nbody cube") + 12] ^= 0x02;
  const drb::Scene& scene = twoBodies().scene();
  drb::SceneOptions one;
  one.bodies = { "cube" };
  drb_test::urdf::TwoBodies heavier;
  heavier.ball_mass = "1.5";
  const drb::Scene heavier_ball = drb::loadSceneFromUrdf(drb_test::urdf::twoBodies(heavier));
  return {
    { "S01", "no file yet", Expect::Accepted, "", "",
      [] {
        EXPECT_FALSE(drb::readStateFile(tempPath("absent"), twoBodies().scene()).has_value());
        return std::string("accepted: the URDF state is used, and saved at once");
      } },
    { "S02", "empty file", Expect::Refused, "StateFileError", "empty file", parse("") },
    { "S03", "cut in the middle of a line", Expect::Refused, "StateFileError", "truncated",
      parse(good.substr(0, good.size() / 2)) },
    { "S04", "cut at a line end (no trailer)", Expect::Refused, "StateFileError", "no 'end' line",
      parse(good.substr(0, good.find("body ball"))) },
    { "S05", "another format or version", Expect::Refused, "StateFileError", "line 1: expected",
      parse(replacedOnce(good, "v1", "v2")) },
    { "S06", "one flipped bit", Expect::Refused, "StateFileError", "checksum mismatch", parse(flipped) },
    { "S07", "malformed trailer", Expect::Refused, "StateFileError", "expected 'end <count> crc32",
      parse(replacedOnce(good, "crc32", "md5")) },
    { "S08", "body count that disagrees (checksum fixed up)", Expect::Refused, "StateFileError", "body count mismatch",
      parse(resealed(replacedOnce(good, "bodies 2", "bodies 3"))) },
    { "S09", "body line with too few values (checksum fixed up)", Expect::Refused, "StateFileError",
      "expected 'body <name> <6 hex floats>'", parse(resealed(replacedOnce(good, " 0x1p+1\n", "\n"))) },
    { "S10", "malformed percent-encoded name (checksum fixed up)", Expect::Refused, "StateFileError",
      "malformed body name", parse(resealed(replacedOnce(good, "body ball", "body ba%G1"))) },
    { "S11", "decimal instead of a hex float (checksum fixed up)", Expect::Refused, "StateFileError", "not a hex float",
      parse(resealed(replacedOnce(good, "body cube 0x1p-1", "body cube 0.5"))) },
    { "S12", "non-finite value (checksum fixed up)", Expect::Refused, "StateFileError", "not finite",
      parse(resealed(replacedOnce(good, "body cube 0x1p-1", "body cube 0xinf"))) },
    { "S13", "saved for other bodies", Expect::Refused, "StateFileError", "saved for other bodies",
      [=] {
        drb::parseStateFile(drb::formatStateFile(drb::loadSceneFromUrdf(robot("<link name=\"cube\">" + inertial() +
                                                                              "</link>" + floatingJoint("cube")),
                                                                        one),
                                                 { drb::Vector6<double>::Zero() }),
                            scene);
        return std::string("accepted");
      } },
    { "S14", "same bodies, other mass properties", Expect::Refused, "StateFileError", "saved for another scene",
      [=] {
        drb::parseStateFile(drb::formatStateFile(heavier_ball, drb::SceneState(2, drb::Vector6<double>::Zero())),
                            scene);
        return std::string("accepted");
      } },
    { "S15", "data after the trailer", Expect::Refused, "StateFileError", "no 'end' line", parse(good + "extra\n") },
    { "S16", "CRLF line ends (checksum fixed up)", Expect::Refused, "StateFileError", "line 3: expected",
      parse(resealed(replacedOnce(good, "bodies 2\n", "bodies 2\r\n"))) },
    { "S17", "file larger than 64 KiB + 4 KiB per body", Expect::Refused, "StateFileError", "too large",
      [] {
        const std::string path = tempPath("large");
        std::ofstream(path) << std::string(drb::maxStateFileSize(2) + 1, '\n');
        try
        {
          drb::readStateFile(path, twoBodies().scene());
        }
        catch (...)
        {
          std::remove(path.c_str());
          throw;
        }
        std::remove(path.c_str());
        return std::string("accepted");
      } },
    { "S18", "a folder where the file should be", Expect::Refused, "StateFileError", "not a regular file",
      [] {
        const std::string path = tempPath("folder");
        ::mkdir(path.c_str(), 0700);
        try
        {
          drb::readStateFile(path, twoBodies().scene());
        }
        catch (...)
        {
          ::rmdir(path.c_str());
          throw;
        }
        ::rmdir(path.c_str());
        return std::string("accepted");
      } },
    { "S19", "saving into a folder that does not exist", Expect::Refused, "StateFileError",
      "cannot create a temporary file",
      [] {
        drb::writeStateFile("/nonexistent/drb/state", twoBodies().scene(), twoBodies().initialState());
        return std::string("accepted");
      } },
  };
}

// ---------------------------------------------------------------------------

std::string docLine(const std::string& id)
{
  std::ifstream doc(kDoc);
  for (std::string line; std::getline(doc, line);)
    if (line.rfind("| " + id + " |", 0) == 0)
      return replaceAll(line, "\\|", "|");
  return "";
}

class Catalogue : public ::testing::TestWithParam<Row>
{
};

TEST_P(Catalogue, Row)
{
  const Row& row = GetParam();
  std::string outcome;
  std::string type;
  try
  {
    outcome = row.run();
  }
  catch (const drb::Error& e)
  {
    type = errorType(e);
    outcome = portable(e.what());
  }
  if (row.expect == Expect::Refused)
  {
    EXPECT_EQ(type, row.type) << row.input << ": " << outcome;
    EXPECT_NE(outcome.find(row.fragment), std::string::npos) << row.input << ": " << outcome;
  }
  else
  {
    EXPECT_TRUE(type.empty()) << row.input << ": refused: " << outcome;
  }
  const std::string cell = type.empty() ? outcome : type + ": `" + outcome + "`";
  if (const char* markdown = std::getenv("DRB_CATALOGUE_MARKDOWN"))
    std::ofstream(markdown, std::ios::app) << "| " << row.id << " | " << row.input << " | "
                                           << replaceAll(cell, "|", "\\|") << " | |\n";
  const std::string line = docLine(row.id);
  EXPECT_FALSE(line.empty()) << "docs/robustness.md has no row " << row.id;
  if (!line.empty())
  {
    EXPECT_NE(line.find(cell), std::string::npos)
        << "docs/robustness.md row " << row.id << " does not quote the current outcome:\n  " << cell << "\nrow:\n  "
        << line;
  }
}

std::string rowName(const ::testing::TestParamInfo<Row>& info)
{
  return info.param.id;
}

INSTANTIATE_TEST_SUITE_P(Urdf, Catalogue, ::testing::ValuesIn(urdfRows()), rowName);
INSTANTIATE_TEST_SUITE_P(Mesh, Catalogue, ::testing::ValuesIn(meshRows()), rowName);
INSTANTIATE_TEST_SUITE_P(Request, Catalogue, ::testing::ValuesIn(requestRows()), rowName);
INSTANTIATE_TEST_SUITE_P(StateFile, Catalogue, ::testing::ValuesIn(stateFileRows()), rowName);
INSTANTIATE_TEST_SUITE_P(Dynamics, Catalogue, ::testing::ValuesIn(drb_test::catalogue::dynamicsRows()), rowName);
}  // namespace
