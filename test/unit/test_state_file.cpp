// The durable state file (state_file.h): exact round trips, atomic durable
// writes, and the refusal of every damaged or foreign file with a clear
// error (never a partial read).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>

#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "diff_rigid_body/state/state_file.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "../support/expect_throws.h"
#include "../support/plumbing_scenes.h"
#include "../support/state_files.h"
#include "../support/urdf_builders.h"

namespace drb = diff_rigid_body;
using drb_test::bitwiseEqual;
using drb_test::entriesIn;
using drb_test::reseal;
using drb_test::withoutTrailer;

namespace
{
std::string twoBodyUrdf(const std::string& second_name = "ball", const std::string& cube_mass = "2")
{
  drb_test::urdf::TwoBodies scene;
  scene.cube_mass = cube_mass;
  scene.cube_inertia = drb_test::urdf::diagonalInertia("0.1", "0.2", "0.25");
  scene.cube_rpy = "0.1 0.2 0.3";
  scene.ball_name = second_name;
  return drb_test::urdf::twoBodies(scene);
}

// A state whose values need every bit: irrational-looking, negative zero,
// subnormal, huge and tiny magnitudes.
drb::SceneState awkwardState()
{
  drb::SceneState state(2, Eigen::VectorXd(6));
  state[0] << 0.1, -0.0, 3.141592653589793, 1e-310, -1.7976931348623157e308, 2.2250738585072014e-308;
  state[1] << -1.0 / 3.0, std::nextafter(1.0, 2.0), 1e300, -5e-324, 0.0, 123456.789;
  return state;
}
}  // namespace

TEST(StateFile, RoundTripIsBitExact)
{
  const drb::Scene scene = drb::loadSceneFromUrdf(twoBodyUrdf());
  const drb::SceneState state = awkwardState();
  const std::string text = drb::formatStateFile(scene, state);
  EXPECT_TRUE(bitwiseEqual(drb::parseStateFile(text, scene), state)) << text;
  // Negative zero survives (it would not through a plain decimal parser that drops the sign).
  EXPECT_TRUE(std::signbit(drb::parseStateFile(text, scene)[0][1]));
}

TEST(StateFile, DocumentedFormat)
{
  const drb::Scene scene = drb::loadSceneFromUrdf(twoBodyUrdf());
  drb::SceneState state(2, Eigen::VectorXd::Zero(6));
  state[0] << 1.5, -2.0, 0.0, -0.0, 0.1, 1.0;
  const std::string text = drb::formatStateFile(scene, state);
  std::istringstream lines(text);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "diff_rigid_body state file v1");
  std::getline(lines, line);
  EXPECT_EQ(line.substr(0, 12), "fingerprint ");
  EXPECT_EQ(line.size(), 12u + 16u);
  std::getline(lines, line);
  EXPECT_EQ(line, "bodies 2");
  std::getline(lines, line);
  EXPECT_EQ(line, "body cube 0x1.8p+0 -0x1p+1 0x0p+0 -0x0p+0 0x1.999999999999ap-4 0x1p+0");
  std::getline(lines, line);
  EXPECT_EQ(line, "body ball 0x0p+0 0x0p+0 0x0p+0 0x0p+0 0x0p+0 0x0p+0");
  std::getline(lines, line);
  EXPECT_EQ(line.substr(0, 12), "end 2 crc32 ");
  EXPECT_EQ(line.size(), 12u + 8u);
  EXPECT_EQ(drb::crc32("123456789"), 0xcbf43926u);  // the CRC-32 check value
}

TEST(StateFile, NamesArePercentEncoded)
{
  const drb::Scene scene = drb::loadSceneFromUrdf(twoBodyUrdf("odd name%2"));
  const drb::SceneState state = awkwardState();
  const std::string text = drb::formatStateFile(scene, state);
  EXPECT_NE(text.find("body odd%20name%252 "), std::string::npos) << text;
  EXPECT_TRUE(bitwiseEqual(drb::parseStateFile(text, scene), state));
}

