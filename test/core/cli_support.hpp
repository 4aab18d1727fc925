#pragma once
// Running amytiss_synth as a process in a test's own temporary directory (test_cli.cpp,
// test_cli_mpi.cpp).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "test_support.hpp"

namespace amytiss {
namespace test_support {

namespace fs = std::filesystem;

inline const std::string kSynth = AMYTISS_SYNTH_BIN;

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

inline std::string read_file(const fs::path& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

inline std::string quote(const std::string& text) { return "'" + text + "'"; }

/// The CLI tests' tiny configuration, and the arguments that run it quietly.
inline const std::string kTinyConfig = std::string(AMYTISS_SOURCE_DIR) + "/test/data/cli_tiny.yaml";
inline const std::string kTiny = "--config " + quote(kTinyConfig) + " --quiet ";

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = fresh_test_directory("amytiss_cli_test_");
  }
  void TearDown() override { fs::remove_all(directory_); }

  // Runs `command` in the test's directory with stdout and stderr captured to files.
  CommandResult run_in_directory(const std::string& command) const {
    const fs::path out = directory_ / "stdout.txt", err = directory_ / "stderr.txt";
    const std::string line = "cd " + quote(directory_.string()) + " && " + command + " >" +
                             quote(out.string()) + " 2>" + quote(err.string());
    const int status = std::system(line.c_str());
    CommandResult result;
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    result.out = read_file(out);
    result.err = read_file(err);
    fs::remove(out);
    fs::remove(err);
    return result;
  }
  CommandResult synth(const std::string& arguments) const {
    return run_in_directory(quote(kSynth) + " " + arguments);
  }
  std::string path(const std::string& name) const { return (directory_ / name).string(); }

  fs::path directory_;
};

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string::npos, (haystack).find(needle)) << "missing '" << (needle) << "' in:\n" << (haystack)

}  // namespace test_support
}  // namespace amytiss
