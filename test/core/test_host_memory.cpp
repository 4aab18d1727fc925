// Host memory: what the process may use (available_memory()), the plan's estimate against the
// bounds engine's measured peak, and the refusal of a run whose estimate exceeds what is available,
// before anything is allocated.
#include <gtest/gtest.h>
#include <malloc.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/resources.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using namespace amytiss::test_support;

std::string robot_yaml(const std::string& states_eta, const std::string& inputs_eta, const std::string& guarantee,
                       const std::string& disturbances_eta = "0.2", unsigned horizon = 4) {
  return "name: robot\n"
         "states: {lb: [-10, -10], ub: [10, 10], eta: [" + states_eta + ", " + states_eta + "]}\n"
         "inputs: {lb: [-1, -1], ub: [1, 1], eta: [" + inputs_eta + ", " + inputs_eta + "]}\n"
         "disturbances: {lb: [-1], ub: [1], eta: [" + disturbances_eta + "]}\n"
         "dynamics: [\"x0 + 2*u0*cos(u1) + 0.1*w0\", \"x1 + 2*u0*sin(u1) + 0.1*w0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.75, 0.75],\n"
         "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"
         "spec: {type: safety, horizon: " + std::to_string(horizon) + "}\n"
         "guarantee: " + guarantee + "\n";
}

// Peak resident set of one synthesis above what the process holds before it: the peak is reset
// to the resident set first (clear_refs 5), the heap's free memory given back.
constexpr double kMostEstimatePerPeak = 2.0;

struct Measured {
  double peak_bytes = 0, estimate_bytes = 0;
};
Measured measure(const Abstraction& a, SynthesisOptions options = {}) {
  options.compute = a.config.compute;
  malloc_trim(0);
  std::ofstream("/proc/self/clear_refs") << "5";
  const double before = double(resident_bytes());
  SynthesisReport report;
  synthesize(a, options, &report);
  return {double(report.host_peak_bytes) - before, estimate_memory(a, options.compute).host_bytes};
}

TEST(HostMemory, AvailableMemoryIsTheLeastLimitKnown) {
  const HostMemory available = available_memory();
  EXPECT_GT(available.bytes, 0);
  EXPECT_FALSE(available.source.empty());
  std::ifstream meminfo("/proc/meminfo");
  for (std::string key; meminfo >> key;) {
    double kilobytes = 0;
    if (key == "MemAvailable:" && meminfo >> kilobytes) EXPECT_LE(available.bytes, kilobytes * 1024);
  }
  const HostMemory limited = available_memory(12345);
  EXPECT_EQ(limited.bytes, 12345);
  EXPECT_EQ(limited.source, "a limit of the caller");
}

// The estimate covers the bounds engine's measured peak, and is within twice it, for shapes that
// take different methods: a 2-d grid and many inputs (whole tables), a 3-d system (elimination).
void expect_estimate_covers_peak(const std::string& yaml) {
  const Abstraction a = from_yaml(yaml);
  const Measured measured = measure(a);
  std::printf("estimate %.1f MB, peak %.1f MB (x%.2f), %zu cells x %zu inputs x %zu disturbances, method %s\n",
              measured.estimate_bytes / 1e6, measured.peak_bytes / 1e6, measured.estimate_bytes / measured.peak_bytes,
              a.states.size(), a.inputs.size(), a.disturbances.size(),
              estimate_memory(a).bounds_method.c_str());
  EXPECT_GE(measured.estimate_bytes, measured.peak_bytes);
  EXPECT_LE(measured.estimate_bytes, kMostEstimatePerPeak * measured.peak_bytes);
}

TEST(HostMemory, EstimateCoversThePeakOfA2dGrid) { expect_estimate_covers_peak(robot_yaml("0.05", "1", "system", "1")); }

TEST(HostMemory, EstimateCoversThePeakOfManyInputs) {
  expect_estimate_covers_peak(robot_yaml("0.5", "0.0625", "system", "1"));
}

TEST(HostMemory, EstimateCoversThePeakOfA3dSystem) {
  expect_estimate_covers_peak(
      "name: system_3d\n"
      "states: {lb: [-2, -2, -1], ub: [2, 2, 1], eta: [0.05, 0.05, 0.1]}\n"
      "inputs: {lb: [-0.5], ub: [0.5], eta: [0.25]}\n"
      "disturbances: {lb: [-0.1], ub: [0.1], eta: [0.2]}\n"
      "dynamics: [\"x0 + 0.5*x1\", \"0.9*x1 + 0.2*sin(x0) + u0 + w0\", \"0.8*x2 + 0.1*x0*x1\"]\n"
      "noise: {type: additive, distribution: normal, covariance: [0.04, 0.04, 0.02],\n"
      "        truncation: cutting_probability, cutting_probability: 1.0e-4}\n"
      "spec: {type: safety, horizon: 3}\n"
      "guarantee: system\n");
}

// A run past the memory available is refused by the plan, naming the grid to coarsen, before the
// row bounds are allocated: at once, whatever the estimate.
void expect_refused(const std::string& yaml, const std::string& key, double limit_bytes = 0) {
  const Abstraction a = from_yaml(yaml);
  SynthesisOptions options;
  options.compute = a.config.compute;
  options.memory_limit_bytes = limit_bytes;
  const auto start = std::chrono::steady_clock::now();
  try {
    synthesize(a, options);
    ADD_FAILURE() << "not refused";
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), key) << error.what();
    EXPECT_NE(std::string(error.what()).find(" bytes"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("this process may use"), std::string::npos) << error.what();
  }
  EXPECT_THROW(describe_synthesis(a, options), ConfigError);  // --dry-run says so too
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
}

TEST(HostMemory, ManyInputsOrDisturbancesAreRefusedAtOnce) {
  expect_refused(robot_yaml("5", "0.0002", "system"), "inputs.eta");  // 1e8 inputs
  expect_refused(robot_yaml("5", "1", "system", "2e-8"), "disturbances.eta");  // 1e8 disturbances
  expect_refused(robot_yaml("0.02", "0.02", "system", "2"), "states.eta");  // 1e6 states x 1e4 inputs
}

TEST(HostMemory, TheLimitOfTheCallerIsComparedUnderBothGuarantees) {
  for (const char* guarantee : {"system", "abstraction"}) {
    const std::string yaml = robot_yaml("1", "0.5", guarantee);
    const Abstraction a = from_yaml(yaml);
    const double estimate = estimate_memory(a).host_bytes;
    ASSERT_GT(estimate, 0);
    expect_refused(yaml, "states.eta", estimate / 2);
    SynthesisOptions options;
    options.compute.device = DeviceKind::Reference;
    options.memory_limit_bytes = estimate * 1.01;
    EXPECT_NO_THROW(synthesize(a, options)) << guarantee;
  }
}

}  // namespace
}  // namespace amytiss
