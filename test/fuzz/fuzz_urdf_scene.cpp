// libFuzzer target: URDF XML text -> scene (loadSceneFromUrdf), then every
// query at the scene's initial state.
//
// The input is the URDF text. Before loading, every <mesh filename> is
// rewritten so that only small committed fixtures (test/meshes/) or paths
// under /nonexistent/ are ever opened: the file's base name picks a fixture
// if it names one, otherwise the path becomes /nonexistent/drb_fuzz/<name>;
// the package://, file://, absolute or relative form is kept. (The document
// is re-printed by tinyxml2 for that; the core parses it with tinyxml2 first
// anyway, so nothing tinyxml2 rejects reaches urdfdom or a mesh file.)
// Options (density, geometry source) follow the input size modulo 4.
//
// Passes when loading either throws a diff_rigid_body::Error or gives a
// scene that satisfies requireValidScene(), and the queries either refuse
// with InvalidArgumentError or answer with finite numbers. Anything else
// (a crash, a sanitizer report, another exception, a non-finite answer) is
// a finding.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>

#include <tinyxml2.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "fuzz_invariants.h"

namespace
{
namespace drb = diff_rigid_body;

// The package's folder: $DRB_FUZZ_PACKAGE_DIR (scripts/fuzz: a link to the checkout with a name
// of fixed length, so that runs from any checkout lay out memory alike), else the checkout.
const std::string kPackageDir = std::getenv("DRB_FUZZ_PACKAGE_DIR") ? std::getenv("DRB_FUZZ_PACKAGE_DIR") :
                                                                      std::string(DRB_TEST_DATA_DIR) + "/..";
const std::string kMeshDir = kPackageDir + "/test/meshes";
const std::set<std::string> kFixtures = { "box_2x1x0.5.stl",   "tetrahedron.obj",      "bad_degenerate.obj",
                                          "bad_empty.stl",     "bad_garbage.stl",      "bad_huge.obj",
                                          "bad_nan_vertex.obj", "bad_no_triangles.obj", "bad_open_surface.obj" };

std::string safeBaseName(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  std::string safe;
  for (char c : name.substr(0, 64))
    safe += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-') ? c : '_';
  return safe.empty() ? "empty" : safe;
}

// The mesh reference with the same form as `filename`, pointing to a
// fixture or to /nonexistent/.
std::string safeMeshReference(const std::string& filename)
{
  const std::string name = safeBaseName(filename);
  const bool fixture = kFixtures.count(name) > 0;
  const std::string absolute = fixture ? kMeshDir + "/" + name : "/nonexistent/drb_fuzz/" + name;
  if (filename.rfind("package://", 0) == 0)
  {
    const std::string package = filename.substr(10, filename.find('/', 10) - 10);
    const std::string rest = fixture ? "/test/meshes/" + name : "/nonexistent/" + name;
    return "package://" + (package == "diff_rigid_body" ? package : safeBaseName(package)) + rest;
  }
  if (filename.rfind("file://", 0) == 0)
    return "file://" + absolute;
  if (!filename.empty() && filename[0] == '/')
    return absolute;
  return fixture ? name : "nonexistent_drb_fuzz/" + name;  // relative to base_directory = test/meshes
}

void sanitizeMeshes(tinyxml2::XMLElement* element)
{
  for (; element; element = element->NextSiblingElement())
  {
    if (std::strcmp(element->Name(), "mesh") == 0)
    {
      const char* filename = element->Attribute("filename");
      if (filename)
        element->SetAttribute("filename", safeMeshReference(filename).c_str());
    }
    sanitizeMeshes(element->FirstChildElement());
  }
}

void exerciseQueries(const drb::Scene& scene)
{
  const drb::SceneQueries queries(scene);
  const drb::SceneState state = queries.initialState();
  try
  {
    const drb::MassMatrixAnswer answer = queries.massMatrices(state, {}, {}, true);
    drb_fuzz::requireAllFinite(answer.mass_matrices.data(), answer.mass_matrices.size(), "mass_matrices");
    drb_fuzz::requireAllFinite(answer.derivatives.data(), answer.derivatives.size(), "derivatives");
  }
  catch (const drb::InvalidArgumentError&)
  {
  }
  for (std::size_t i = 0; i < queries.bodyCount(); ++i)
  {
    const std::string& name = queries.body(i).name;
    try
    {
      std::vector<double> positions, jacobians;
      queries.vertexJacobians(state, name, {}, {}, positions, jacobians);
      drb_fuzz::requireAllFinite(positions.data(), positions.size(), "positions of " + name);
      drb_fuzz::requireAllFinite(jacobians.data(), jacobians.size(), "jacobians of " + name);
      const std::vector<double> gradients(positions.size(), 1.0);
      const Eigen::VectorXd gradient = queries.backprop(state, name, {}, gradients, {});
      drb_fuzz::require(static_cast<std::size_t>(gradient.size()) == queries.dofs(i), "backprop size of " + name);
      drb_fuzz::requireAllFinite(gradient.data(), gradient.size(), "backprop of " + name);
    }
    catch (const drb::InvalidArgumentError&)
    {
    }
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  if (size > 65536)
    return 0;
  std::string xml(reinterpret_cast<const char*>(data), size);
  tinyxml2::XMLDocument document;
  if (document.Parse(xml.c_str(), xml.size()) == tinyxml2::XML_SUCCESS)
  {
    sanitizeMeshes(document.FirstChildElement());
    tinyxml2::XMLPrinter printer;
    document.Print(&printer);
    xml = printer.CStr();
  }

  drb::SceneOptions options;
  options.base_directory = kMeshDir;
  options.find_package = [](const std::string& package) {
    return package == "diff_rigid_body" ? kPackageDir : std::string();
  };
  if (size % 2 == 1)
    options.density = size % 4 == 1 ? 1000.0 : 1e-3;  // [kg/m^3]
  if (size % 4 >= 2)
    options.geometry = drb::GeometrySource::Visual;

  drb::Scene scene;
  try
  {
    scene = drb::loadSceneFromUrdf(xml, options);
  }
  catch (const drb::Error&)
  {
    return 0;  // refused with a typed error: fine
  }
  drb_fuzz::requireValidScene(scene);
  exerciseQueries(scene);
  return 0;
}
