// The OpenCL engine (on pocl here) against the serial reference engine, and its own invariants:
// stored == on-the-fly, work-item == work-group sweep, chunked == unchunked, device listing,
// cancellation, reports.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "execute.hpp"
#include "opencl/source.hpp"
#include "agreement.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using namespace test_support;
using detail::OpenClEngineOptions;
using detail::SweepVariant;

// Values are stored in float, masses too, the contraction is accumulated in double (docs/engine.md
// bounds the error by horizon * (dims + 1) * 2^-24); the product contract asks for 1e-5.
constexpr double kValueTolerance = 1e-5;
// Inputs must agree wherever the best input beats the chosen one by more than this.
constexpr double kInputMarginTolerance = 1e-5;


SynthesisOptions cpu_options(TransitionStorage transitions = TransitionStorage::Auto) {
  SynthesisOptions options;
  options.compute.device = DeviceKind::Cpu;
  options.compute.transitions = transitions;
  return options;
}

// The dense sweep whatever the dynamics (the engine's choice may be the factored sweep).
SynthesisOptions dense_options(TransitionStorage transitions = TransitionStorage::Auto) {
  SynthesisOptions options = cpu_options(transitions);
  options.compute.sweep = SweepChoice::Dense;
  return options;
}

double seconds_of(const SynthesisReport& report) {
  double total = 0;
  for (const auto& phase : report.phases)
    if (!phase.is_breakdown() && !phase.is_setup()) total += phase.seconds;
  return total;
}

// Runs the reference, the dense sweep and the engine's own choice (the factored sweep where the
// dynamics allow it), checks the contract for both, prints the figures.
void expect_agreement(const std::string& label, const Abstraction& a,
                      TransitionStorage transitions = TransitionStorage::Auto) {
  const auto reference_start = std::chrono::steady_clock::now();
  const Policy reference = synthesize_reference(a, {}, nullptr);
  const double reference_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - reference_start).count();
  SynthesisReport dense_report, auto_report;
  const Policy dense_policy = detail::synthesize_opencl(a, dense_options(transitions), &dense_report);
  const Policy chosen = synthesize(a, cpu_options(transitions), &auto_report);
  auto check = [&](const char* name, const Policy& opencl, const SynthesisReport& report) {
    const Agreement agreement = compare(a, reference, opencl);
    std::printf("[%s, %s] pairs %zu, max |dV| %.3g, input mismatches %zu (max margin %.3g), reference %.3f s, "
                "opencl %.3f s (%s)\n",
                label.c_str(), name, a.pairs(), agreement.max_value_difference, agreement.input_mismatches,
                agreement.max_mismatch_margin, reference_seconds, seconds_of(report), report.transitions.c_str());
    EXPECT_LE(agreement.max_value_difference, kValueTolerance) << label << ", " << name;
    EXPECT_LE(agreement.max_mismatch_margin, kInputMarginTolerance) << label << ", " << name;
    // Values are probabilities: the policy file refuses anything outside [0, 1].
    for (double value : opencl.values) {
      ASSERT_GE(value, 0.0) << label;
      ASSERT_LE(value, 1.0) << label;
    }
  };
  check("dense", dense_policy, dense_report);
  check("auto", chosen, auto_report);
}

std::string robot_reach_avoid_yaml(double state_eta, double input_eta, unsigned horizon) {
  return "name: robot_reach_avoid\n"
         "states: {lb: [-10, -10], ub: [10, 10], eta: [" + std::to_string(state_eta) + ", " +
         std::to_string(state_eta) + "]}\n"
         "inputs: {lb: [-1, -1], ub: [1, 1], eta: [" + std::to_string(input_eta) + ", " +
         std::to_string(input_eta) + "]}\n"
         "constants: {tau: 10.0}\n"
         "dynamics: [\"x0 + tau*u0*cos(u1)\", \"x1 + tau*u0*sin(u1)\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.75, 0.75],\n"
         "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"
         "spec: {type: reach_avoid, horizon: " + std::to_string(horizon) + ",\n"
         "       target: {lb: [5, 5], ub: [7, 7]}, avoid: {lb: [-2, -2], ub: [2, 2]}}\n";
}

