// One test body over every engine: the serial reference, the dense sweep (stored and on the fly),
// the factored sweep, and both sweeps over a team of devices (the CPU device split in two), each
// on a few tiny problems. Every engine agrees with the reference, reports its phases and progress
// the same way (the one backward driver), and a team is bit-identical to one device.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "agreement.hpp"
#include "amytiss/engine.hpp"
#include "opencl/device.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using test_support::from_yaml;

// The factored sweep computes in double precision: it agrees with the reference to rounding.
constexpr double kDoubleValueTolerance = 1e-9;
constexpr double kDoubleInputMarginTolerance = 1e-12;
// The dense sweep stores masses in float (docs/engine.md bounds the error by
// horizon * (dims + 1) * 2^-24); the product contract asks for 1e-5.
constexpr double kFloatValueTolerance = 1e-5;
constexpr double kFloatInputMarginTolerance = 1e-5;

struct EngineCase {
  const char* name;
  DeviceKind device;
  SweepChoice sweep;
  TransitionStorage transitions;
  std::vector<std::string> devices;  ///< a team when not empty
  double value_tolerance, input_margin_tolerance;
};

const EngineCase kEngines[] = {
    {"reference", DeviceKind::Reference, SweepChoice::Auto, TransitionStorage::Auto, {}, 0, 0},
    {"dense_stored", DeviceKind::Cpu, SweepChoice::Dense, TransitionStorage::Stored, {}, kFloatValueTolerance,
     kFloatInputMarginTolerance},
    {"dense_on_the_fly", DeviceKind::Cpu, SweepChoice::Dense, TransitionStorage::OnTheFly, {}, kFloatValueTolerance,
     kFloatInputMarginTolerance},
    {"factored", DeviceKind::Cpu, SweepChoice::Factored, TransitionStorage::Auto, {}, kDoubleValueTolerance,
     kDoubleInputMarginTolerance},
    {"team_dense", DeviceKind::Cpu, SweepChoice::Dense, TransitionStorage::Auto, {"cpu:0/1"}, kFloatValueTolerance,
     kFloatInputMarginTolerance},
    {"team_factored", DeviceKind::Cpu, SweepChoice::Factored, TransitionStorage::Auto, {"cpu:0/1"},
     kDoubleValueTolerance, kDoubleInputMarginTolerance},
};

struct Problem {
  const char* name;
  std::string yaml;
};

// Every problem runs on every sweep: dynamics expressions whose coordinates read few variables.
const Problem kProblems[] = {
    // The 3-d traffic ring on a coarser grid: few inputs, wide windows.
    {"traffic", test_support::traffic_yaml(0.4, 4)},
    // 15 cells a dimension: the factored stage tensors' rows padded to 16 doubles.
    {"traffic_padded", test_support::traffic_yaml(0.5, 3, 7.0)},
    {"robot_disturbance", test_support::robot_disturbance_yaml()},
    // Rows of 101 entries along the first stage's vector digit (104 doubles in the stage tensor).
    {"long_rows", test_support::long_rows_yaml()},
    {"multiplicative",
     "name: multiplicative_small\n"
     "states: {lb: [-2, -2, -1], ub: [2, 2, 1], eta: [0.25, 0.25, 0.5]}\n"
     "inputs: {lb: [-1], ub: [1], eta: [0.5]}\n"
     "dynamics: [\"0.8*x0 + 0.3*u0\", \"0.5*x1 + 0.2*x0*u0\", \"0.9*x2\"]\n"
     "noise: {type: multiplicative, distribution: normal, covariance: [0.04, 0.01, 0.02],\n"
     "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"
     "spec: {type: safety, horizon: 5, safe: {lb: [-1.5, -1.5, -1], ub: [1.5, 1.5, 1]}}\n"},
    // A state dimension given by its cell faces, truncated windows of a radius in state units.
    {"faces",
     "name: faces_small\n"
     "states: {lb: [-2, ~], ub: [2, ~], eta: [0.25, ~],\n"
     "         faces: [~, [-2, -1.3, -0.9, -0.6, -0.4, -0.2, -0.1, 0, 0.15, 0.3, 0.6, 1, 1.5, 2]]}\n"
     "inputs: {lb: [-0.5], ub: [0.5], eta: [0.5]}\n"
     "dynamics: [\"0.8*x0 + 0.2*x1 + u0\", \"0.9*x1 - 0.1*x0 + 0.5*u0\"]\n"
     "noise: {type: additive, distribution: normal, covariance: [0.04, 0.03],\n"
     "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"
     "spec: {type: reach_avoid, horizon: 4, target: {lb: [0.5, 0.2], ub: [1.5, 1]}, avoid: {lb: [-2, -2], ub: [-1, -1]}}\n"},
};

SynthesisOptions options_for(const EngineCase& engine) {
  SynthesisOptions options;
  options.compute.device = engine.device;
  options.compute.sweep = engine.sweep;
  options.compute.transitions = engine.transitions;
  options.compute.devices = engine.devices;
  return options;
}

bool cpu_device_splits() {
  std::vector<EngineNote> notes;
  ComputeConfig compute;
  compute.device = DeviceKind::Cpu;
  return detail::choose_device(compute, notes).compute_units >= 2;
}

// The reference engine's policy of each problem, computed once.
const Policy& reference_policy(const Problem& problem, const Abstraction& a) {
  static std::map<std::string, Policy> policies;
  auto found = policies.find(problem.name);
  if (found == policies.end()) found = policies.emplace(problem.name, synthesize_reference(a, {}, nullptr)).first;
  return found->second;
}

// Progress as the callback saw it.
struct ProgressLog {
  std::vector<Phase> phases;
  std::vector<unsigned> steps_done, steps_total;
  double largest_percent = 0;
};

