// Reading a configuration file: a directory, a file over the size limit (also a huge sparse one
// and one that never ends), and a key given twice, each refused naming the file or the key.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;

const char* const kTiny = R"(name: tiny
states: {lb: [-4, -4], ub: [4, 4], eta: [1, 1]}
inputs: {lb: [-1, -1], ub: [1, 1], eta: [1, 1]}
constants: {tau: 1.0}
dynamics: ["x0 + tau*u0", "x1 + u1"]
noise: {covariance: [0.2, 0.2]}
spec:
  type: reach_avoid
  horizon: 4
  target: {lb: [2, 2], ub: [3, 3]}
  avoid: [{lb: [-1, -1], ub: [0, 0]}, {lb: [-3, -3], ub: [-2, -2]}]
guarantee: system
)";

class ConfigFileTest : public ::testing::Test {
 protected:
  void SetUp() override { directory_ = test_support::fresh_test_directory("amytiss_config_file_"); }
  void TearDown() override { fs::remove_all(directory_); }
  std::string path(const std::string& name) const { return (directory_ / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name), std::ios::binary) << text;
    return path(name);
  }

  fs::path directory_;
};

// The message of load_config_file's ConfigError for `file`, whose key must be `key` (the file's
// path for what is not a readable configuration).
std::string refusal_of(const std::string& file, const std::string& key) {
  try {
    load_config_file(file);
  } catch (const ConfigError& error) {
    EXPECT_EQ(key, error.key());
    return error.what();
  }
  ADD_FAILURE() << "no ConfigError for " << file;
  return "";
}
std::string refusal_of(const std::string& file) { return refusal_of(file, file); }

std::string replaced(std::string text, const std::string& part, const std::string& by) {
  const std::size_t at = text.find(part);
  EXPECT_NE(std::string::npos, at) << part;
  return text.replace(at, part.size(), by);
}

TEST_F(ConfigFileTest, ADirectoryIsRefusedAsADirectory) {
  const std::string message = refusal_of(directory_.string());
  EXPECT_NE(std::string::npos, message.find("got a directory, expected a configuration file")) << message;
}

TEST_F(ConfigFileTest, AFileJustOverTheSizeLimitIsRefused) {
  const std::string file = write("big.yaml", kTiny);
  fs::resize_file(file, kMaxConfigFileBytes + 1);
  const std::string message = refusal_of(file);
  EXPECT_NE(std::string::npos, message.find("got a file of more than 16 MiB")) << message;
}

// A sparse file of 6 GiB and /dev/zero: refused after reading the limit, not held in memory.
TEST_F(ConfigFileTest, AHugeSparseFileAndAnEndlessOneAreRefused) {
  const std::string file = write("sparse.yaml", kTiny);
  fs::resize_file(file, std::uintmax_t(6) << 30);
  EXPECT_NE(std::string::npos, refusal_of(file).find("more than 16 MiB"));
  EXPECT_NE(std::string::npos, refusal_of("/dev/zero").find("more than 16 MiB"));
}

TEST_F(ConfigFileTest, AFileOfExactlyTheSizeLimitIsRead) {
  std::string text = std::string(kTiny) + "#";
  text += std::string(kMaxConfigFileBytes - text.size() - 1, 'x') + "\n";
  ASSERT_EQ(kMaxConfigFileBytes, text.size());
  EXPECT_EQ("tiny", load_config_file(write("limit.yaml", text)).name);
}

// yaml-cpp keeps both entries and its lookup finds the first: the second was silently ignored.
TEST_F(ConfigFileTest, AKeyGivenTwiceIsRefusedNamingTheKeyAndBothLines) {
  const std::string file = write("twice.yaml", std::string(kTiny) + "guarantee: abstraction\n");
  const std::string message = refusal_of(file, "guarantee");
  EXPECT_NE(std::string::npos, message.find("guarantee: given twice (lines 12 and 13), expected each key once"))
      << message;
  using test_support::expect_error;
  expect_error(YAML::Load(replaced(kTiny, "  horizon: 4\n", "  horizon: 4\n  horizon: 8\n")), "spec.horizon",
               "given twice (lines 9 and 10)");
  expect_error(YAML::Load(replaced(kTiny, "eta: [1, 1]}", "eta: [1, 1], lb: [0, 0]}")), "states.lb",
               "given twice (lines 2 and 2)");
  expect_error(YAML::Load(replaced(kTiny, "{tau: 1.0}", "{tau: 1.0, tau: 2.0}")), "constants.tau",
               "given twice (lines 4 and 4)");
  expect_error(YAML::Load(replaced(kTiny, "{lb: [-3, -3], ub", "{lb: [-3, -3], lb: [-3, -3], ub")),
               "spec.avoid[1].lb", "given twice (lines 11 and 11)");
  EXPECT_NO_THROW(load_config_file(write("once.yaml", kTiny)));
}

}  // namespace
}  // namespace amytiss
