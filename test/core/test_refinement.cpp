// Gap-guided refinement (`refine`, refinement.hpp):
// - every round's bounds are sound: in 1-d against the fine recursion of the served controller
//   (fine_recursion.hpp), in 2-d against Monte Carlo of the continuous closed loop;
// - the gap at the `at` state does not grow over the rounds, and falls below the asked gap;
// - each budget (max_rounds, max_states, max_seconds) ends the rounds and the stop says which;
// - a stationary policy (horizon: infinite) refines too; the progress carries the round; the policy
//   file keeps the rounds (/refinement);
// - the refine section's reading and checks.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "amytiss/closed_loop.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/policy_file.hpp"
#include "amytiss/refinement.hpp"
#include "fine_recursion.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using test_support::expect_error;

// Monte Carlo episodes per round in 2-d, and how many standard errors a bound may miss by.
constexpr std::size_t kEpisodes = 4000;
constexpr double kStandardErrors = 4.0;

// The fine recursion's system (fine_recursion.hpp) on a uniform grid of cells twice its noise's
// standard deviation, refined at x = -0.55.
std::string refined_1d(const std::string& refine) {
  return "name: refined_1d\n"
         "states: {lb: [-1], ub: [1], eta: [0.25]}\n"
         "inputs: {lb: [-0.2], ub: [0.2], eta: [0.1]}\n"
         "dynamics: [\"0.9*x0 + u0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.0144]}\n"
         "spec: {type: reach_avoid, horizon: 5, target: {lb: [0.3], ub: [0.6]}, avoid: {lb: [-1], ub: [-0.7]}}\n"
         "guarantee: system\n"
         "refine: " + refine + "\n";
}

// A 2-d robot x' = x + u + w, cells three standard deviations wide, reach [1, 2]^2 avoiding a box.
std::string refined_2d(const std::string& refine) {
  return "name: refined_2d\n"
         "states: {lb: [-3, -3], ub: [3, 3], eta: [0.6, 0.6]}\n"
         "inputs: {lb: [-0.6, -0.6], ub: [0.6, 0.6], eta: [0.6, 0.6]}\n"
         "dynamics: [\"x0 + u0\", \"x1 + u1\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.04, 0.04]}\n"
         "spec: {type: reach_avoid, horizon: 6, target: {lb: [1, 1], ub: [2, 2]}, avoid: {lb: [-1, -0.5], ub: [0.4, 0.5]}}\n"
         "guarantee: system\n"
         "refine: " + refine + "\n";
}

RefinedSynthesis refine(const std::string& yaml, const ProgressCallback& progress = {}) {
  SynthesisOptions options;
  options.progress = progress;
  return synthesize_refined(config_from_yaml(YAML::Load(yaml)), options);
}

std::string rounds(unsigned count, const std::string& rest = "") {
  return "{at: [[-0.55]], gap: 0.001, max_rounds: " + std::to_string(count) + rest + "}";
}

TEST(Refinement, EveryRoundEnclosesTheFineValuesIn1d) {
  double previous_gap = 1;
  for (unsigned count = 1; count <= 4; ++count) {
    SCOPED_TRACE("max_rounds " + std::to_string(count));
    const RefinedSynthesis result = refine(refined_1d(rounds(count)));
    const Refinement& refinement = result.policy.refinement;
    ASSERT_EQ(refinement.rounds.size(), count);
    EXPECT_EQ(refinement.served_round, count - 1);
    test_support::expect_encloses_fine_values(result.abstraction, result.policy);
    // The rounds repeat: each run's rounds are the earlier runs' and one more.
    const double gap = refinement.rounds.back().gap;
    EXPECT_LE(gap, previous_gap);
    previous_gap = gap;
    EXPECT_EQ(result.policy.states.size(), refinement.rounds.back().states);
  }
  EXPECT_LT(previous_gap, 0.5 * refine(refined_1d(rounds(1))).policy.refinement.rounds[0].gap);
}

TEST(Refinement, StopsAtTheGapAndServesTheRoundThatReachedIt) {
  const RefinedSynthesis result = refine(refined_1d("{at: [[-0.55]], gap: 0.1, max_rounds: 12}"));
  const Refinement& refinement = result.policy.refinement;
  ASSERT_GE(refinement.rounds.size(), 2u);
  EXPECT_LT(refinement.rounds.size(), 12u);
  EXPECT_LE(refinement.rounds.back().gap, 0.1);
  EXPECT_GT(refinement.rounds[refinement.rounds.size() - 2].gap, 0.1);
  EXPECT_NE(refinement.stop.find("reached"), std::string::npos) << refinement.stop;
  for (std::size_t r = 1; r < refinement.rounds.size(); ++r) {
    EXPECT_LE(refinement.rounds[r].gap, refinement.rounds[r - 1].gap) << "round " << r;
    EXPECT_GT(refinement.rounds[r].states, refinement.rounds[r - 1].states) << "round " << r;
    EXPECT_LE(double(refinement.rounds[r].states), 2.0 * double(refinement.rounds[r - 1].states));
  }
  // The served policy's bounds at the at state are the last round's.
  const double at = -0.55;
  const std::size_t cell = *result.policy.states.cell_of(&at);
  EXPECT_EQ(result.policy.value(0, cell), refinement.rounds.back().lower[0]);
  EXPECT_EQ(result.policy.upper_value(0, cell), refinement.rounds.back().upper[0]);
}