std::string robot_safety_yaml(double state_eta, double input_eta, unsigned horizon) {
  return "name: robot_safety\n"
         "states: {lb: [-10, -10], ub: [10, 10], eta: [" + std::to_string(state_eta) + ", " +
         std::to_string(state_eta) + "]}\n"
         "inputs: {lb: [-1, -1], ub: [1, 1], eta: [" + std::to_string(input_eta) + ", " +
         std::to_string(input_eta) + "]}\n"
         "disturbances: {lb: [-1], ub: [1], eta: [0.2]}\n"
         "constants: {tau: 10.0}\n"
         "dynamics: [\"x0 + tau*u0*cos(u1) + w0\", \"x1 + tau*u0*sin(u1) + w0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.75, 0.75],\n"
         "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"
         "spec: {type: safety, horizon: " + std::to_string(horizon) + "}\n";
}

TEST(OpenClEngine, ListsDevices) {
  const auto devices = list_opencl_devices();
  ASSERT_FALSE(devices.empty()) << "pocl (pocl-opencl-icd) must be installed";
  for (const auto& line : devices) {
    EXPECT_EQ(line.rfind("[", 0), 0u) << line;
    EXPECT_NE(line.find(" / "), std::string::npos) << line;
    EXPECT_NE(line.find("iB, "), std::string::npos) << line;  // the global memory
  }
}

TEST(OpenClEngine, RobotReachAvoidReducedAgreesWithReference) {
  expect_agreement("robot reach-avoid reduced", from_yaml(robot_reach_avoid_yaml(1.0, 0.2, 8)));
}

TEST(OpenClEngine, RobotSafetyWithDisturbanceReducedAgreesWithReference) {
  expect_agreement("robot safety reduced", from_yaml(robot_safety_yaml(1.0, 0.4, 6)));
}

TEST(OpenClEngine, RoomTemperature3dAgreesWithReference) {
  // Paper section 7 (3-d variant): rooms 0 and 2 heated, conduction 0.2, beta 0.022,
  // heater gamma 0.05, T_e = -1, T_h = 50; noise standard deviation 0.1 so windows span cells.
  const std::string yaml =
      "name: room_temperature_3d\n"
      "states: {lb: [19, 19, 19], ub: [21, 21, 21], eta: [0.4, 0.4, 0.4]}\n"
      "inputs: {lb: [0, 0], ub: [1, 1], eta: [0.2, 0.2]}\n"
      "constants: {c: 0.2, beta: 0.022, gamma: 0.05, te: -1, th: 50}\n"
      "dynamics: [\"(1 - 2*c - beta - gamma*u0)*x0 + gamma*th*u0 + c*(x1 + x2) + beta*te\",\n"
      "           \"(1 - 2*c - beta)*x1 + c*(x0 + x2) + beta*te\",\n"
      "           \"(1 - 2*c - beta - gamma*u1)*x2 + gamma*th*u1 + c*(x0 + x1) + beta*te\"]\n"
      "noise: {type: additive, distribution: normal, covariance: [0.01, 0.01, 0.01],\n"
      "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"
      "spec: {type: safety, horizon: 8}\n";
  expect_agreement("room temperature 3d", from_yaml(yaml));
}

TEST(OpenClEngine, RandomAffineSystemsWithDisturbancesAgreeWithReference) {
  for (std::uint64_t seed : {11u, 12u}) {
    const Abstraction safety = random_affine_abstraction(seed, 2, 1, true, safety_spec(5), 7);
    expect_agreement("random affine safety seed " + std::to_string(seed), safety);
    const Abstraction reach = random_affine_abstraction(
        seed + 100, 3, 2, true, reach_avoid_spec(4, box({0.2, -1, -1}, {1, 1, 1}), box({-1, -1, -1}, {-0.6, 1, 1})), 5);
    expect_agreement("random affine reach-avoid seed " + std::to_string(seed + 100), reach);
  }
}

