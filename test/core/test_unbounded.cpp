// Unbounded specifications (spec.horizon: infinite): interval iteration against closed forms,
// with and without end components, on the reference engine and both OpenCL sweeps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/policy_file.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

constexpr double kTolerance = 1e-6;
// The dense sweep's masses are float (docs/engine.md): its bounds agree to this.
constexpr double kOpenClTolerance = 1e-5;
constexpr double kRounding = 1e-12;

using test_support::from_yaml;

Policy run(const Abstraction& a, DeviceKind device, SweepChoice sweep, SynthesisReport* report) {
  SynthesisOptions options;
  options.compute.device = device;
  options.compute.sweep = sweep;
  return synthesize(a, options, report);
}

bool note_contains(const SynthesisReport& report, const std::string& text) {
  for (const auto& note : report.notes)
    if (note.text.find(text) != std::string::npos) return true;
  return false;
}

// Checks the bounds against the exact value: lower <= value <= upper within rounding (reference)
// or the device's precision, and upper - lower <= tolerance.
void expect_bounds(const Policy& policy, const std::vector<double>& exact, double slack, const std::string& what) {
  ASSERT_TRUE(policy.stationary);
  ASSERT_EQ(policy.upper_values.size(), exact.size());
  double worst_gap = 0, worst_error = 0;
  for (std::size_t x = 0; x < exact.size(); ++x) {
    const double lower = policy.value(0, x), upper = policy.upper_values[x];
    EXPECT_LE(lower, exact[x] + slack) << what << " cell " << x;
    EXPECT_GE(upper, exact[x] - slack) << what << " cell " << x;
    worst_gap = std::max(worst_gap, upper - lower);
    worst_error = std::max(worst_error, std::fabs(lower - exact[x]));
  }
  EXPECT_LE(worst_gap, kTolerance + slack) << what;
  EXPECT_LE(policy.gap, kTolerance + slack) << what;
  std::printf("%s: %u iterations, gap %.3g, max |lower - exact| %.3g\n", what.c_str(), policy.iterations, policy.gap,
              worst_error);
}

// Gambler's ruin: a lazy symmetric walk (uniform noise on [-1.5, 1.5]: one cell down, stay, up,
// each 1/3) on 0..10 reaches 10 before 0 with probability x/10.
const char* const kRuin =
    "name: ruin\n"
    "states: {lb: [0], ub: [10], eta: [1]}\n"
    "dynamics: [\"x0\"]\n"
    "noise: {distribution: uniform, half_width: [1.5]}\n"
    "spec: {type: reach_avoid, horizon: infinite, target: {lb: [10], ub: [10]}, avoid: {lb: [0], ub: [0]}}\n";

std::vector<double> ruin_value() {
  std::vector<double> value(11);
  for (int x = 0; x <= 10; ++x) value[x] = x / 10.0;
  return value;
}

// A parking end component: below 6, input 0 parks the walk in {2, 3, 4} forever (value 0 if kept),
// input 1 gambles (one third into the target, the rest off the grid); above 5 input 0 walks. The
// value is 1/3 up to 5 and rises linearly (harmonic walk) to 1 at 10. Without the end-component
// correction the upper bound would stay at 1 on {2, 3, 4}.
const char* const kParking =
    "name: parking\n"
    "states: {lb: [0], ub: [10], eta: [1]}\n"
    "inputs: {lb: [0], ub: [1], eta: [1]}\n"
    "dynamics: [\"u0 > 0.5 ? 11 : (x0 <= 5 ? 3 : x0)\"]\n"
    "noise: {distribution: uniform, half_width: [1.5]}\n"
    "spec: {type: reach_avoid, horizon: infinite, target: {lb: [10], ub: [10]}, avoid: {lb: [0], ub: [0]}}\n";

std::vector<double> parking_value() {
  std::vector<double> value(11);
  for (int x = 1; x <= 10; ++x) value[x] = x <= 5 ? 1.0 / 3 : 1.0 / 3 + 2.0 * (x - 5) / 15;
  value[0] = 0;
  value[10] = 1;
  return value;
}

// Safety with a sure way to stay: pushing towards the centre keeps the walk in [1, 9] forever.
const char* const kSureSafety =
    "name: sure_safety\n"
    "states: {lb: [0], ub: [10], eta: [1]}\n"
    "inputs: {lb: [-1], ub: [1], eta: [1]}\n"
    "dynamics: [\"x0 + u0\"]\n"
    "noise: {distribution: uniform, half_width: [1.5]}\n"
    "spec: {type: safety, horizon: infinite, safe: {lb: [1], ub: [9]}}\n";

