// amytiss_synth's refusals of hostile paths, with exit status 2 before anything is computed: a
// configuration that is a directory or never ends.
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

}  // namespace
}  // namespace amytiss