TEST(OpenClEngine, RandomNonlinearExpressionSystemsAgreeWithReference) {
  std::mt19937_64 generator(7);
  std::uniform_real_distribution<double> coefficient(-0.5, 0.5);
  for (int trial = 0; trial < 3; ++trial) {
    char dynamics[512];
    std::snprintf(dynamics, sizeof dynamics,
                  "[\"0.6*x0 + %.6f*sin(x1) + 0.5*u0 + %.6f*w0\", \"0.7*x1 + %.6f*x0*x0 + 0.4*u0*cos(x0) + 0.2*w0\"]",
                  coefficient(generator), coefficient(generator), coefficient(generator));
    const std::string yaml = std::string("name: random_nonlinear\n") +
                             "states: {lb: [-2, -2], ub: [2, 2], eta: [0.25, 0.25]}\n"
                             "inputs: {lb: [-1], ub: [1], eta: [0.25]}\n"
                             "disturbances: {lb: [-0.3], ub: [0.3], eta: [0.3]}\n"
                             "dynamics: " + dynamics + "\n"
                             "noise: {type: additive, distribution: normal, covariance: [0.04, 0.09],\n"
                             "        truncation: cutting_probability, cutting_probability: 1.0e-4}\n"
                             "spec: {type: reach_avoid, horizon: 6, target: {lb: [-0.5, -0.5], ub: [0.5, 0.5]},\n"
                             "       avoid: {lb: [1.5, -2], ub: [2, 2]}}\n";
    expect_agreement("random nonlinear " + std::to_string(trial), from_yaml(yaml));
  }
}

TEST(OpenClEngine, MultiplicativeAndUniformNoiseAgreeWithReference) {
  const std::string grid =
      "states: {lb: [-2, -2], ub: [2, 2], eta: [0.25, 0.25]}\n"
      "inputs: {lb: [-1], ub: [1], eta: [0.5]}\n"
      "dynamics: [\"0.8*x0 + 0.3*u0\", \"0.5*x1 + 0.2*x0*u0\"]\n"
      "spec: {type: safety, horizon: 5, safe: {lb: [-1.5, -1.5], ub: [1.5, 1.5]}}\n";
  expect_agreement("multiplicative normal",
                   from_yaml("name: m\n" + grid +
                             "noise: {type: multiplicative, distribution: normal, covariance: [0.04, 0.01],\n"
                             "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"));
  expect_agreement("additive uniform",
                   from_yaml("name: u\n" + grid +
                             "noise: {type: additive, distribution: uniform, half_width: [0.3, 0.2],\n"
                             "        truncation: cutting_probability}\n"));
  expect_agreement("fixed region, no truncation",
                   from_yaml("name: f\n" + grid +
                             "noise: {type: additive, distribution: normal, covariance: [0.04, 0.04],\n"
                             "        truncation: fixed_region, fixed_region: [0.5, 0.25]}\n"));
  // Window half width (20 cells) far beyond the grid (5 cells) and means far off the grid:
  // the kept range is nearest +- h of the noise model, not of the capped layout.
  expect_agreement("wide noise, small grid",
                   from_yaml("name: w\n"
                             "states: {lb: [-1], ub: [1], eta: [0.5]}\n"
                             "inputs: {lb: [-1], ub: [1], eta: [0.25]}\n"
                             "dynamics: [\"0.5*x0 + 9*u0\"]\n"
                             "noise: {type: additive, distribution: normal, covariance: [9.0],\n"
                             "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"
                             "spec: {type: safety, horizon: 3}\n"));
  expect_agreement("no truncation",
                   from_yaml("name: n\n" + grid +
                             "noise: {type: additive, distribution: normal, covariance: [0.04, 0.04],\n"
                             "        truncation: none}\n"));
}