TEST(Unbounded, GamblersRuinClosedForm) {
  const Abstraction a = from_yaml(kRuin);
  SynthesisReport report;
  expect_bounds(run(a, DeviceKind::Reference, SweepChoice::Auto, &report), ruin_value(), kRounding, "ruin reference");
  EXPECT_TRUE(note_contains(report, "no end components"));
  expect_bounds(run(a, DeviceKind::Cpu, SweepChoice::Dense, nullptr), ruin_value(), kOpenClTolerance, "ruin dense");
  expect_bounds(run(a, DeviceKind::Cpu, SweepChoice::Factored, nullptr), ruin_value(), kRounding, "ruin factored");
}

TEST(Unbounded, EndComponentIsCorrected) {
  const Abstraction a = from_yaml(kParking);
  SynthesisReport report;
  const Policy policy = run(a, DeviceKind::Reference, SweepChoice::Auto, &report);
  expect_bounds(policy, parking_value(), kRounding, "parking reference");
  EXPECT_TRUE(note_contains(report, "cells in end components"));
  // The stored policy gambles in the parking cells (parking forever is worth 0).
  for (std::size_t x = 2; x <= 4; ++x) EXPECT_EQ(policy.input(0, x), 1u) << x;
  expect_bounds(run(a, DeviceKind::Cpu, SweepChoice::Dense, nullptr), parking_value(), kOpenClTolerance,
                "parking dense");
  expect_bounds(run(a, DeviceKind::Cpu, SweepChoice::Factored, nullptr), parking_value(), kRounding,
                "parking factored");
}

TEST(Unbounded, SureSafetyIsOne) {
  const Abstraction a = from_yaml(kSureSafety);
  std::vector<double> exact(11, 1.0);
  exact[0] = exact[10] = 0.0;
  expect_bounds(run(a, DeviceKind::Reference, SweepChoice::Auto, nullptr), exact, kRounding, "sure safety reference");
  expect_bounds(run(a, DeviceKind::Cpu, SweepChoice::Dense, nullptr), exact, kOpenClTolerance, "sure safety dense");
}

// Safety against a disturbance that pushes right at the edge: below 10 the controller keeps the walk
// in [1, 9] surely; at 10 and 11 the disturbance cancels its push, so V(10) = (1 + V(10) + V(11))/3
// and V(11) = (V(10) + V(11) + 0)/3: V(10) = 2/3, V(11) = 1/3.
TEST(Unbounded, SafetyWithDisturbanceClosedForm) {
  const Abstraction a = from_yaml(
      "name: safety_disturbance\n"
      "states: {lb: [0], ub: [12], eta: [1]}\n"
      "inputs: {lb: [-1], ub: [1], eta: [1]}\n"
      "disturbances: {lb: [0], ub: [1], eta: [1]}\n"
      "dynamics: [\"x0 + u0 + w0*(x0 > 9 ? 1 : 0)\"]\n"
      "noise: {distribution: uniform, half_width: [1.5]}\n"
      "spec: {type: safety, horizon: infinite, safe: {lb: [1], ub: [11]}}\n");
  std::vector<double> exact(13, 1.0);
  exact[0] = exact[12] = 0.0;
  exact[10] = 2.0 / 3;
  exact[11] = 1.0 / 3;
  expect_bounds(run(a, DeviceKind::Reference, SweepChoice::Auto, nullptr), exact, kRounding, "safety reference");
  expect_bounds(run(a, DeviceKind::Cpu, SweepChoice::Dense, nullptr), exact, kOpenClTolerance, "safety dense");
  expect_bounds(run(a, DeviceKind::Cpu, SweepChoice::Factored, nullptr), exact, kRounding, "safety factored");
}

