// amytiss_synth over several processes (mpirun) and several devices (--devices): the policy
// file's values and inputs equal a single-process run's exactly; a failing rank fails the run,
// named, with no file; --dry-run prints the plan and writes nothing. The MPI tests are skipped
// only when the build has no MPI.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "amytiss/policy_file.hpp"
#include "cli_support.hpp"

namespace amytiss {
namespace {

using test_support::CliTest;
using test_support::CommandResult;
using test_support::kSynth;
using test_support::quote;
using test_support::kTinyConfig;

const std::string kMpiexec = AMYTISS_MPIEXEC;
// Root (CI) needs --allow-run-as-root; more ranks than cores need --oversubscribe.
const std::string kMpiFlags = " --allow-run-as-root --oversubscribe";

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string::npos, (haystack).find(needle)) << "missing '" << (needle) << "' in:\n" << (haystack)

class CliMpiTest : public CliTest {
 protected:
  // A run of the tiny problem on the CPU device with `sweep`, written to `name`.
  CommandResult synthesize(const std::string& launcher, const std::string& sweep, const std::string& name,
                           const std::string& extra = "") const {
    return run_in_directory(launcher + quote(kSynth) + " --config " + quote(kTinyConfig) +
                            " --device cpu --quiet --sweep " + sweep + " --output " + name + extra);
  }
  std::string mpirun(int ranks) const { return quote(kMpiexec) + kMpiFlags + " -np " + std::to_string(ranks) + " "; }
  void expect_same_policy(const std::string& one, const std::string& many) const {
    const LoadedPolicy a = read_policy_file(path(one)), b = read_policy_file(path(many));
    EXPECT_EQ(a.policy.values, b.policy.values) << one << " vs " << many;
    EXPECT_EQ(a.policy.input_index, b.policy.input_index) << one << " vs " << many;
  }
};

TEST_F(CliMpiTest, TwoAndThreeRanksWriteTheSingleProcessPolicy) {
  if (kMpiexec.empty()) GTEST_SKIP() << "built without MPI";
  for (const std::string sweep : {"dense", "factored"}) {
    const CommandResult one = synthesize("", sweep, "one.h5");
    ASSERT_EQ(0, one.exit_code) << one.err;
    for (int ranks : {2, 3}) {
      const std::string name = "ranks" + std::to_string(ranks) + ".h5";
      const CommandResult many = synthesize(mpirun(ranks), sweep, name);
      ASSERT_EQ(0, many.exit_code) << many.out << many.err;
      EXPECT_CONTAINS(many.out, "MPI: " + std::to_string(ranks) + " ranks");
      EXPECT_CONTAINS(many.out, "rank " + std::to_string(ranks - 1) + ": synthesize()");
      expect_same_policy("one.h5", name);
      std::filesystem::remove(path(name));
    }
  }
}

TEST_F(CliMpiTest, AFailingRankFailsTheRunNamingItWithoutAFile) {
  if (kMpiexec.empty()) GTEST_SKIP() << "built without MPI";
  // Rank 1 asks for an OpenCL platform index that does not exist; rank 0 would run.
  const std::string arguments = " --config " + quote(kTinyConfig) + " --device cpu --quiet --output run.h5";
  const CommandResult result = run_in_directory(quote(kMpiexec) + kMpiFlags + " -np 1 " + quote(kSynth) + arguments +
                                                " : -np 1 " + quote(kSynth) + arguments + " --platform 99");
  EXPECT_NE(0, result.exit_code);
  EXPECT_CONTAINS(result.err, "rank 1 of 2");
  EXPECT_FALSE(std::filesystem::exists(path("run.h5")));
}

TEST_F(CliMpiTest, TwoSubDevicesWriteTheSingleDevicePolicy) {
  for (const std::string sweep : {"dense", "factored"}) {
    ASSERT_EQ(0, synthesize("", sweep, "one.h5").exit_code);
    const CommandResult parts = synthesize("", sweep, "parts.h5", " --devices cpu:0/1");
    ASSERT_EQ(0, parts.exit_code) << parts.err;
    EXPECT_CONTAINS(parts.out, "exchanged per step");
    expect_same_policy("one.h5", "parts.h5");
  }
}

TEST_F(CliMpiTest, DryRunPrintsThePlanAndWritesNothing) {
  const CommandResult result = synthesize("", "dense", "plan.h5", " --devices cpu:0/1 --dry-run");
  ASSERT_EQ(0, result.exit_code) << result.err;
  EXPECT_CONTAINS(result.out, "plan: rank 0 device 1:");
  EXPECT_CONTAINS(result.out, "plan: exchange per step:");
  EXPECT_FALSE(std::filesystem::exists(path("plan.h5")));
  const CommandResult bad = synthesize("", "dense", "plan.h5", " --devices gpu:x --dry-run");
  EXPECT_EQ(2, bad.exit_code);
  EXPECT_CONTAINS(bad.err, "compute.devices[0]");
}

}  // namespace
}  // namespace amytiss