// A dimension without noise (variance 0): the post state's cell [lo, hi) gets all the mass, in a
// one-cell window. x2's means land exactly on cell faces for odd grid indices (0.5 * 0.25 * k),
// so the half-open rule is exercised; stored and on-the-fly compute the masses separately.
TEST(OpenClEngine, ZeroVarianceDimensionAgreesWithReference) {
  const std::string grid =
      "states: {lb: [-1, -1, -1], ub: [1, 1, 1], eta: [0.25, 0.25, 0.25]}\n"
      "inputs: {lb: [-1], ub: [1], eta: [0.5]}\n"
      "dynamics: [\"0.7*x0 + 0.2*x2 + 0.3*u0\", \"0.6*x1 - 0.2*x0*u0\", \"0.5*x2 + 0.25*u0\"]\n"
      "spec: {type: reach_avoid, horizon: 5, target: {lb: [-0.3, -0.3, -0.3], ub: [0.3, 0.3, 0.3]},\n"
      "       avoid: {lb: [0.8, -1, -1], ub: [1, 1, 1]}}\n";
  const std::string noises[] = {
      "noise: {type: additive, distribution: normal, covariance: [0.04, 0.02, 0.0],\n"
      "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n",
      "noise: {type: additive, distribution: normal, covariance: [0.04, 0.02, 0.0], truncation: none}\n",
      "noise: {type: additive, distribution: normal, covariance: [0.04, 0.02, 0.0],\n"
      "        truncation: fixed_region, fixed_region: [0.5, 0.5, 0.5]}\n",
      "noise: {type: multiplicative, distribution: normal, covariance: [0.04, 0.0, 0.02],\n"
      "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n",
  };
  for (std::size_t i = 0; i < sizeof noises / sizeof noises[0]; ++i) {
    const Abstraction a = from_yaml("name: zero_variance\n" + grid + noises[i]);
    const std::size_t deterministic_dim = i == 3 ? 1 : 2;
    EXPECT_EQ(a.noise->window_half_cells()[deterministic_dim], 0) << "noise " << i;
    expect_agreement("zero variance, noise " + std::to_string(i) + ", stored", a, TransitionStorage::Stored);
    // On the fly recomputes the records with the same compute_record(); once is enough.
    if (i == 0)
      expect_agreement("zero variance, noise " + std::to_string(i) + ", on the fly", a, TransitionStorage::OnTheFly);
  }
}

// Same kernels, four ways: stored/on-the-fly x work-item/work-group, plus a chunked run. The
// per-(state, input) arithmetic is the same code, so the results must be bit-identical.
// Float-stored masses of a row can sum to slightly more than 1; next to the target that used to
// give values of 1 + 1e-8, which the policy file refuses. Coarse vehicle3d is such a case.
TEST(OpenClEngine, ValuesStayProbabilitiesWhereRoundedRowsSumAboveOne) {
  Config config = test_support::shipped_abstraction("vehicle3d.yaml");
  config.states.eta = {1.0, 1.0, 0.4};
  config.spec.horizon = 4;
  const Abstraction a = Abstraction::from_config(config);
  expect_agreement("vehicle3d coarse", a, TransitionStorage::Stored);
  SynthesisOptions group_options = cpu_options(TransitionStorage::Stored);
  OpenClEngineOptions group_engine;
  group_engine.variant = SweepVariant::GroupPerState;
  const Policy grouped = detail::synthesize_opencl(a, group_options, nullptr, group_engine);
  EXPECT_LE(*std::max_element(grouped.values.begin(), grouped.values.end()), 1.0);
}

// StocHy's CSB benchmark is n decoupled copies of x+ = 0.8x + noise, autonomous, safety in the
// grid: the abstraction is a product, so V_0 of the n-d system is V_0 of the 1-d system to the
// n-th power. With truncation none in 14 dimensions, a value array padded by n - 1 cells per side
// would need 4^14 cells (2 GiB, refused by pocl); the whole-grid window needs no padding.
TEST(OpenClEngine, StochyFourteenDimensionsIsTheOneDimensionalValueToThe14th) {
  constexpr int kDims = 14;
  // Float masses: the relative error of a product of 14 factors over 6 steps stays far below this.
  constexpr double kRelativeTolerance = 1e-5;
  auto stochy = [](int dims) {
    std::string lb, ub, eta, dynamics, covariance;
    for (int i = 0; i < dims; ++i) {
      const std::string comma = i ? ", " : "";
      lb += comma + "-0.5";
      ub += comma + "0.5";
      eta += comma + "1";
      covariance += comma + "0.2";
      dynamics += comma + "\"0.8*x" + std::to_string(i) + "\"";
    }
    return "name: stochy\nstates: {lb: [" + lb + "], ub: [" + ub + "], eta: [" + eta + "]}\n" +
           "dynamics: [" + dynamics + "]\n" +
           "noise: {type: additive, distribution: normal, covariance: [" + covariance +
           "], truncation: none}\nspec: {type: safety, horizon: 6}\n";
  };
  const Policy one = synthesize_reference(from_yaml(stochy(1)), {}, nullptr);
  const Abstraction fourteen = from_yaml(stochy(kDims));
  const Policy many = synthesize(fourteen, cpu_options(), nullptr);
  ASSERT_EQ(many.states.size(), std::size_t(1) << kDims);
  for (std::size_t cell : {std::size_t(0), std::size_t(5), many.states.size() - 1}) {
    const std::vector<double> point = many.states.point(cell);
    double expected = 1.0;
    for (double coordinate : point) expected *= one.value(0, coordinate < 0 ? 0 : 1);
    EXPECT_NEAR(many.value(0, cell), expected, kRelativeTolerance * expected) << "cell " << cell;
  }
}

