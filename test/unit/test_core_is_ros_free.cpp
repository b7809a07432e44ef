// The core library (include/diff_rigid_body/, src/core/) must never include a
// ROS header, so that it builds and runs without roscpp (see docs/architecture.md).
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include <gtest/gtest.h>

namespace fs = std::filesystem;

TEST(CoreIsRosFree, NoCoreFileIncludesARosHeader)
{
  const fs::path root = fs::path(DRB_TEST_DATA_DIR).parent_path();
  // ros/, roscpp, tf2_ros/, tf2_msgs/, *_msgs/, rosconsole and message headers of this package.
  const std::regex ros_include(
      R"(^\s*#\s*include\s*[<"](ros/|roscpp|rosconsole|tf2_ros/|tf2_msgs/|[a-z_]+_msgs/|diff_rigid_body/[A-Z]))");
  int files = 0;
  for (const fs::path& folder : { root / "include" / "diff_rigid_body", root / "src" / "core" })
  {
    ASSERT_TRUE(fs::is_directory(folder)) << folder;
    for (const auto& entry : fs::recursive_directory_iterator(folder))
    {
      if (!entry.is_regular_file())
        continue;
      ++files;
      std::ifstream file(entry.path());
      std::string line;
      for (int number = 1; std::getline(file, line); ++number)
        EXPECT_FALSE(std::regex_search(line, ros_include)) << entry.path().string() << ":" << number << ": " << line;
    }
  }
  EXPECT_GT(files, 10);
}
