// The continuous-system bounds (guarantee: system) of shipped examples against the Monte Carlo
// truth of the served controller (closed_loop.hpp): at each example's documented start, the
// certified lower bound must not exceed the simulated success rate by more than 4 standard errors,
// nor (without disturbances, where the upper bound holds for random disturbances too) the rate the
// upper bound. The examples are those whose bounds take a few seconds at most on 2 cores; one of
// them also refined at its start.
#include <gtest/gtest.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/closed_loop.hpp"
#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/refinement.hpp"

namespace amytiss {
namespace {

const std::string kConfigDir = std::string(AMYTISS_SOURCE_DIR) + "/config/";
constexpr std::size_t kEpisodes = 300;
constexpr double kStandardErrors = 4.0;
constexpr std::uint64_t kSeed = 1;
// How far a served value may exceed the simulated rate (beyond the standard errors) before it
// overstates the real system.
constexpr double kServedOverstatement = 0.01;

struct Example {
  std::string config;
  std::vector<double> start;  // documented in the configuration or its launch file
};

// The example synthesized under `guarantee`, and kEpisodes of its closed loop from its start's cell.
struct Simulated {
  Config config;
  Policy policy;
  std::size_t cell = 0;
  SimulationResult result;
};

// With `refine`, the served round of that refinement (refinement.hpp).
Simulated simulate_example(const Example& example, const std::string& guarantee,
                           const std::optional<RefineConfig>& refine = std::nullopt) {
  ComputeOverrides overrides;
  overrides.guarantee = guarantee;
  overrides.refine = refine;
  Simulated simulated;
  simulated.config = load_config_file(kConfigDir + example.config, overrides);
  SynthesisOptions options;
  options.compute = simulated.config.compute;
  simulated.policy = refine ? synthesize_refined(simulated.config, options).policy
                            : synthesize(Abstraction::from_config(simulated.config), options, nullptr);
  const auto cell = simulated.policy.states.cell_of(example.start.data());
  if (!cell) throw std::logic_error(example.config + ": the start lies outside the grid");
  simulated.cell = *cell;
  simulated.result = simulate_cell(ClosedLoop(simulated.config, simulated.policy), *cell, kEpisodes, kSeed);
  return simulated;
}

void expect_bounds_hold_the_rate(const Example& example, const std::optional<RefineConfig>& refine = std::nullopt) {
  const Simulated simulated = simulate_example(example, "system", refine);
  const Config& config = simulated.config;
  const Policy& policy = simulated.policy;
  const SimulationResult& result = simulated.result;
  const double lower = policy.value(0, simulated.cell), upper = policy.upper_value(0, simulated.cell);
  const std::string where = example.config + ": lower " + std::to_string(lower) + ", upper " +
                            std::to_string(upper) + ", rate " + std::to_string(result.rate()) + " +- " +
                            std::to_string(result.standard_error());
  EXPECT_TRUE(result.consistent_with_lower(lower, kStandardErrors)) << where;
  if (!config.disturbances) {
    EXPECT_TRUE(result.consistent_with_upper(upper, kStandardErrors)) << where;
  }
  EXPECT_LE(lower, upper) << where;
  ::testing::Test::RecordProperty(example.config, where);
}

// The abstraction's value is no guarantee, but its controller must not make it a lie where the
// grid is fine against the noise: in target cells (whose points lie in the target, not all their
// states) it applies the input a Free cell would get, not input 0 (a jump off the grid).
TEST(SimulatedSoundness, AbstractionsRobotControllerDoesNotOverstateFromItsLaunchStart) {
  const Simulated simulated = simulate_example({"robot_reach_avoid.yaml", {-8.0, -8.0}}, "abstraction");
  const SimulationResult& result = simulated.result;
  EXPECT_LE(simulated.policy.value(0, simulated.cell),
            result.rate() + kServedOverstatement + kStandardErrors * result.standard_error())
      << "rate " << result.rate() << " +- " << result.standard_error();
}

TEST(SimulatedSoundness, RobotReachAvoidFromItsLaunchStart) {
  expect_bounds_hold_the_rate({"robot_reach_avoid.yaml", {-8.0, -8.0}});
}

TEST(SimulatedSoundness, RobotSafetyFromItsLaunchStart) {
  expect_bounds_hold_the_rate({"robot_safety.yaml", {0.0, 0.0}});
}

TEST(SimulatedSoundness, BmwFinalApproachFromItsDocumentedStart) {
  expect_bounds_hold_the_rate({"bmw_final_approach.yaml", {0.25, 0.5, 1.4660765716752369}});
}

TEST(SimulatedSoundness, BuildingAutomation4dFromItsCornerCell) {
  expect_bounds_hold_the_rate({"arch_building_automation_4d.yaml", {19, 19, 30, 30}});
}

TEST(SimulatedSoundness, BuildingAutomation4dRefinedAtItsCornerCell) {
  RefineConfig refine;
  refine.at = {{19, 19, 30, 30}};
  refine.max_rounds = 4;
  expect_bounds_hold_the_rate({"arch_building_automation_4d.yaml", {19, 19, 30, 30}}, refine);
}

}  // namespace
}  // namespace amytiss
