// amytiss_synth --simulate N --at X [--seed S]: the Monte Carlo rate of the served controller from
// X's cell, printed beside the cell's values (abstraction) or bounds (guarantee: system), the same
// for the same seed; with refine, the rounds' table and the served round's bounds beside the rate;
// and the refusals of counts, seeds and combinations that make no sense.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "amytiss/closed_loop.hpp"
#include "amytiss/config.hpp"
#include "amytiss/policy_file.hpp"
#include "cli_support.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;
using test_support::CliTest;
using test_support::CommandResult;
using test_support::quote;
using test_support::read_file;
using test_support::kTiny;
using test_support::kTinyConfig;

constexpr double kPrintedRounding = 5e-7;  // six decimals

// The number after `label` in the output, or NaN.
double number_after(const std::string& out, const std::string& label) {
  const std::size_t at = out.find(label);
  return at == std::string::npos ? std::nan("") : std::stod(out.substr(at + label.size()));
}

// The "simulation: success rate k/N = p" line's p.
double printed_rate(const std::string& out) {
  const std::size_t line = out.find("simulation: success rate ");
  if (line == std::string::npos) return std::nan("");
  return number_after(out.substr(line), " = ");
}

TEST_F(CliTest, SimulatePrintsTheRateBesideTheAbstractionsValue) {
  const CommandResult result = synth(kTiny + "--output tiny.h5 --at -2.2,1.1 --simulate 400");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  EXPECT_CONTAINS(result.out, "simulation: 400 episodes of the continuous closed loop from uniform points of the "
                              "cell of [-2.2, 1.1] (seed 1)");
  const double rate = printed_rate(result.out);
  ASSERT_TRUE(rate >= 0 && rate <= 1) << result.out;
  const double error = number_after(result.out, ", standard error ");
  EXPECT_NEAR(error, std::sqrt(rate * (1 - rate) / 400), kPrintedRounding) << result.out;
  EXPECT_CONTAINS(result.out, "simulation: V_0 ");
  EXPECT_CONTAINS(result.out, "(the abstraction's value, not a guarantee for the real system, of the cell)");
  const double value = number_after(result.out, "simulation: V_0 ");
  EXPECT_NEAR(number_after(result.out, "rate - V_0 = "), rate - value, kPrintedRounding) << result.out;
  EXPECT_CONTAINS(result.out, "simulation: ends: ");
}

TEST_F(CliTest, SimulateWithTheSystemGuaranteeComparesWithBothBounds) {
  const CommandResult result =
      synth(kTiny + "--guarantee system --output system.h5 --at -2.2,1.1 --simulate 400 --seed 9");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  EXPECT_CONTAINS(result.out, "(seed 9)");
  const LoadedPolicy loaded = read_policy_file(path("system.h5"));
  const std::vector<double> state = {-2.2, 1.1};
  std::vector<double> input(2);
  double lower = 0, upper = 0;
  ASSERT_EQ(loaded.policy.lookup(state.data(), state.size(), 0, input.data(), &lower, &upper), LookupStatus::Ok);
  EXPECT_NEAR(number_after(result.out, "simulation: certified lower bound "), lower, kPrintedRounding);
  EXPECT_NEAR(number_after(result.out, "simulation: upper bound "), upper, kPrintedRounding) << result.out;
  EXPECT_CONTAINS(result.out, "simulation: consistent with both bounds within 4 standard errors");
}

TEST_F(CliTest, RefinePrintsTheRoundsAndSimulatesTheServedRound) {
  std::ofstream(path("refined.yaml")) << read_file(kTinyConfig) << "guarantee: system\n"
                                      << "refine: {at: [[-2.2, 1.1]], gap: 0.001, max_rounds: 3}\n";
  const CommandResult result =
      synth("--config refined.yaml --quiet --output refined.h5 --at -2.2,1.1 --simulate 400");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  EXPECT_CONTAINS(result.out, "refinement (3 rounds):");
  EXPECT_CONTAINS(result.out, "  round 3: ");
  EXPECT_CONTAINS(result.out, "<- served");
  EXPECT_CONTAINS(result.out, "  stopped: max_rounds 3 done");
  EXPECT_CONTAINS(result.out, "note: refinement round 1: ");
  const LoadedPolicy loaded = read_policy_file(path("refined.h5"));
  ASSERT_EQ(loaded.policy.refinement.rounds.size(), 3u);
  const RefinementRound& served = loaded.policy.refinement.rounds[loaded.policy.refinement.served_round];
  // The simulation compares with the served round's bounds, the file's.
  EXPECT_NEAR(number_after(result.out, "simulation: certified lower bound "), served.lower[0], kPrintedRounding);
  EXPECT_EQ(loaded.policy.states.size(), served.states);
  const CommandResult dry = synth("--config refined.yaml --quiet --dry-run");
  ASSERT_EQ(0, dry.exit_code) << dry.out << dry.err;
  EXPECT_CONTAINS(dry.out, "plan: refine: until the gap at 1 at state is at most 0.001; at most 3 rounds");
}

