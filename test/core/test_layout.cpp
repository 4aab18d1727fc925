// The core library, its public headers and the command-line tool stay ROS-free: they must build
// on the GPU machine, which has no ROS.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
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
      {"bounds", 4},  {"io", 4},    {"simulate", 4}, {"opencl", 5}, {"scale_out", 6}, {"", 7},
      {"refine", 8}};  // "": src/core itself (plan, engine); refine/ runs the engine in rounds
  for (const auto& [name, layer] : kLayers)
    if (folder == name) return layer;
  return -1;
}

// The layer of each public header: that of the folder that implements it. Headers of types and
// interfaces only (errors, stopwatch, version, scale_out's Communicator) and those whose code is
// common's (the enum names of config.hpp and synthesis_types.hpp) are common's. config.hpp also
// declares config/'s reading and checks, which the layers below config/ do not call.
const std::map<std::string, std::string>& public_header_folders() {
  static const std::map<std::string, std::string> folders = {
      {"abstraction.hpp", "model"}, {"apriori_error.hpp", "model"},  {"closed_loop.hpp", "simulate"},
      {"config.hpp", "common"},     {"plant.hpp", "simulate"},        {"spec_sets.hpp", "simulate"},
      {"enclosure.hpp", "model"},   {"engine.hpp", ""},               {"enum_names.hpp", "common"},
      {"errors.hpp", "common"},     {"expression.hpp", "model"},      {"expression_step.hpp", "model"},
      {"footprint.hpp", "model"},   {"format.hpp", "common"},         {"grid.hpp", "model"},
      {"grid_rules.hpp", "model"},  {"interval.hpp", "model"},        {"model.hpp", "model"},
      {"model_export.hpp", "io"},   {"noise.hpp", "model"},           {"noise_sampler.hpp", "model"},
      {"policy.hpp", "solve"},      {"policy_file.hpp", "io"},        {"refinement.hpp", "refine"},
      {"resources.hpp", "common"},
      {"roofline.hpp", "common"},   {"run_id.hpp", "common"},         {"scale_out.hpp", "common"},
      {"stopwatch.hpp", "common"},  {"synthesis_types.hpp", "common"}, {"version.hpp", "common"}};
  return folders;
}

// The first folder of a path relative to src/core ("" for a file directly in src/core).
std::string top_folder(const std::string& relative) {
  const auto slash = relative.find('/');
  return slash == std::string::npos ? std::string() : relative.substr(0, slash);
}

// The layer an include names: an internal header's folder's, a public header's from the table;
// -1 for a public header missing from it, -2 for a file of the same folder named by a subfolder path.
int layer_of_include(const std::string& path) {
  if (path.rfind("amytiss/", 0) == 0) {
    const auto found = public_header_folders().find(path.substr(8));
    return found == public_header_folders().end() ? -1 : layer_of(found->second);
  }
  const int layer = layer_of(top_folder(path));
  return layer < 0 ? -2 : layer;
}

TEST(Layout, EveryPublicHeaderHasTheLayerOfItsFolder) {
  const fs::path include = fs::path(AMYTISS_SOURCE_DIR) / "include/amytiss";
  std::size_t headers = 0;
  for (const auto& entry : fs::directory_iterator(include)) {
    if (entry.path().extension() != ".hpp") continue;
    ++headers;
    const auto found = public_header_folders().find(entry.path().filename().string());
    EXPECT_TRUE(found != public_header_folders().end())
        << entry.path() << " has no layer: add it to public_header_folders()";
  }
  EXPECT_EQ(headers, public_header_folders().size()) << "a header of the table is gone: remove it there";
  for (const auto& [header, folder] : public_header_folders())
    EXPECT_GE(layer_of(folder), 0) << header << ": " << folder << " is no folder of kLayers";

  // A source whose first include is a public header implements it, in the table's folder (but
  // config/'s part of config.hpp, see above).
  const fs::path core = fs::path(AMYTISS_SOURCE_DIR) / "src/core";
  const std::regex first_public(R"re(^#include "amytiss/([a-z_]+\.hpp)")re");
  std::size_t implementations = 0;
  for (const auto& file : sources_under(core)) {
    std::ifstream input(file);
    std::string line;
    while (std::getline(input, line))
      if (line.rfind("#include", 0) == 0) break;
    std::smatch match;
    if (file.extension() != ".cpp" || !std::regex_search(line, match, first_public)) continue;
    const auto found = public_header_folders().find(match[1].str());
    const std::string folder = top_folder(fs::relative(file, core).generic_string());
    if (found == public_header_folders().end() || (found->first == "config.hpp" && folder == "config")) continue;
    ++implementations;
    EXPECT_EQ(found->second, folder) << file.string() << " implements " << found->first << " in another layer";
  }
  EXPECT_GE(implementations, 15u);
}

// Each include in `file` (of layer `from`) that names a layer above it.
void expect_includes_read_down(const fs::path& file, int from, std::size_t& checked) {
  static const std::regex quoted_include(R"re(^\s*#\s*include\s*"([a-z_]+/[^"]+)")re");
  std::ifstream input(file);
  std::string line;
  std::smatch match;
  for (int number = 1; std::getline(input, line); ++number) {
    if (!std::regex_search(line, match, quoted_include)) continue;
    const int to = layer_of_include(match[1].str());
    if (to == -2) continue;
    ++checked;
    EXPECT_GE(to, 0) << file.string() << ":" << number << " includes a public header without a layer: " << line;
    EXPECT_LE(to, from) << file.string() << ":" << number << " reads up a layer: " << line;
  }
}

TEST(Layout, CoreIncludesReadDownTheLayers) {
  const fs::path core = fs::path(AMYTISS_SOURCE_DIR) / "src/core";
  std::size_t checked = 0;
  for (const auto& file : sources_under(core)) {
    const std::string from = top_folder(fs::relative(file, core).generic_string());
    ASSERT_GE(layer_of(from), 0) << file << " is in a folder without a layer: add it to kLayers";
    expect_includes_read_down(file, layer_of(from), checked);
  }
  EXPECT_GE(checked, 300u) << "too few includes found under " << core;
}

TEST(Layout, PublicHeadersIncludeDownTheLayers) {
  const fs::path include = fs::path(AMYTISS_SOURCE_DIR) / "include/amytiss";
  std::size_t checked = 0;
  for (const auto& [header, folder] : public_header_folders())
    expect_includes_read_down(include / header, layer_of(folder), checked);
  EXPECT_GE(checked, 20u) << "too few includes found under " << include;
}

TEST(Layout, RosIncludePatternMatchesWhatItMustRefuse) {
  EXPECT_TRUE(std::regex_search("#include <ros/ros.h>", kRosInclude));
  EXPECT_TRUE(std::regex_search("  #include \"std_msgs/Float64.h\"", kRosInclude));
  EXPECT_TRUE(std::regex_search("#include <amytiss/GetInput.h>", kRosInclude));
  EXPECT_FALSE(std::regex_search("#include \"amytiss/policy.hpp\"", kRosInclude));
  EXPECT_FALSE(std::regex_search("#include <rosetta/stone.hpp>", kRosInclude));
}

}  // namespace