TEST(Refinement, EveryRoundIsConsistentWithMonteCarloIn2d) {
  const std::vector<double> start{-2.1, -2.1};
  double previous_gap = 1;
  for (unsigned count = 1; count <= 3; ++count) {
    SCOPED_TRACE("max_rounds " + std::to_string(count));
    const RefinedSynthesis result = refine(refined_2d("{at: [[-2.1, -2.1]], gap: 0.001, max_rounds: " +
                                                      std::to_string(count) + "}"));
    const Policy& policy = result.policy;
    const std::size_t cell = *policy.states.cell_of(start.data());
    const ClosedLoop loop(result.abstraction.config, policy);
    const SimulationResult simulated = simulate_cell(loop, cell, kEpisodes, 7);
    EXPECT_TRUE(simulated.consistent_with_lower(policy.value(0, cell), kStandardErrors))
        << "lower " << policy.value(0, cell) << ", rate " << simulated.rate();
    EXPECT_TRUE(simulated.consistent_with_upper(policy.upper_value(0, cell), kStandardErrors))
        << "upper " << policy.upper_value(0, cell) << ", rate " << simulated.rate();
    const double gap = policy.refinement.rounds.back().gap;
    EXPECT_LE(gap, previous_gap);
    previous_gap = gap;
  }
}

TEST(Refinement, MaxStatesEndsTheRoundsWithinTheBudget) {
  const RefinedSynthesis result = refine(refined_1d(rounds(20, ", max_states: 14")));
  const Refinement& refinement = result.policy.refinement;
  for (const RefinementRound& round : refinement.rounds) EXPECT_LE(round.states, 14u);
  EXPECT_LT(refinement.rounds.size(), 20u);
  EXPECT_NE(refinement.stop.find("max_states 14"), std::string::npos) << refinement.stop;
}

TEST(Refinement, MaxRoundsAndMaxSecondsEndTheRounds) {
  const Refinement by_rounds = refine(refined_1d(rounds(2))).policy.refinement;
  EXPECT_EQ(by_rounds.rounds.size(), 2u);
  EXPECT_NE(by_rounds.stop.find("max_rounds 2"), std::string::npos) << by_rounds.stop;
  const Refinement by_seconds = refine(refined_1d(rounds(20, ", max_seconds: 1.0e-6"))).policy.refinement;
  EXPECT_EQ(by_seconds.rounds.size(), 1u);  // the first round always runs
  EXPECT_NE(by_seconds.stop.find("max_seconds"), std::string::npos) << by_seconds.stop;
}

TEST(Refinement, ARoundThatOutrunsMaxSecondsIsCancelledAndTheEarlierOneServed) {
  // The second round's first progress takes longer than the whole budget (the first round takes a few
  // milliseconds, so the estimate lets the second start): its next progress cancels it.
  constexpr auto kSlowProgress = std::chrono::milliseconds(1200);
  bool slowed = false;
  const RefinedSynthesis result = refine(refined_1d(rounds(5, ", max_seconds: 1.0")), [&](const Progress& progress) {
    if (progress.round == 2 && !slowed) {
      slowed = true;
      std::this_thread::sleep_for(kSlowProgress);
    }
    return true;
  });
  const Refinement& refinement = result.policy.refinement;
  ASSERT_TRUE(slowed);
  EXPECT_EQ(refinement.rounds.size(), 1u);
  EXPECT_EQ(refinement.served_round, 0u);
  EXPECT_NE(refinement.stop.find("round 2 cancelled"), std::string::npos) << refinement.stop;
  EXPECT_EQ(result.policy.states.size(), refinement.rounds[0].states);
}

TEST(Refinement, RefinesAStationaryPolicyOfAnUnboundedSpecification) {
  std::string yaml = refined_1d(rounds(3));
  yaml.replace(yaml.find("horizon: 5"), 10, "horizon: infinite");
  const RefinedSynthesis result = refine(yaml);
  const Refinement& refinement = result.policy.refinement;
  EXPECT_TRUE(result.policy.stationary);
  ASSERT_EQ(refinement.rounds.size(), 3u);
  for (std::size_t r = 1; r < refinement.rounds.size(); ++r)
    EXPECT_LE(refinement.rounds[r].gap, refinement.rounds[r - 1].gap) << "round " << r;
  EXPECT_LT(refinement.rounds.back().gap, refinement.rounds.front().gap);
  const double at = -0.55;
  const std::size_t cell = *result.policy.states.cell_of(&at);
  EXPECT_EQ(result.policy.upper_value(0, cell), refinement.rounds.back().upper[0]);
}