// A 2-d reach-avoid robot with Gaussian noise and a disturbance: the engines' bounds agree.
TEST(Unbounded, OpenClAgreesWithReferenceOnARobot) {
  const Abstraction a = from_yaml(
      "name: robot_unbounded\n"
      "states: {lb: [-2, -2], ub: [2, 2], eta: [0.5, 0.5]}\n"
      "inputs: {lb: [-1, -1], ub: [1, 1], eta: [1, 1]}\n"
      "disturbances: {lb: [-0.1], ub: [0.1], eta: [0.2]}\n"
      "dynamics: [\"x0 + 0.5*u0 + w0\", \"x1 + 0.5*u1\"]\n"
      "noise: {covariance: [0.04, 0.04], truncation: cutting_probability, cutting_probability: 1.0e-4}\n"
      "spec: {type: reach_avoid, horizon: infinite, target: {lb: [1, 1], ub: [2, 2]}, "
      "avoid: {lb: [-0.5, -0.5], ub: [0.5, 0.5]}}\n");
  const Policy reference = run(a, DeviceKind::Reference, SweepChoice::Auto, nullptr);
  EXPECT_LE(reference.gap, kTolerance);
  for (SweepChoice sweep : {SweepChoice::Dense, SweepChoice::Factored}) {
    const Policy opencl = run(a, DeviceKind::Cpu, sweep, nullptr);
    double lower = 0, upper = 0;
    for (std::size_t x = 0; x < a.states.size(); ++x) {
      lower = std::max(lower, std::fabs(opencl.value(0, x) - reference.value(0, x)));
      upper = std::max(upper, std::fabs(opencl.upper_values[x] - reference.upper_values[x]));
    }
    EXPECT_LE(lower, kOpenClTolerance);
    EXPECT_LE(upper, kOpenClTolerance);
    EXPECT_LE(opencl.gap, kTolerance);
    std::printf("robot %s: %u iterations, max |lower - reference| %.3g, max |upper - reference| %.3g, V_0 at "
                "(-2, -2) %.6f\n",
                to_string(sweep).c_str(), opencl.iterations, lower, upper, opencl.value(0, 0));
  }
}

// An independent value iteration, written plainly: V <- max_u min_w sum_x' P(x'|x,u,w) V(x') on
// Free cells with P from NoiseModel::transition_probability, fixed cells at their role's value,
// from `start` (reachability: 0 on Free cells, the least fixed point from below; safety: 1, the
// greatest from above) until no cell moves by more than kIndependentConvergence.
constexpr double kIndependentConvergence = 1e-15;
constexpr unsigned kIndependentIterations = 1000000;

std::vector<double> independent_value(const Abstraction& a, double start) {
  const std::size_t n = a.states.size(), inputs = a.inputs.size(), disturbances = a.disturbances.size();
  std::vector<double> probability(n * inputs * disturbances * n), x(a.states.dims()), mean(a.states.dims());
  for (std::size_t cell = 0; cell < n; ++cell) {
    a.states.point(cell, x.data());
    for (std::size_t u = 0; u < inputs; ++u)
      for (std::size_t w = 0; w < disturbances; ++w) {
        a.dynamics->evaluate(x.data(), a.inputs.point(u).data(), a.disturbances.point(w).data(), mean.data());
        for (std::size_t to = 0; to < n; ++to)
          probability[((cell * inputs + u) * disturbances + w) * n + to] =
              a.noise->transition_probability(a.states, to, mean.data(), x.data());
      }
  }
  std::vector<double> value(n);
  for (std::size_t cell = 0; cell < n; ++cell)
    value[cell] = a.roles[cell] == CellRole::Free ? start : a.roles[cell] == CellRole::FixedOne ? 1.0 : 0.0;
  for (unsigned iteration = 0; iteration < kIndependentIterations; ++iteration) {
    std::vector<double> next = value;
    double change = 0;
    for (std::size_t cell = 0; cell < n; ++cell) {
      if (a.roles[cell] != CellRole::Free) continue;
      double best = 0;
      for (std::size_t u = 0; u < inputs; ++u) {
        double worst = 1;
        for (std::size_t w = 0; w < disturbances; ++w) {
          double sum = 0;
          for (std::size_t to = 0; to < n; ++to)
            sum += probability[((cell * inputs + u) * disturbances + w) * n + to] * value[to];
          worst = std::min(worst, sum);
        }
        best = std::max(best, worst);
      }
      next[cell] = best;
      change = std::max(change, std::fabs(best - value[cell]));
    }
    value = next;
    if (change <= kIndependentConvergence) return value;
  }
  ADD_FAILURE() << "the independent value iteration did not converge";
  return value;
}