TEST(OpenClEngine, StoredOnTheFlyGroupAndChunkedRunsAreIdentical) {
  const Abstraction a = from_yaml(robot_safety_yaml(1.0, 0.4, 4));
  SynthesisReport stored_report;
  const Policy stored = detail::synthesize_opencl(a, dense_options(TransitionStorage::Stored), &stored_report,
                                                  {SweepVariant::ItemPerState, 0, {}, false});
  EXPECT_EQ(stored_report.transitions.rfind("stored", 0), 0u) << stored_report.transitions;
  struct Variant {
    const char* name;
    TransitionStorage transitions;
    OpenClEngineOptions engine;
  };
  const Variant variants[] = {
      {"on the fly, item", TransitionStorage::OnTheFly, {SweepVariant::ItemPerState, 0, {}, false}},
      {"stored, group (GPU path)", TransitionStorage::Stored, {SweepVariant::GroupPerState, 0, {}, false}},
      {"on the fly, group (GPU path)", TransitionStorage::OnTheFly, {SweepVariant::GroupPerState, 0, {}, false}},
      {"stored, item, chunks of 37 states", TransitionStorage::Stored, {SweepVariant::ItemPerState, 37, {}, false}},
      {"on the fly, group, chunks of 50 states", TransitionStorage::OnTheFly, {SweepVariant::GroupPerState, 50, {}, false}},
  };
  for (const Variant& variant : variants) {
    SynthesisReport report;
    const Policy other = detail::synthesize_opencl(a, dense_options(variant.transitions), &report, variant.engine);
    EXPECT_EQ(other.values, stored.values) << variant.name;
    EXPECT_EQ(other.input_index, stored.input_index) << variant.name;
    const bool group = variant.engine.variant == SweepVariant::GroupPerState;
    const bool logged = std::any_of(report.notes.begin(), report.notes.end(), [&](const EngineNote& note) {
      return note.kind == NoteKind::Sweep && note.text.find(group ? "work-group" : "work-item") != std::string::npos;
    });
    EXPECT_TRUE(logged) << variant.name << ": the sweep variant that ran is logged";
    if (variant.engine.max_states_per_chunk) {
      EXPECT_TRUE(std::any_of(report.notes.begin(), report.notes.end(),
                              [](const EngineNote& note) { return note.kind == NoteKind::Chunking; }))
          << variant.name;
    }
  }
}

TEST(OpenClEngine, AutoTransitionsFallsBackToOnTheFlyWhenStoredDoesNotFit) {
  const Abstraction a = from_yaml(robot_reach_avoid_yaml(1.0, 0.2, 2));
  SynthesisOptions options = cpu_options(TransitionStorage::Auto);
  options.compute.memory_fraction = 1e-6;  // a few KiB: the records cannot fit
  SynthesisReport report;
  options.compute.sweep = SweepChoice::Dense;
  const Policy small_budget = detail::synthesize_opencl(a, options, &report);
  EXPECT_EQ(report.transitions.rfind("on_the_fly (auto", 0), 0u) << report.transitions;
  SynthesisReport stored_report;
  const Policy stored = detail::synthesize_opencl(a, dense_options(TransitionStorage::Auto), &stored_report);
  EXPECT_EQ(stored_report.transitions.rfind("stored (auto", 0), 0u) << stored_report.transitions;
  EXPECT_EQ(small_budget.values, stored.values);
}