TEST(StateFile, RefusesDamagedFiles)
{
  const drb::Scene scene = drb::loadSceneFromUrdf(twoBodyUrdf());
  const std::string good = drb::formatStateFile(scene, awkwardState());
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile("", scene), drb::StateFileError, "empty file");
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(good.substr(0, good.size() - 1), scene), drb::StateFileError,
                            "truncated: the last line has no line end");
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(good.substr(0, good.find("body ball")), scene), drb::StateFileError,
                            "truncated: no 'end' line");
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(good + "body extra 0x0p+0\n", scene), drb::StateFileError,
                            "truncated: no 'end' line");
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile("not a state file\n", scene), drb::StateFileError,
                            "line 1: expected 'diff_rigid_body state file v1'");
  DRB_EXPECT_THROWS_MESSAGE(
      drb::parseStateFile("diff_rigid_body state file v2\n" + good.substr(good.find('\n') + 1), scene),
      drb::StateFileError, "line 1: expected");
  // One flipped bit anywhere before the trailer.
  std::string flipped = good;
  flipped[good.find("body cube") + 12] ^= 0x01;
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(flipped, scene), drb::StateFileError,
                            "checksum mismatch: the file is corrupt");
  std::string bad_end = good;
  bad_end.replace(bad_end.rfind("crc32"), 5, "crc33");
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(bad_end, scene), drb::StateFileError,
                            "expected 'end <count> crc32 <8 hex digits>'");
  // Correct checksums over wrong contents.
  const std::string body = withoutTrailer(good);
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(reseal(body, 3), scene), drb::StateFileError, "body count mismatch");
  const std::string count = drb_test::replacedOnce(body, "bodies 2", "bodies 3");
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(reseal(count, 3), scene), drb::StateFileError,
                            "body count mismatch: 'bodies 3', 2 body lines");
  // The cube's body line replaced by `line`, resealed.
  const auto with_cube_line = [&](const std::string& line) {
    return reseal(body.substr(0, body.find("body cube")) + line + "\n" + body.substr(body.find("body ball")), 2);
  };
  DRB_EXPECT_THROWS_MESSAGE(
      drb::parseStateFile(with_cube_line("body cube nan 0x0p+0 0x0p+0 0x0p+0 0x0p+0 0x0p+0"), scene),
      drb::StateFileError, "q[0] of body 'cube': not a hex float: 'nan'");
  DRB_EXPECT_THROWS_MESSAGE(
      drb::parseStateFile(with_cube_line("body cube 0x0p+0 0xinf 0x0p+0 0x0p+0 0x0p+0 0x0p+0"), scene),
      drb::StateFileError, "q[1] of body 'cube': not finite");
  DRB_EXPECT_THROWS_MESSAGE(
      drb::parseStateFile(with_cube_line("body cube 0.5 0x0p+0 0x0p+0 0x0p+0 0x0p+0 0x0p+0"), scene),
      drb::StateFileError, "q[0] of body 'cube': not a hex float: '0.5'");
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(with_cube_line("body cube 0x0p+0 0x0p+0"), scene), drb::StateFileError,
                            "line 4: expected 'body <name> <6 hex floats>'");
  DRB_EXPECT_THROWS_MESSAGE(
      drb::parseStateFile(with_cube_line("body cu%4 0x0p+0 0x0p+0 0x0p+0 0x0p+0 0x0p+0 0x0p+0"), scene),
      drb::StateFileError, "line 4: malformed body name 'cu%4'");
  const std::string crlf = drb_test::replacedOnce(body, "bodies 2\n", "bodies 2\r\n");
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(reseal(crlf, 2), scene), drb::StateFileError,
                            "line 3: expected 'bodies <count>'");
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(std::string(drb::maxStateFileSize(2) + 1, '\n'), scene),
                            drb::StateFileError, "too large");
}