// Safety against a disturbance that pushes right near the edge (as above, on 13 cells of `eta`),
// with noise laws of bounded support whose cell masses may sum to 1 - 1e-16 in double:
// where the controller keeps the whole support on safe cells the value is 1, and the lower bound
// must find it (deciding leaks from the sums left it at 0 everywhere).
std::string bounded_support_safety(double eta, const std::string& noise) {
  auto times = [eta](double factor) { return std::to_string(factor * eta); };
  return "name: bounded_support_safety\n"
         "states: {lb: [0], ub: [" + times(12) + "], eta: [" + times(1) + "]}\n"
         "inputs: {lb: [" + times(-1) + "], ub: [" + times(1) + "], eta: [" + times(1) + "]}\n"
         "disturbances: {lb: [0], ub: [1], eta: [1]}\n"
         "dynamics: [\"x0 + u0 + " + times(1) + "*w0*(x0 > " + times(9.2) + " ? 1 : 0)\"]\n"
         "noise: " + noise + "\n"
         "spec: {type: safety, horizon: infinite, safe: {lb: [" + times(1) + "], ub: [" + times(11) + "]}}\n";
}

TEST(Unbounded, SafetyWithBoundedSupportNoiseAndADisturbance) {
  // Beta, Beta(1,1) and the Epanechnikov kernel: each left the lower bound at 0 on every cell
  // while the leaks were decided from the sums.
  const std::vector<std::pair<double, std::string>> cases = {
      {0.45, "{distribution: beta, alpha: [2], beta: [3], support: {lb: [-0.54], ub: [0.54]}}"},
      {0.25, "{distribution: beta, alpha: [1], beta: [1], support: {lb: [-0.3], ub: [0.3]}}"},
      {0.9, "{distribution: custom, density: [\"0.75*(1 - z^2)\"], support: {lb: [-1], ub: [1]}}"}};
  for (const auto& [eta, noise] : cases) {
    const Abstraction a = from_yaml(bounded_support_safety(eta, noise));
    const std::vector<double> exact = independent_value(a, 1.0);
    EXPECT_GT(*std::max_element(exact.begin(), exact.end()), 1 - kTolerance) << noise;
    const Policy policy = run(a, DeviceKind::Reference, SweepChoice::Auto, nullptr);
    expect_bounds(policy, exact, kRounding, "bounded support safety reference " + noise);
    EXPECT_TRUE(policy.converged) << noise;
    expect_bounds(run(a, DeviceKind::Cpu, SweepChoice::Factored, nullptr), exact, kRounding,
                  "bounded support safety factored " + noise);
  }
}

// A near end component: input 1 gambles (mean just below the grid: about 0.959 into the target
// cell 0, the rest off the grid), input 0 hovers on the cell's left face, where exponential noise
// of rate 14 keeps the state in its cell but for e^-14 = 8.3e-7 per step, drifting right to the
// avoided cell 5. Hovering is worth less than gambling, but plain iteration lowers the upper
// bound of a hovering cell by about 1e-6 of its excess per step.
const char* const kHovering =
    "name: hovering\n"
    "states: {lb: [0], ub: [5], eta: [1]}\n"
    "inputs: {lb: [0], ub: [1], eta: [1]}\n"
    "dynamics: [\"u0 > 0.5 ? -0.503 : x0 - 0.5\"]\n"
    "noise: {distribution: exponential, rate: [14]}\n"
    "spec: {type: reach_avoid, horizon: infinite, tolerance: 1.0e-8, target: {lb: [0], ub: [0]}, "
    "avoid: {lb: [5], ub: [5]}}\n";
constexpr double kHoveringTolerance = 1e-8;

TEST(Unbounded, NearEndComponentsConverge) {
  const Abstraction a = from_yaml(kHovering);
  const std::vector<double> exact = independent_value(a, 0.0);
  for (SweepChoice sweep : {SweepChoice::Auto, SweepChoice::Factored}) {
    SynthesisReport report;
    const Policy policy = run(a, sweep == SweepChoice::Auto ? DeviceKind::Reference : DeviceKind::Cpu, sweep, &report);
    ASSERT_TRUE(policy.stationary);
    double worst_gap = 0;
    for (std::size_t x = 0; x < exact.size(); ++x) {
      EXPECT_LE(policy.value(0, x), exact[x] + kRounding) << x;
      EXPECT_GE(policy.upper_values[x], exact[x] - kRounding) << x;
      worst_gap = std::max(worst_gap, policy.upper_values[x] - policy.value(0, x));
      if (a.roles[x] == CellRole::Free) {
        EXPECT_EQ(policy.input(0, x), 1u) << "cell " << x << " gambles";
      }
    }
    EXPECT_LE(worst_gap, kHoveringTolerance);
    EXPECT_TRUE(policy.converged);
    EXPECT_TRUE(note_contains(report, "optimistic upper bound"));
    std::printf("hovering %s: %u iterations, gap %.3g, V(1) %.12f\n", to_string(sweep).c_str(), policy.iterations,
                policy.gap, exact[1]);
  }
}

