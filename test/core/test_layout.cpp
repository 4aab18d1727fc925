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

// The core's folders by layer (docs/engine.md): an include may read its own layer or one below.
int layer_of(const std::string& folder) {
  static const std::vector<std::pair<std::string, int>> kLayers = {
      {"common", 0},  {"model", 1}, {"config", 2}, {"factored", 3}, {"solve", 3},     {"serial", 4},
      {"bounds", 4},  {"io", 4},    {"opencl", 5}, {"scale_out", 6}, {"", 7}};  // "": src/core itself (plan, engine)
  for (const auto& [name, layer] : kLayers)
    if (folder == name) return layer;
  return -1;
}

// The first folder of a path relative to src/core ("" for a file directly in src/core).
std::string top_folder(const std::string& relative) {
  const auto slash = relative.find('/');
  return slash == std::string::npos ? std::string() : relative.substr(0, slash);
}

TEST(Layout, CoreIncludesReadDownTheLayers) {
  const fs::path core = fs::path(AMYTISS_SOURCE_DIR) / "src/core";
  const std::regex internal_include(R"re(^\s*#\s*include\s*"([a-z_]+/[^"]+)")re");
  std::size_t checked = 0;
  for (const auto& file : sources_under(core)) {
    const std::string from = top_folder(fs::relative(file, core).generic_string());
    ASSERT_GE(layer_of(from), 0) << file << " is in a folder without a layer: add it to kLayers";
    std::ifstream input(file);
    std::string line;
    std::smatch match;
    for (int number = 1; std::getline(input, line); ++number) {
      if (!std::regex_search(line, match, internal_include) || match[1].str().rfind("amytiss/", 0) == 0) continue;
      const std::string to = top_folder(match[1].str());
      if (layer_of(to) < 0) continue;  // a file of the same folder named by a subfolder path
      ++checked;
      EXPECT_LE(layer_of(to), layer_of(from)) << file.string() << ":" << number << " reads up a layer: " << line;
    }
  }
  EXPECT_GE(checked, 50u) << "too few internal includes found under " << core;
}

TEST(Layout, RosIncludePatternMatchesWhatItMustRefuse) {
  EXPECT_TRUE(std::regex_search("#include <ros/ros.h>", kRosInclude));
  EXPECT_TRUE(std::regex_search("  #include \"std_msgs/Float64.h\"", kRosInclude));
  EXPECT_TRUE(std::regex_search("#include <amytiss/GetInput.h>", kRosInclude));
  EXPECT_FALSE(std::regex_search("#include \"amytiss/policy.hpp\"", kRosInclude));
  EXPECT_FALSE(std::regex_search("#include <rosetta/stone.hpp>", kRosInclude));
}

}  // namespace