TEST_F(CliTest, RefineOptionRefinesAtTheAtState) {
  const CommandResult result = synth(kTiny + "--guarantee system --output refined.h5 --at -2.2,1.1 --refine 0.2");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  EXPECT_CONTAINS(result.out, "refinement (");
  const LoadedPolicy loaded = read_policy_file(path("refined.h5"));
  const Config stored = read_stored_config(loaded.config_yaml);
  ASSERT_TRUE(stored.refine);
  EXPECT_EQ(stored.refine->gap, 0.2);
  EXPECT_EQ(stored.refine->at, (std::vector<std::vector<double>>{{-2.2, 1.1}}));
  EXPECT_TRUE(stored.fit_sets);
  EXPECT_LE(loaded.policy.refinement.rounds[loaded.policy.refinement.served_round].gap, 0.2)
      << loaded.policy.refinement.stop;
  for (const std::string& wrong : {std::string("--guarantee system --refine 0.05"),
                                   std::string("--guarantee system --at -2.2,1.1 --refine 1.5"),
                                   std::string("--guarantee system --at -2.2,1.1 --refine x")}) {
    const CommandResult refused = synth(kTiny + wrong);
    EXPECT_EQ(2, refused.exit_code) << wrong << "\n" << refused.out << refused.err;
    EXPECT_CONTAINS(refused.err, "--refine: got");
  }
}

TEST_F(CliTest, SimulateGivesTheSameRateForTheSameSeed) {
  const std::string base = kTiny + "--output tiny.h5 --at 0.4,-2.6 --simulate 300";
  const CommandResult first = synth(base), second = synth(base + " --seed 1"), other = synth(base + " --seed 2");
  ASSERT_EQ(0, first.exit_code) << first.err;
  ASSERT_EQ(0, other.exit_code) << other.err;
  const auto rate_line = [](const std::string& out) {
    const std::size_t at = out.find("simulation: success rate ");
    return out.substr(at, out.find('\n', at) - at);
  };
  EXPECT_EQ(rate_line(first.out), rate_line(second.out)) << "the default seed is 1";
  EXPECT_CONTAINS(other.out, "(seed 2)");
}

TEST_F(CliTest, NonsenseSimulationsExitTwoBeforeComputing) {
  const std::string most = std::to_string(kMaxSimulatedEpisodes);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--at 0,0 --simulate 0", "--simulate: got '0', expected a whole number from 1 to " + most +
                                    " (example: --simulate 1000)"},
      {"--at 0,0 --simulate " + std::to_string(kMaxSimulatedEpisodes + 1),
       "--simulate: got '" + std::to_string(kMaxSimulatedEpisodes + 1) + "', expected a whole number from 1"},
      {"--at 0,0 --simulate 1e3", "--simulate: got '1e3', expected a whole number"},
      {"--at 0,0 --simulate -5", "--simulate: got '-5', expected a whole number"},
      {"--at 0,0 --simulate 99999999999999999999999", "--simulate: got '99999999999999999999999'"},
      {"--simulate 100", "--simulate: got 100 episodes without --at, expected the state whose cell the episodes "
                         "start from (example: --at -8,-8 --simulate 1000)"},
      {"--at 0,0 --seed 3", "--seed: got 3 without --simulate"},
      {"--at 0,0 --simulate 10 --seed x", "--seed: got 'x', expected a whole number from 0 to"},
      {"--at 0,0 --simulate 10 --dry-run", "--simulate: got it with --dry-run"},
      {"--at 0,0 --simulate 10 --export prism model", "--export: got it with --at"},
      {"--at 9,0 --simulate 10", "--at: the state [9, 0] lies outside the grid"}};
  for (const auto& [arguments, message] : cases) {
    const CommandResult result = synth(kTiny + "--output refused.h5 " + arguments);
    EXPECT_EQ(2, result.exit_code) << arguments << ": " << result.out << result.err;
    EXPECT_CONTAINS(result.err, message);
    EXPECT_FALSE(fs::exists(path("refused.h5"))) << arguments;
    EXPECT_FALSE(fs::exists(path("model"))) << arguments;
  }
}

}  // namespace
}  // namespace amytiss