TEST(OpenClEngine, StoredRequestThatDoesNotFitIsRefusedNotReplaced) {
  const Abstraction a = from_yaml(robot_reach_avoid_yaml(1.0, 0.2, 2));
  SynthesisOptions options = dense_options(TransitionStorage::Stored);
  options.compute.memory_fraction = 1e-6;  // a few KiB: the records cannot fit
  try {
    detail::synthesize_opencl(a, options, nullptr);
    FAIL() << "expected DeviceError";
  } catch (const DeviceError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("compute.transitions: got stored, but the records do not fit", 0), 0u)
        << error.what();
  }
  // Not retried elsewhere either: the request is the user's.
  EXPECT_THROW(synthesize(a, options), DeviceError);
}

TEST(OpenClEngine, ReportsPhasesProgressAndMemory) {
  const Abstraction a = from_yaml(robot_reach_avoid_yaml(1.0, 0.2, 3));
  std::vector<Progress> seen;
  SynthesisOptions options = dense_options(TransitionStorage::Stored);
  options.profile = true;
  options.progress = [&](const Progress& progress) {
    seen.push_back(progress);
    return true;
  };
  SynthesisReport report;
  const Policy policy = detail::synthesize_opencl(a, options, &report);
  std::vector<std::string> names;
  for (const auto& phase : report.phases) names.push_back(phase.name);
  const std::size_t targets = std::size_t(std::count(a.roles.begin(), a.roles.end(), CellRole::FixedOne));
  ASSERT_GT(targets, 0u);
  const std::vector<std::string> expected = {"device setup", "kernel build", "construction", "step 2", "step 1", "step 0",
                                             "target cells' inputs (" + std::to_string(targets) + " cells, host)"};
  EXPECT_EQ(names, expected);
  EXPECT_GT(report.phases[2].pairs_per_second, 0);
  EXPECT_GT(report.phases[3].multiply_adds, 0);
  EXPECT_GT(report.phases[3].bytes, 0);
  EXPECT_GT(report.measured_bandwidth_bytes_per_second, 0);  // measured with profile
  EXPECT_GT(report.device_bytes, a.pairs() * sizeof(float));
  EXPECT_FALSE(report.device.empty());
  EXPECT_EQ(policy.computed_by, report.device);
  ASSERT_EQ(seen.size(), 5u);  // setup, construction, 3 steps
  EXPECT_EQ(seen.front().phase, Phase::Setup);
  EXPECT_EQ(seen[1].phase, Phase::Construction);
  EXPECT_EQ(seen.back().steps_done, 3u);
  EXPECT_DOUBLE_EQ(seen.back().percent(), 100.0);
}

TEST(OpenClEngine, CancelThrowsCancelled) {
  const Abstraction a = from_yaml(robot_reach_avoid_yaml(1.0, 0.2, 5));
  SynthesisOptions options = cpu_options();
  unsigned calls = 0;
  options.progress = [&](const Progress& progress) {
    ++calls;
    return progress.steps_done < 2;
  };
  EXPECT_THROW(synthesize(a, options), Cancelled);
  EXPECT_EQ(calls, 4u);  // setup, construction, step 1 done, step 2 done -> cancelled
}

TEST(OpenClEngine, FullCovarianceIsRefusedClearly) {
  const Abstraction a = from_yaml(
      "name: full\n"
      "states: {lb: [-1, -1], ub: [1, 1], eta: [0.5, 0.5]}\n"
      "dynamics: [\"0.5*x0\", \"0.5*x1\"]\n"
      "noise: {type: additive, distribution: normal, covariance: [0.04, 0.01, 0.01, 0.04],\n"
      "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"
      "spec: {type: safety, horizon: 2}\n");
  try {
    synthesize(a, cpu_options());
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), "noise.covariance");
    EXPECT_NE(std::string(error.what()).find("reference"), std::string::npos) << error.what();
  }
}