// Safety where the state drifts right by e^-14 a step from every cell to the unsafe cell 5: the
// value is 0, the lower bound has it at once, the upper bound crawls (no optimistic guess for
// safety) and 100000 iterations leave a gap: the policy says it has not converged, the report
// warns, and the policy file keeps the flag.
TEST(Unbounded, AGapThatRemainsIsRecorded) {
  const Abstraction a = from_yaml(
      "name: drifting_safety\n"
      "states: {lb: [0], ub: [5], eta: [1]}\n"
      "dynamics: [\"x0 - 0.5\"]\n"
      "noise: {distribution: exponential, rate: [14]}\n"
      "spec: {type: safety, horizon: infinite, safe: {lb: [0], ub: [4]}}\n");
  SynthesisReport report;
  const Policy policy = run(a, DeviceKind::Reference, SweepChoice::Auto, &report);
  EXPECT_GT(policy.gap, kTolerance);
  EXPECT_FALSE(policy.converged);
  for (std::size_t x = 0; x < a.states.size(); ++x) EXPECT_EQ(policy.value(0, x), 0.0) << x;
  bool warned = false;
  for (const auto& note : report.notes)
    warned = warned || (note.severity == NoteSeverity::Warning && note.text.find("not reached") != std::string::npos);
  EXPECT_TRUE(warned);
  const std::string path = (test_support::fresh_test_directory("amytiss_unbounded_") / "drifting.h5").string();
  write_policy_file(path, policy, a.config);
  const LoadedPolicy loaded = read_policy_file(path);
  EXPECT_FALSE(loaded.policy.converged);
  EXPECT_EQ(loaded.policy.gap, policy.gap);
  const Abstraction ruin = from_yaml(kRuin);
  write_policy_file(path, run(ruin, DeviceKind::Reference, SweepChoice::Auto, nullptr), ruin.config);
  EXPECT_TRUE(read_policy_file(path).policy.converged);
}

TEST(Unbounded, SeveralDevicesAreRefused) {
  SynthesisOptions options;
  options.compute.device = DeviceKind::Cpu;
  options.compute.devices = {"all"};
  try {
    synthesize(from_yaml(kRuin), options);
    ADD_FAILURE() << "an unbounded specification ran on several devices";
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), "spec.horizon") << error.what();
  }
}

TEST(Unbounded, ConfigurationKeys) {
  const Config config = config_from_yaml(YAML::Load(kRuin));
  EXPECT_TRUE(config.spec.unbounded);
  EXPECT_EQ(config.spec.tolerance_or_default(), 1e-6);
  EXPECT_EQ(config_from_yaml(YAML::Load(to_yaml(config))).spec.unbounded, true);
  auto error_key = [](const std::string& text) {
    try {
      config_from_yaml(YAML::Load(text));
    } catch (const ConfigError& error) {
      return error.key();
    }
    return std::string("none");
  };
  std::string text = kRuin;
  EXPECT_EQ(error_key(text.substr(0, text.find("spec:")) +
                      "spec: {type: safety, horizon: 5, tolerance: 1.0e-3}\n"),
            "spec.tolerance");
  EXPECT_EQ(error_key(text.substr(0, text.find("spec:")) +
                      "spec: {type: safety, horizon: infinite, tolerance: 0}\n"),
            "spec.tolerance");
  EXPECT_EQ(error_key(text.substr(0, text.find("spec:")) + "spec: {type: safety, horizon: forever}\n"),
            "spec.horizon");
}

TEST(Unbounded, StationaryLookupIgnoresTheStep) {
  const Policy policy = run(from_yaml(kRuin), DeviceKind::Reference, SweepChoice::Auto, nullptr);
  const double state[] = {3.0};
  double input[1] = {0}, probability = -1;
  EXPECT_EQ(policy.lookup(state, 1, 12345, input, &probability), LookupStatus::Ok);
  EXPECT_NEAR(probability, 0.3, kTolerance);
}

}  // namespace
}  // namespace amytiss
