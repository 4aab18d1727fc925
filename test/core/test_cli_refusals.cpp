// amytiss_synth's refusals of hostile paths and option combinations, each with exit status 2
// before anything is computed: a configuration that is a directory or never ends, --export with
// the options of a synthesis, a state with a trailing comma, an --output that is not a regular
// file (a symbolic link is followed instead); and the documented layout of a system policy file.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/policy_file.hpp"
#include "cli_support.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;
using test_support::CliTest;
using test_support::CommandResult;
using test_support::quote;
using test_support::kTiny;

const std::string kSourceDir = AMYTISS_SOURCE_DIR;

TEST_F(CliTest, AConfigurationThatIsADirectoryOrNeverEndsExitsTwo) {
  CommandResult result = synth("--config " + quote(directory_.string()));
  EXPECT_EQ(2, result.exit_code) << result.err;
  EXPECT_CONTAINS(result.err, directory_.string() + ": got a directory, expected a configuration file");
  result = synth("--config /dev/zero");
  EXPECT_EQ(2, result.exit_code) << result.err;
  EXPECT_CONTAINS(result.err, "/dev/zero: got a file of more than 16 MiB");
}

// An export computes no policy: the options of a synthesis would be ignored.
TEST_F(CliTest, ExportWithTheOptionsOfASynthesisExitsTwoAndWritesNothing) {
  for (const std::string option : {"--dry-run", "--at 0,0", "--output p.h5", "--profile", "--compare-reference"}) {
    const CommandResult result = synth(kTiny + "--export prism model " + option);
    EXPECT_EQ(2, result.exit_code) << option << ": " << result.err;
    EXPECT_CONTAINS(result.err, "--export: got it with " + option.substr(0, option.find(' ')));
    EXPECT_FALSE(fs::exists(path("model"))) << option;
    EXPECT_FALSE(fs::exists(path("p.h5"))) << option;
  }
}

TEST_F(CliTest, AStateWithAnEmptyValueOrATrailingCommaExitsTwo) {
  for (const std::string state : {"1,1,", "0,,0", ",1,1"}) {
    const CommandResult result = synth(kTiny + "--output refused.h5 --at " + state);
    EXPECT_EQ(2, result.exit_code) << state;
    EXPECT_CONTAINS(result.err, "--at: got '" + state + "', expected the state's values separated by commas");
    EXPECT_FALSE(fs::exists(path("refused.h5"))) << state;
  }
}

// Device nodes are never written here: as root, the node is one made in the test's directory
// (what a failure would replace); unprivileged, /dev/null, which cannot be replaced.
std::string device_node(const fs::path& directory) {
  if (::geteuid() != 0) return "/dev/null";
  const std::string node = (directory / "null").string();
  return ::mknod(node.c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0 ? node : "";
}

TEST_F(CliTest, AnOutputThatIsNotARegularFileExitsTwoAndIsLeftAsItIs) {
  ASSERT_EQ(0, ::mkfifo(path("fifo.h5").c_str(), 0600));
  fs::create_symlink(path("fifo.h5"), path("to_fifo.h5"));
  fs::create_symlink(path("absent.h5"), path("dangling.h5"));
  std::vector<std::pair<std::string, std::string>> cases = {
      {path("fifo.h5"), "it is a FIFO, not a regular file"},
      {path("to_fifo.h5"), "it is a symbolic link to a FIFO"},
      {path("dangling.h5"), "it is a symbolic link to a missing file"}};
  const std::string device = device_node(directory_);
  if (!device.empty()) cases.push_back({device, "it is a character device, not a regular file"});
  for (const auto& [output, message] : cases) {
    const CommandResult result = synth(kTiny + "--output " + quote(output));
    EXPECT_EQ(2, result.exit_code) << output << ": " << result.err;
    EXPECT_CONTAINS(result.err, "error: --output: cannot write " + output + ": " + message);
    EXPECT_EQ(std::string::npos, result.out.find("step 1/4")) << "refused before computing";
  }
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(path("fifo.h5"))));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(path("dangling.h5"))));
  EXPECT_FALSE(fs::exists(path("absent.h5")));
  if (!device.empty()) {
    EXPECT_TRUE(fs::is_character_file(fs::symlink_status(device)));
  }
}

// The export shares the writer: a FIFO among its files is refused, nothing is renamed.
TEST_F(CliTest, AnExportOntoAFifoExitsOneAndLeavesIt) {
  fs::create_directories(path("model"));
  ASSERT_EQ(0, ::mkfifo(path("model/model.sta").c_str(), 0600));
  const CommandResult result = synth(kTiny + "--export prism model");
  EXPECT_EQ(1, result.exit_code) << result.err;
  EXPECT_CONTAINS(result.err, "error: cannot write model/model.sta: it is a FIFO, not a regular file");
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(path("model/model.sta"))));
  EXPECT_EQ(1, std::distance(fs::directory_iterator(path("model")), fs::directory_iterator()));
}

// A symbolic link is followed: its target is replaced, the link stays.
TEST_F(CliTest, AnOutputThatIsASymbolicLinkReplacesItsTarget) {
  fs::create_directories(path("runs"));
  { std::ofstream(path("runs/old.h5")) << "an older file"; }
  fs::create_symlink("runs/old.h5", path("latest.h5"));
  const CommandResult result = synth(kTiny + "--output latest.h5");
  ASSERT_EQ(0, result.exit_code) << result.err;
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(path("latest.h5"))));
  EXPECT_EQ("cli_tiny", read_stored_config(read_policy_file(path("runs/old.h5")).config_yaml).name);
  EXPECT_EQ(1, std::distance(fs::directory_iterator(path("runs")), fs::directory_iterator()));
}

// docs/policy_file.md lists the attribute `guarantee` and /upper_values of a bounded system file
// as they are written.
TEST_F(CliTest, ASystemPolicyFileHasTheDocumentedGuaranteeAndUpperValues) {
  ASSERT_EQ(0, synth(kTiny + "--guarantee system --output system.h5").exit_code);
  const CommandResult result =
      run_in_directory("/usr/bin/python3 " + quote(kSourceDir + "/scripts/inspect_policy.py") + " system.h5");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  EXPECT_CONTAINS(result.out, "attribute guarantee = system");
  EXPECT_CONTAINS(result.out, "dataset /values float64 (5, 9, 9)");
  EXPECT_CONTAINS(result.out, "dataset /upper_values float64 (5, 9, 9)");
  const std::string doc = test_support::read_file(kSourceDir + "/docs/policy_file.md");
  EXPECT_CONTAINS(doc, "| `guarantee` | string | only with `guarantee: system`");
  EXPECT_CONTAINS(doc, "| `/upper_values` | as `/values` | (horizon+1, n0, n1, ...) with `guarantee = system`");
}

}  // namespace
}  // namespace amytiss
