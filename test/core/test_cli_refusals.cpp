// amytiss_synth's refusals of hostile paths and option combinations, each with exit status 2
// before anything is computed: a configuration that is a directory or never ends, --export with
// the options of a synthesis, a state with a trailing comma.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli_support.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;
using test_support::CliTest;
using test_support::CommandResult;
using test_support::quote;

const std::string kSourceDir = AMYTISS_SOURCE_DIR;
const std::string kTiny = "--config " + quote(kSourceDir + "/test/data/cli_tiny.yaml") + " --quiet ";

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

}  // namespace
}  // namespace amytiss