TEST(Refinement, WithoutAtTheFreeCellsMeanGapFalls) {
  const Refinement refinement = refine(refined_1d("{gap: 0.001, max_rounds: 3}")).policy.refinement;
  ASSERT_EQ(refinement.rounds.size(), 3u);
  EXPECT_TRUE(refinement.rounds[0].lower.empty());
  EXPECT_LT(refinement.rounds[2].gap, refinement.rounds[0].gap);
}

TEST(Refinement, ProgressCarriesTheRound) {
  std::vector<unsigned> seen;
  refine(refined_1d(rounds(3)), [&](const Progress& progress) {
    EXPECT_EQ(progress.max_rounds, 3u);
    if (seen.empty() || seen.back() != progress.round) seen.push_back(progress.round);
    return true;
  });
  EXPECT_EQ(seen, (std::vector<unsigned>{1, 2, 3}));
}

TEST(Refinement, PolicyFileKeepsTheRounds) {
  const std::string yaml = refined_1d(rounds(3));
  const Config config = config_from_yaml(YAML::Load(yaml));
  const RefinedSynthesis result = refine(yaml);
  EXPECT_EQ(result.policy.config_hash, config_hash(config));
  const auto directory = test_support::fresh_test_directory("amytiss_refinement_");
  const std::string path = (directory / "refined.h5").string();
  write_policy_file(path, result.policy, config);
  const LoadedPolicy loaded = read_policy_file_for(path, config);
  const Refinement& stored = loaded.policy.refinement;
  ASSERT_EQ(stored.rounds.size(), 3u);
  EXPECT_EQ(stored.served_round, result.policy.refinement.served_round);
  EXPECT_EQ(stored.stop, result.policy.refinement.stop);
  EXPECT_EQ(stored.at, (std::vector<std::vector<double>>{{-0.55}}));
  for (std::size_t r = 0; r < 3; ++r) {
    EXPECT_EQ(stored.rounds[r].states, result.policy.refinement.rounds[r].states);
    EXPECT_EQ(stored.rounds[r].gap, result.policy.refinement.rounds[r].gap);
    EXPECT_EQ(stored.rounds[r].lower, result.policy.refinement.rounds[r].lower);
    EXPECT_EQ(stored.rounds[r].upper, result.policy.refinement.rounds[r].upper);
  }
  EXPECT_EQ(loaded.policy.states.faces(0), result.policy.states.faces(0));
  std::filesystem::remove_all(directory);
}

TEST(RefineConfig, FitSetsDefaultsOnAndTheTextReadsBack) {
  const Config config = config_from_yaml(YAML::Load(refined_1d(rounds(3))));
  EXPECT_TRUE(config.fit_sets);
  const Config again = config_from_yaml(YAML::Load(to_yaml(config)));
  EXPECT_EQ(config_hash(again), config_hash(config));
  ASSERT_TRUE(again.refine);
  EXPECT_EQ(again.refine->at, config.refine->at);
  EXPECT_EQ(again.refine->max_rounds, 3u);
  std::string off = refined_1d(rounds(3));
  off.replace(off.find("eta: [0.25]}"), 12, "eta: [0.25], fit_sets: false}");
  const Config unfitted = config_from_yaml(YAML::Load(off));
  EXPECT_FALSE(unfitted.fit_sets);
  EXPECT_FALSE(config_from_yaml(YAML::Load(to_yaml(unfitted))).fit_sets);
  EXPECT_NE(config_hash(unfitted), config_hash(config));
}

TEST(RefineConfig, RefusalsNameTheKey) {
  auto with = [](const std::string& refine) { return YAML::Load(refined_1d(refine)); };
  expect_error(with("{at: [[5]]}"), "refine.at[0]", "inside the grid");
  expect_error(with("{at: [[0, 0]]}"), "refine.at[0]", "one per state dimension");
  expect_error(with("{gap: 1.5}"), "refine.gap", "(0, 1)");
  expect_error(with("{max_states: 3}"), "refine.max_states", "at least the first grid's");
  expect_error(with("{max_states: 2.5}"), "refine.max_states", "whole number");
  expect_error(with("{max_rounds: 0}"), "refine.max_rounds", "from 1 to 100");
  expect_error(with("{max_seconds: -1}"), "refine.max_seconds", "positive");
  expect_error(with("{step: 2}"), "refine.step", "unknown key");
  std::string abstraction = refined_1d("{}");
  abstraction.replace(abstraction.find("guarantee: system"), 17, "guarantee: abstraction");
  abstraction.replace(abstraction.find("eta: [0.25]}"), 12, "eta: [0.25], fit_sets: false}");
  expect_error(YAML::Load(abstraction), "refine", "guarantee: system");
}

}  // namespace
}  // namespace amytiss
