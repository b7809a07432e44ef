// The scene and the fuzzed inputs shared by the requests of
// fuzz_scene_queries.cpp: a small fixed scene (a free object with a merged
// link, a fixed-base revolute body, and a floating tree: a free root with a
// revolute joint below it; no files are read), and decoders of names,
// doubles (NaN, +-Inf, subnormals, +-0, huge, +-pi/2, or plain values) and
// vertex indices from a FuzzedDataProvider.
#pragma once

#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>

#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body/parsers/urdf_scene.h"

namespace drb_fuzz
{
namespace drb = diff_rigid_body;

inline const char* const kUrdf =
    "<robot name=\"fuzz\"><link name=\"world\"/>"
    "<link name=\"cube\"><inertial><origin xyz=\"0.01 0.02 0.03\" rpy=\"0.1 0.2 0.3\"/><mass value=\"2\"/>"
    "<inertia ixx=\"0.1\" iyy=\"0.2\" izz=\"0.25\" ixy=\"0.01\" ixz=\"0.02\" iyz=\"-0.03\"/></inertial>"
    "<collision><geometry><box size=\"0.2 0.3 0.4\"/></geometry></collision></link>"
    "<link name=\"cap\"><collision><origin xyz=\"0 0 0.1\"/><geometry><cylinder radius=\"0.05\" length=\"0.1\"/>"
    "</geometry></collision></link>"
    "<joint name=\"cap_joint\" type=\"fixed\"><parent link=\"cube\"/><child link=\"cap\"/>"
    "<origin xyz=\"0 0 0.2\"/></joint>"
    "<link name=\"ball\"><inertial><mass value=\"1\"/><inertia ixx=\"0.004\" iyy=\"0.004\" izz=\"0.004\" ixy=\"0\" "
    "ixz=\"0\" iyz=\"0\"/></inertial><collision><geometry><sphere radius=\"0.1\"/></geometry></collision></link>"
    "<joint name=\"jc\" type=\"floating\"><parent link=\"world\"/><child link=\"cube\"/>"
    "<origin xyz=\"0 0 1\" rpy=\"0.1 0.2 0.3\"/></joint>"
    "<joint name=\"jb\" type=\"revolute\"><parent link=\"world\"/><child link=\"ball\"/>"
    "<origin xyz=\"1 0 1\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>"
    "</joint>"
    "<link name=\"torso\"><inertial><origin xyz=\"0 0.01 0.02\"/><mass value=\"3\"/><inertia ixx=\"0.05\" "
    "iyy=\"0.06\" izz=\"0.04\" ixy=\"0.001\" ixz=\"0\" iyz=\"0.002\"/></inertial></link>"
    "<link name=\"limb\"><inertial><origin xyz=\"0 0 -0.2\"/><mass value=\"0.5\"/><inertia ixx=\"0.01\" "
    "iyy=\"0.01\" izz=\"0.001\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial><collision><geometry><box "
    "size=\"0.05 0.05 0.4\"/></geometry></collision></link>"
    "<joint name=\"jt\" type=\"floating\"><parent link=\"world\"/><child link=\"torso\"/>"
    "<origin xyz=\"0 2 1\"/></joint>"
    "<joint name=\"jl\" type=\"revolute\"><parent link=\"torso\"/><child link=\"limb\"/>"
    "<origin xyz=\"0.1 0 0\" rpy=\"0.3 0 0\"/><axis xyz=\"0 1 0\"/><limit lower=\"-2\" upper=\"2\" effort=\"1\" "
    "velocity=\"1\"/></joint></robot>";

inline const drb::SceneQueries& queries()
{
  static const drb::SceneQueries instance(drb::loadSceneFromUrdf(kUrdf));
  return instance;
}

inline double fuzzedDouble(FuzzedDataProvider& in)
{
  static const double kSpecial[] = { std::numeric_limits<double>::quiet_NaN(),
                                     -std::numeric_limits<double>::quiet_NaN(),
                                     std::numeric_limits<double>::infinity(),
                                     -std::numeric_limits<double>::infinity(),
                                     std::numeric_limits<double>::denorm_min(),
                                     -std::numeric_limits<double>::denorm_min(),
                                     std::numeric_limits<double>::min(),
                                     std::numeric_limits<double>::max(),
                                     std::numeric_limits<double>::lowest(),
                                     0.0,
                                     -0.0,
                                     1.5707963267948966,
                                     -1.5707963267948966,
                                     1e154,
                                     1e308,
                                     1.0 };
  switch (in.ConsumeIntegralInRange<int>(0, 3))
  {
    case 0:
      return in.PickValueInArray(kSpecial);
    case 1:
    {
      std::uint64_t bits = in.ConsumeIntegral<std::uint64_t>();  // any IEEE pattern, NaN payloads included
      double value;
      std::memcpy(&value, &bits, sizeof value);
      return value;
    }
    case 2:
      return in.ConsumeFloatingPoint<double>();
    default:
      return in.ConsumeFloatingPointInRange<double>(-10.0, 10.0);
  }
}

inline std::string fuzzedName(FuzzedDataProvider& in)
{
  static const char* const kNames[] = { "cube", "ball", "torso", "cap", "world", "", "ghost", "cube " };
  if (in.ConsumeBool())
    return in.PickValueInArray(kNames);
  return in.ConsumeRandomLengthString(24);
}

inline std::vector<double> fuzzedDoubles(FuzzedDataProvider& in, std::size_t max_count)
{
  std::vector<double> values(in.ConsumeIntegralInRange<std::size_t>(0, max_count));
  // Often a size the service expects, so that validation goes past the size checks.
  for (double& value : values)
    value = fuzzedDouble(in);
  return values;
}

inline std::vector<std::uint32_t> fuzzedVertices(FuzzedDataProvider& in)
{
  std::vector<std::uint32_t> vertices(in.ConsumeIntegralInRange<std::size_t>(0, 24));
  for (std::uint32_t& v : vertices)
    v = in.ConsumeBool() ? in.ConsumeIntegralInRange<std::uint32_t>(0, 120) : in.ConsumeIntegral<std::uint32_t>();
  return vertices;
}

inline std::vector<std::string> fuzzedNames(FuzzedDataProvider& in)
{
  std::vector<std::string> names(in.ConsumeIntegralInRange<std::size_t>(0, 4));
  for (std::string& name : names)
    name = fuzzedName(in);
  return names;
}

}  // namespace drb_fuzz