TEST(OpenClEngine, ExplicitRequestForAnAbsentDeviceKindFailsNamingTheDevicesPresent) {
  const Abstraction a = from_yaml(robot_reach_avoid_yaml(1.0, 0.2, 2));
  const auto devices = list_opencl_devices();
  auto present = [&](const char* type) {
    return std::any_of(devices.begin(), devices.end(),
                       [&](const std::string& line) { return line.find(std::string("(") + type) != std::string::npos; });
  };
  // CI has only pocl (no GPU); the GPU machine has no CPU device.
  if (present("GPU") && present("CPU")) GTEST_SKIP() << "both kinds present: no absent kind to request";
  const bool ask_gpu = !present("GPU");
  SynthesisOptions options = cpu_options();
  options.compute.device = ask_gpu ? DeviceKind::Gpu : DeviceKind::Cpu;
  try {
    synthesize(a, options);
    FAIL() << "expected DeviceError";
  } catch (const DeviceError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.rfind("compute.device: ", 0), 0u) << message;
    EXPECT_NE(message.find(std::string("got ") + (ask_gpu ? "gpu" : "cpu") + ", but no OpenCL"), std::string::npos)
        << message;
    EXPECT_NE(message.find("devices present"), std::string::npos) << message;
    EXPECT_NE(message.find(devices.front().substr(devices.front().find("] ") + 2, 20)), std::string::npos) << message;
  }
}

// A selection that matches nothing is a device request refused: DeviceError (exit status 1) naming
// its key, like an absent device kind.
TEST(OpenClEngine, UnknownDeviceSelectionIsARefusedRequest) {
  const Abstraction a = from_yaml(robot_reach_avoid_yaml(1.0, 0.2, 2));
  SynthesisOptions options = cpu_options();
  options.compute.platform = "no-such-platform-name";
  try {
    synthesize(a, options);
    FAIL() << "expected DeviceError";
  } catch (const DeviceError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("compute.platform: ", 0), 0u) << error.what();
  }
}

// The last dimension's window wider than the unrolled vector form (64 cells): the contraction
// falls back to a scalar loop over that dimension; both forms must agree with the reference.
TEST(OpenClEngine, WideLastDimensionWindowUsesTheScalarContractionAndAgrees) {
  const Abstraction wide = from_yaml(
      "name: wide\n"
      "states: {lb: [-1, -5], ub: [1, 5], eta: [0.5, 0.1]}\n"
      "inputs: {lb: [-1], ub: [1], eta: [1.0]}\n"
      "dynamics: [\"0.5*x0 + 0.5*u0\", \"0.9*x1 + u0\"]\n"
      "noise: {type: additive, distribution: normal, covariance: [0.04, 1.0], truncation: none}\n"
      "spec: {type: safety, horizon: 3, safe: {lb: [-1, -4], ub: [1, 4]}}\n");
  const std::string wide_source = detail::opencl_program_source(wide, false, 1);
  EXPECT_EQ(wide_source.find("double4 even0"), std::string::npos) << "scalar form expected";
  // Truncation none: the window is the whole dimension, its 101 cells.
  EXPECT_NE(wide_source.find("j < 101"), std::string::npos) << "window of the 101 cells of x1";
  expect_agreement("wide last dimension (scalar contraction)", wide, TransitionStorage::Stored);
  const std::string robot_source =
      detail::opencl_program_source(from_yaml(robot_reach_avoid_yaml(1.0, 0.2, 2)), false, 1);
  EXPECT_NE(robot_source.find("double4 even0"), std::string::npos) << "vector row form expected";
}