TEST(StateFile, RefusesFilesOfAnotherScene)
{
  const drb::Scene scene = drb::loadSceneFromUrdf(twoBodyUrdf());
  const drb::SceneState state = awkwardState();
  const drb::Scene renamed = drb::loadSceneFromUrdf(twoBodyUrdf("sphere"));
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(drb::formatStateFile(renamed, state), scene), drb::StateFileError,
                            "saved for other bodies: the file has [cube, sphere], the scene has [cube, ball]");
  const drb::Scene heavier = drb::loadSceneFromUrdf(twoBodyUrdf("ball", "2.5"));
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(drb::formatStateFile(heavier, state), scene), drb::StateFileError,
                            "saved for another scene: fingerprint");
  drb::SceneOptions one_body;
  one_body.bodies = { "cube" };
  const drb::Scene subset = drb::loadSceneFromUrdf(twoBodyUrdf(), one_body);
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(drb::formatStateFile(subset, { state[0] }), scene), drb::StateFileError,
                            "the file has [cube], the scene has [cube, ball]");
  EXPECT_NE(drb::sceneFingerprint(scene), drb::sceneFingerprint(heavier));
  EXPECT_EQ(drb::sceneFingerprint(scene), drb::sceneFingerprint(drb::loadSceneFromUrdf(twoBodyUrdf())));
}

TEST(StateFile, RefusesToSaveInvalidStates)
{
  const drb::Scene scene = drb::loadSceneFromUrdf(twoBodyUrdf());
  drb::SceneState state = awkwardState();
  EXPECT_THROW(drb::formatStateFile(scene, { state[0] }), drb::StateFileError);
  state[1][4] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(drb::formatStateFile(scene, state), drb::StateFileError);
}

TEST(StateFile, DurableWriteAndRead)
{
  const drb::Scene scene = drb::loadSceneFromUrdf(twoBodyUrdf());
  const std::string folder = drb_test::tempFolder("drb_state_file");
  const std::string path = folder + "/state";
  EXPECT_FALSE(drb::readStateFile(path, scene).has_value());  // no file yet: not an error
  drb::SceneState state = awkwardState();
  drb::writeStateFile(path, scene, state);
  EXPECT_TRUE(bitwiseEqual(*drb::readStateFile(path, scene), state));
  state[1][5] = 42.0;
  drb::writeStateFile(path, scene, state);  // replaces it
  EXPECT_TRUE(bitwiseEqual(*drb::readStateFile(path, scene), state));
  EXPECT_EQ(entriesIn(folder), 1u);  // no temporary file left behind

  // A damaged file names its path, and can be set aside for inspection.
  std::ofstream(path, std::ios::app) << "junk\n";
  DRB_EXPECT_THROWS_MESSAGE(drb::readStateFile(path, scene), drb::StateFileError,
                            "state file '" + path + "': truncated");
  EXPECT_EQ(drb::setStateFileAside(path), path + ".bad");
  EXPECT_FALSE(drb::readStateFile(path, scene).has_value());
  std::remove((path + ".bad").c_str());

  // Unwritable places fail with the system's reason, and leave nothing behind.
  DRB_EXPECT_THROWS_MESSAGE(drb::writeStateFile(folder + "/missing/state", scene, state), drb::StateFileError,
                            "cannot create a temporary file in '" + folder + "/missing'", "No such file or directory");
  ::mkdir(path.c_str(), 0700);  // a folder where the file should be
  EXPECT_THROW(drb::writeStateFile(path, scene, state), drb::StateFileError);
  EXPECT_THROW(drb::readStateFile(path, scene), drb::StateFileError);
  EXPECT_EQ(entriesIn(folder), 1u);
  ::rmdir(path.c_str());

  // Temporary files of a save interrupted by a kill are removed on start; others stay.
  std::ofstream(path + ".tmp.AbC123") << "half";
  std::ofstream(path + ".tmp.other") << "not ours";
  std::ofstream(folder + "/unrelated.tmp.AbC123") << "not ours";
  EXPECT_EQ(drb::removeStaleTemporaryFiles(path), 1u);
  EXPECT_EQ(entriesIn(folder), 2u);  // the two that are not ours
  std::remove((path + ".tmp.other").c_str());
  std::remove((folder + "/unrelated.tmp.AbC123").c_str());

  // Oversized files are refused from their size, before they are read.
  std::ofstream(path) << std::string(drb::maxStateFileSize(2) + 1, 'x');
  DRB_EXPECT_THROWS_MESSAGE(drb::readStateFile(path, scene), drb::StateFileError, "too large");
  std::remove(path.c_str());
  ::rmdir(folder.c_str());
}