class EveryEngine : public testing::TestWithParam<std::tuple<EngineCase, Problem>> {};

TEST_P(EveryEngine, AgreesWithTheReferenceAndReportsEveryStep) {
  const EngineCase& engine = std::get<0>(GetParam());
  const Problem& problem = std::get<1>(GetParam());
  if (!engine.devices.empty() && !cpu_device_splits()) GTEST_SKIP() << "the CPU device has one compute unit";
  const Abstraction a = from_yaml(problem.yaml);
  SynthesisOptions options = options_for(engine);
  ProgressLog log;
  options.progress = [&log](const Progress& progress) {
    log.phases.push_back(progress.phase);
    log.largest_percent = std::max(log.largest_percent, progress.percent());
    if (progress.phase == Phase::Synthesis || progress.phase == Phase::Done) {
      log.steps_done.push_back(progress.steps_done);
      log.steps_total.push_back(progress.steps_total);
    }
    return true;
  };
  SynthesisReport report;
  const Policy policy = synthesize(a, options, &report);
  const Policy& reference = reference_policy(problem, a);

  // Values and inputs: the reference's, within the engine's arithmetic.
  const test_support::Agreement agreement = test_support::compare(a, reference, policy);
  EXPECT_LE(agreement.max_value_difference, engine.value_tolerance);
  EXPECT_LE(agreement.max_mismatch_margin, engine.input_margin_tolerance);
  for (double value : policy.values) {
    ASSERT_GE(value, 0.0);
    ASSERT_LE(value, 1.0);
  }
  // Progress: set-up first, one report per step counting up to the horizon, the last one Done.
  ASSERT_FALSE(log.phases.empty());
  EXPECT_EQ(log.phases.front(), Phase::Setup);
  EXPECT_EQ(log.phases.back(), Phase::Done);
  std::vector<unsigned> expected_steps;
  for (unsigned k = 1; k <= a.horizon; ++k) expected_steps.push_back(k);
  EXPECT_EQ(log.steps_done, expected_steps);
  EXPECT_EQ(log.steps_total, std::vector<unsigned>(a.horizon, a.horizon));
  EXPECT_LE(log.largest_percent, 100.0);
  // Report: one Step phase per time step with its multiply-adds; the device names the policy.
  unsigned step_phases = 0;
  for (const PhaseReport& phase : report.phases)
    if (phase.kind == PhaseKind::Step) {
      ++step_phases;
      EXPECT_GT(phase.multiply_adds, 0.0) << phase.name;
    }
  EXPECT_EQ(step_phases, a.horizon);
  EXPECT_EQ(policy.computed_by, report.device);
  EXPECT_GT(report.host_peak_bytes, 0u);
  if (engine.device == DeviceKind::Reference) {
    EXPECT_EQ(policy.values, reference.values);
    EXPECT_EQ(policy.input_index, reference.input_index);
  }
  // A team computes what one device computes, bit for bit.
  if (!engine.devices.empty()) {
    EngineCase alone = engine;
    alone.devices.clear();
    const Policy one = synthesize(a, options_for(alone), nullptr);
    EXPECT_EQ(one.values, policy.values);
    EXPECT_EQ(one.input_index, policy.input_index);
  }
}

std::string case_name(const testing::TestParamInfo<EveryEngine::ParamType>& info) {
  return std::string(std::get<0>(info.param).name) + "_" + std::get<1>(info.param).name;
}

INSTANTIATE_TEST_SUITE_P(Engines, EveryEngine, testing::Combine(testing::ValuesIn(kEngines), testing::ValuesIn(kProblems)),
                         case_name);

// Unbounded specifications: interval iterations have no known total, so progress stays at 0 %
// (never past 100 %) and ends Done, on every engine that runs them.
class EveryUnboundedEngine : public testing::TestWithParam<EngineCase> {};

TEST_P(EveryUnboundedEngine, ProgressNeverPassesAHundredPercentAndEndsDone) {
  const Abstraction a = from_yaml(
      "name: walk_unbounded\n"
      "states: {lb: [-2, -2], ub: [2, 2], eta: [0.5, 0.5]}\n"
      "inputs: {lb: [-1, -1], ub: [1, 1], eta: [1, 1]}\n"
      "dynamics: [\"x0 + 0.5*u0\", \"x1 + 0.5*u1\"]\n"
      "noise: {covariance: [0.04, 0.04], truncation: cutting_probability, cutting_probability: 1.0e-4}\n"
      "spec: {type: reach_avoid, horizon: infinite, target: {lb: [1, 1], ub: [2, 2]}}\n");
  SynthesisOptions options = options_for(GetParam());
  ProgressLog log;
  unsigned iteration_reports = 0;
  options.progress = [&](const Progress& progress) {
    log.phases.push_back(progress.phase);
    log.largest_percent = std::max(log.largest_percent, progress.percent());
    EXPECT_EQ(progress.steps_total, 0u);
    iteration_reports += progress.phase == Phase::Synthesis;
    return true;
  };
  const Policy policy = synthesize(a, options, nullptr);
  EXPECT_TRUE(policy.stationary);
  EXPECT_GT(iteration_reports, 0u);
  EXPECT_EQ(log.largest_percent, 0.0);
  ASSERT_FALSE(log.phases.empty());
  EXPECT_EQ(log.phases.back(), Phase::Done);
}

// Teams compute bounded horizons only.
INSTANTIATE_TEST_SUITE_P(Engines, EveryUnboundedEngine,
                         testing::Values(kEngines[0], kEngines[1], kEngines[2], kEngines[3]),
                         [](const testing::TestParamInfo<EngineCase>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace amytiss
