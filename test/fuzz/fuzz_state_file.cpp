// libFuzzer target: state file text -> parseStateFile, on a small fixed
// scene (the same as fuzz_scene_queries'; no files are read or written).
//
// Invariants: the parser either throws StateFileError, or returns one finite
// q per scene body; a parsed state formats and parses back bit for bit.
#include <cstdint>
#include <cstring>
#include <string>

#include "diff_rigid_body/state/state_file.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "fuzz_invariants.h"

namespace
{
namespace drb = diff_rigid_body;

const drb::Scene& scene()
{
  static const drb::Scene instance = drb::loadSceneFromUrdf(
      "<robot name=\"fuzz\"><link name=\"world\"/>"
      "<link name=\"cube\"><inertial><mass value=\"2\"/><inertia ixx=\"0.1\" iyy=\"0.2\" izz=\"0.25\" ixy=\"0\" "
      "ixz=\"0\" iyz=\"0\"/></inertial><collision><geometry><box size=\"0.2 0.3 0.4\"/></geometry></collision></link>"
      "<link name=\"odd name%\"><inertial><mass value=\"1\"/><inertia ixx=\"0.004\" iyy=\"0.004\" izz=\"0.004\" "
      "ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>"
      "<joint name=\"jc\" type=\"floating\"><parent link=\"world\"/><child link=\"cube\"/>"
      "<origin xyz=\"0 0 1\"/></joint>"
      "<joint name=\"jb\" type=\"floating\"><parent link=\"world\"/><child link=\"odd name%\"/></joint></robot>");
  return instance;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const std::string text(reinterpret_cast<const char*>(data), size);
  drb::SceneState state;
  try
  {
    state = drb::parseStateFile(text, scene());
  }
  catch (const drb::StateFileError&)
  {
    return 0;
  }
  drb_fuzz::require(state.size() == scene().bodies.size(), "parsed state has the wrong size");
  for (std::size_t i = 0; i < state.size(); ++i)
  {
    drb_fuzz::require(static_cast<std::size_t>(state[i].size()) == scene().bodies[i].coordinates,
                      "parsed x of wrong length");
    drb_fuzz::requireAllFinite(state[i].data(), state[i].size(), "parsed q");
  }
  const drb::SceneState again = drb::parseStateFile(drb::formatStateFile(scene(), state), scene());
  for (std::size_t i = 0; i < state.size(); ++i)
    drb_fuzz::require(std::memcmp(state[i].data(), again[i].data(), sizeof(double) * state[i].size()) == 0,
                      "format/parse round trip is not bit exact");
  return 0;
}