// Program binaries are cached on disk: the second run loads the binary (no front end) and gives
// bit-identical results; a corrupt entry is ignored (built from source again and overwritten).
TEST(OpenClEngine, ProgramBinaryCacheIsUsedAndACorruptEntryIsIgnored) {
  const Abstraction a = from_yaml(robot_reach_avoid_yaml(1.0, 0.4, 3));
  const std::string cache = ::testing::TempDir() + "amytiss_kernel_cache_" +
                            std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
  OpenClEngineOptions engine;
  engine.kernel_cache_dir = cache;
  auto logged = [](const SynthesisReport& report, const std::string& text) {
    return std::any_of(report.notes.begin(), report.notes.end(),
                       [&](const EngineNote& note) { return note.text.find(text) != std::string::npos; });
  };
  SynthesisReport first_report, second_report, third_report, uncached_report;
  const Policy first = detail::synthesize_opencl(a, cpu_options(), &first_report, engine);
  EXPECT_TRUE(logged(first_report, "compiled from source, program binary cached in " + cache));
  const Policy second = detail::synthesize_opencl(a, cpu_options(), &second_report, engine);
  EXPECT_TRUE(logged(second_report, "program binary from cache " + cache));
  EXPECT_EQ(second.values, first.values);
  EXPECT_EQ(second.input_index, first.input_index);

  std::size_t entries = 0;
  for (const auto& entry : std::filesystem::directory_iterator(cache)) {
    ++entries;
    std::ofstream(entry.path(), std::ios::binary | std::ios::trunc) << "not a program binary";
  }
  EXPECT_EQ(entries, 1u);
  const Policy third = detail::synthesize_opencl(a, cpu_options(), &third_report, engine);
  EXPECT_TRUE(logged(third_report, "compiled from source")) << "corrupt entry must be ignored";
  EXPECT_EQ(third.values, first.values);

  engine.kernel_cache_dir = "-";
  const Policy uncached = detail::synthesize_opencl(a, cpu_options(), &uncached_report, engine);
  EXPECT_FALSE(logged(uncached_report, "kernel build:")) << "\"-\" disables the cache";
  EXPECT_EQ(uncached.values, first.values);
  std::filesystem::remove_all(cache);
}

// With profile the device's copy bandwidth is measured once and then read from the cache folder;
// without profile nothing is measured.
TEST(OpenClEngine, ProfileMeasuresTheBandwidthOnceAndCachesIt) {
  const Abstraction a = from_yaml(robot_reach_avoid_yaml(1.0, 0.4, 2));
  const std::filesystem::path cache = fresh_test_directory("amytiss_bandwidth_cache_");
  OpenClEngineOptions engine;
  engine.kernel_cache_dir = cache.string();
  SynthesisOptions profiled = cpu_options();
  profiled.profile = true;
  SynthesisReport first, second, unprofiled;
  detail::synthesize_opencl(a, profiled, &first, engine);
  EXPECT_GT(first.measured_bandwidth_bytes_per_second, 0);
  EXPECT_NE(first.bandwidth_basis.find("measured now, cached in " + cache.string()), std::string::npos)
      << first.bandwidth_basis;
  detail::synthesize_opencl(a, profiled, &second, engine);
  EXPECT_EQ(second.measured_bandwidth_bytes_per_second, first.measured_bandwidth_bytes_per_second);
  EXPECT_EQ(second.bandwidth_basis.rfind("copy of ", 0), 0u) << second.bandwidth_basis;
  EXPECT_EQ(second.bandwidth_basis.find("measured now"), std::string::npos) << second.bandwidth_basis;
  detail::synthesize_opencl(a, cpu_options(), &unprofiled, engine);
  EXPECT_EQ(unprofiled.measured_bandwidth_bytes_per_second, 0);
  EXPECT_TRUE(unprofiled.bandwidth_basis.empty());
  std::filesystem::remove_all(cache);
}

TEST(OpenClEngine, RobotReachAvoidFullGridAgreesWithReference) {
  // The robot reach-avoid example's grid (config/robot_reach_avoid.yaml): 1681 states x 441 inputs = 741,321 pairs. The horizon is 6 instead of
  // 16 only to keep the serial reference under ~10 s here; the T_d = 16 comparison is recorded in
  // docs/engine.md (max |dV| 2.2e-7).
  const Abstraction a = from_yaml(robot_reach_avoid_yaml(0.5, 0.1, 6));
  ASSERT_EQ(a.pairs(), 741321u);
  expect_agreement("robot reach-avoid full", a);
}

}  // namespace
}  // namespace amytiss