// Free scenes keep version 1's fingerprint (values of the version 1 code),
// so that their state files still load.
TEST(StateFile, FreeSceneFingerprintsAreVersion1s)
{
  EXPECT_EQ(drb::sceneFingerprint(drb::loadSceneFromUrdf(twoBodyUrdf())), 0xbc940bca4f53be20ull);
  EXPECT_EQ(drb::sceneFingerprint(drb::loadSceneFromUrdf(drb_test::urdf::twoBodies())), 0x2dcad80891de5090ull);
}

// Articulated bodies: a line of d values per body, round trips bit for bit,
// and a file of another robot (one joint different) is refused.
TEST(StateFile, ArticulatedBodiesRoundTripAndAreFingerprinted)
{
  const drb::Scene scene = drb_test::plumbing::scene();
  drb::SceneState state;
  for (const drb::BodyModel& body : scene.bodies)
    state.push_back(body.initial_x);
  state[2][8] = -0.0;
  state[3][1] = 5e-324;
  const std::string text = drb::formatStateFile(scene, state);
  EXPECT_NE(text.find("\nbody arm 0x1.999999999999ap-4 0x1.999999999999ap-3 0x1.3333333333333p-2 0x1p+0 0x1p+1 "
                      "0x1.8p+1 0x1.999999999999ap-2 -0x1p-1 -0x0p+0\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("\nbody crane 0x1.6666666666666p-1 0x0.0000000000001p-1022\n"), std::string::npos) << text;
  EXPECT_TRUE(drb_test::bitwiseEqual(drb::parseStateFile(text, scene), state)) << text;

  // Each change below moves the robot's vertices for the same x: another fingerprint.
  const auto changed = [](const std::function<void(drb::BodyModel&)>& change) {
    drb::BodyModel arm = drb_test::plumbing::arm();
    change(arm);
    drb_test::core_body::refreshDerivedFields(arm);
    return drb_test::plumbing::scene(arm);
  };
  const std::vector<std::pair<std::string, drb::Scene>> others = {
    { "origin", changed([](drb::BodyModel& b) { b.segments[2].placement_translation[0] += 1e-12; }) },
    { "axis", changed([](drb::BodyModel& b) { b.segments[1].axis = -b.segments[1].axis; }) },
    { "motion", changed([](drb::BodyModel& b) { b.segments[3].joint_type = drb::JointType::Revolute; }) },
    { "mimic", changed([](drb::BodyModel& b) { b.dofs[b.segments[4].first_dof].multiplier = 0.5; }) },
    { "mass", changed([](drb::BodyModel& b) { b.segments[1].inertia.mass *= 2; }) },
    { "vertex", changed([](drb::BodyModel& b) { b.vertices(1, 13) += 1e-9; }) },
    { "joint", changed([](drb::BodyModel& b) { b.segments[1].joint = "hip"; }) },
    { "tree", changed([](drb::BodyModel& b) { b.segments[4].parent = 1; }) },
  };
  for (const auto& other : others)
  {
    EXPECT_NE(drb::sceneFingerprint(other.second), drb::sceneFingerprint(scene)) << other.first;
    DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(text, other.second), drb::StateFileError,
                              "saved for another scene");
  }
  // A line with the wrong number of values for its body, its checksum fixed up.
  const std::string short_crane = reseal(withoutTrailer(drb_test::replacedOnce(text, " 0x0.0000000000001p-1022\n", "\n")), 4);
  DRB_EXPECT_THROWS_MESSAGE(drb::parseStateFile(short_crane, scene), drb::StateFileError,
                            "line 7: expected 'body <name> <2 hex floats>', got 'body crane 0x1.6666666666666p-1'");
  state[3].resize(3);
  DRB_EXPECT_THROWS_MESSAGE(drb::formatStateFile(scene, state), drb::StateFileError,
                            "cannot save 3 values for body 'crane' of 2 dofs");
}
