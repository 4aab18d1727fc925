// The core library, its public headers and the command-line tool stay ROS-free: they must build
// on the GPU machine, which has no ROS.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

// Headers of ROS itself and of the ROS message packages this project uses.
const std::regex kRosInclude(
    R"(^\s*#\s*include\s*[<"](ros|roscpp|rosconsole|std_msgs|geometry_msgs|visualization_msgs|actionlib|actionlib_msgs|amytiss/[A-Z]\w*\.h)\b)");

std::vector<fs::path> sources_under(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    const auto extension = entry.path().extension().string();
    if (entry.is_regular_file() &&
        (extension == ".cpp" || extension == ".hpp" || extension == ".h" || extension == ".cl"))
      files.push_back(entry.path());
  }
  return files;
}

TEST(Layout, CoreHeadersSourcesAndCliIncludeNoRos) {
  const fs::path root = AMYTISS_SOURCE_DIR;
  std::vector<fs::path> files;
  for (const char* folder : {"include/amytiss", "src/core", "src/cli"}) {
    const auto found = sources_under(root / folder);
    files.insert(files.end(), found.begin(), found.end());
  }
  // Guards against a wrong root making the scan vacuous.
  ASSERT_GE(files.size(), 20u) << "scanned too few files under " << root;

  for (const auto& file : files) {
    std::ifstream input(file);
    ASSERT_TRUE(input) << "cannot read " << file;
    std::string line;
    for (int number = 1; std::getline(input, line); ++number)
      EXPECT_FALSE(std::regex_search(line, kRosInclude))
          << file.string() << ":" << number << " includes ROS: " << line;
  }
}

TEST(Layout, RosIncludePatternMatchesWhatItMustRefuse) {
  EXPECT_TRUE(std::regex_search("#include <ros/ros.h>", kRosInclude));
  EXPECT_TRUE(std::regex_search("  #include \"std_msgs/Float64.h\"", kRosInclude));
  EXPECT_TRUE(std::regex_search("#include <amytiss/GetInput.h>", kRosInclude));
  EXPECT_FALSE(std::regex_search("#include \"amytiss/policy.hpp\"", kRosInclude));
  EXPECT_FALSE(std::regex_search("#include <rosetta/stone.hpp>", kRosInclude));
}

}  // namespace
