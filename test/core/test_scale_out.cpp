// Scale-out in one process: the weighted split, the compute.devices syntax and its checks, and
// several devices (the CPU device split into sub-devices with clCreateSubDevices) giving values
// and inputs bit-identical to one device, with the dense and the factored sweep.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "factored/factored_plan.hpp"
#include "opencl/device.hpp"
#include "execute.hpp"
#include "scale_out/partition.hpp"
#include "scale_out/team_factored.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

// The CPU device split into parts of one compute unit (two on a two-core machine), and the whole
// CPU device beside those parts: three devices of unequal weight.
const std::vector<std::string> kParts = {"cpu:0/1"};
const std::vector<std::string> kUnequal = {"cpu:0", "cpu:0/1"};

using test_support::from_yaml;
using test_support::has_note;

// Traffic-like 3-d chain (each coordinate reads two states and at most one input): factored.
std::string chain_yaml() {
  return "name: chain\n"
         "states: {lb: [0, 0, 0], ub: [4, 4, 4], eta: [0.25, 0.25, 0.5]}\n"
         "inputs: {lb: [0, 0], ub: [1, 1], eta: [1, 1]}\n"
         "dynamics: [\"0.7*x0 + 0.2*x2 + 0.5*u0\", \"0.3*x0 + 0.6*x1\", \"0.4*x1 + 0.5*x2 + 0.6*u1\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.2, 0.2, 0.3]}\n"
         "spec: {type: safety, horizon: 4, safe: {lb: [0, 0, 0], ub: [3.5, 3.5, 3.5]}}\n";
}

// 2-d robot with a disturbance and a cut window: the dense sweep's padded values.
std::string robot_yaml() {
  return "name: robot\n"
         "states: {lb: [-5, -5], ub: [5, 5], eta: [0.5, 0.5]}\n"
         "inputs: {lb: [-1, -1], ub: [1, 1], eta: [0.5, 0.5]}\n"
         "disturbances: {lb: [-0.2], ub: [0.2], eta: [0.2]}\n"
         "dynamics: [\"x0 + u0 + w0\", \"x1 + u1 * cos(x0)\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.3, 0.3], truncation: cutting_probability,"
         " cutting_probability: 1.0e-4}\n"
         "spec: {type: reach_avoid, horizon: 5, target: {lb: [2, 2], ub: [4, 4]}, avoid: {lb: [-1, -1], ub: [0, 1]}}\n";
}

Policy run(const Abstraction& a, SweepChoice sweep, const std::vector<std::string>& devices,
           SynthesisReport* report = nullptr, double memory_fraction = 0.5, bool entry_per_item = false) {
  SynthesisOptions options;
  options.compute.device = DeviceKind::Cpu;
  options.compute.sweep = sweep;
  options.compute.devices = devices;
  options.compute.memory_fraction = memory_fraction;
  detail::OpenClEngineOptions engine;
  engine.factored_vector_width = entry_per_item ? 1 : 0;
  SynthesisReport local;
  return detail::synthesize_opencl(a, options, report ? report : &local, engine);
}

void expect_identical(const Policy& one, const Policy& many) {
  EXPECT_EQ(one.values, many.values);  // bit-identical, not within a tolerance
  EXPECT_EQ(one.input_index, many.input_index);
}

std::size_t cpu_compute_units() {
  std::vector<EngineNote> notes;
  ComputeConfig compute;
  compute.device = DeviceKind::Cpu;
  return detail::choose_device(compute, notes).compute_units;
}

TEST(Split, ContiguousCoveringAndProportionalToWeight) {
  const auto ranges = detail::split_by_weight(100, {1, 3});
  ASSERT_EQ(ranges.size(), 2u);
  EXPECT_EQ(ranges[0].begin, 0u);
  EXPECT_EQ(ranges[0].end, 25u);
  EXPECT_EQ(ranges[1].begin, 25u);
  EXPECT_EQ(ranges[1].end, 100u);
  const auto few = detail::split_by_weight(2, {1, 1, 1});
  EXPECT_EQ(few.back().end, 2u);
  for (std::size_t i = 1; i < few.size(); ++i) EXPECT_EQ(few[i].begin, few[i - 1].end);
}

// A stage whose output digits have the given radices (variables, ids 0, 1, ...).
detail::FactoredStage stage_with(const std::vector<std::size_t>& radices, std::optional<std::size_t> vector_digit) {
  detail::FactoredStage stage;
  stage.output_entries = 1;
  for (std::size_t j = 0; j < radices.size(); ++j) {
    stage.output.push_back({false, j, radices[j]});
    stage.output_entries *= radices[j];
  }
  stage.output_size = stage.output_entries;
  stage.vector_digit = vector_digit;
  return stage;
}

TEST(StageParts, MajorDigitWhenItHasEnoughValuesElseEveryDigitBeforeTheVectorDigit) {
  const auto by_major = detail::stage_parts(stage_with({8, 3, 5}, 2), 2);
  EXPECT_TRUE(by_major.by_major_digit);
  EXPECT_EQ(by_major.parts, 8u);
  EXPECT_EQ(by_major.entries, 15u);
  const auto by_prefix = detail::stage_parts(stage_with({2, 3, 5}, 2), 4);
  EXPECT_FALSE(by_prefix.by_major_digit);
  EXPECT_EQ(by_prefix.parts, 6u);
  EXPECT_EQ(by_prefix.entries, 5u);
  const auto scalar = detail::stage_parts(stage_with({2, 3}, std::nullopt), 4);
  EXPECT_EQ(scalar.parts, 6u);
  EXPECT_EQ(scalar.entries, 1u);
  const auto whole = detail::stage_parts(stage_with({4, 3}, 0), 2);
  EXPECT_EQ(whole.parts, 1u);
}

TEST(StageParts, NoExchangeBetweenStagesSplitByTheSameVariable) {
  detail::FactoredPlan plan;
  plan.stages = {stage_with({8, 3}, 1), stage_with({8, 5}, 1), stage_with({6, 5}, 1)};
  plan.stages[2].output[0].id = 7;  // another variable
  std::vector<detail::StageParts> parts;
  for (const auto& stage : plan.stages) parts.push_back(detail::stage_parts(stage, 2));
  EXPECT_FALSE(detail::exchange_after(plan, parts, 0));  // same variable 0, 8 values
  EXPECT_TRUE(detail::exchange_after(plan, parts, 1));   // the next is split by variable 7
  EXPECT_TRUE(detail::exchange_after(plan, parts, 2));   // Q: the input choice reads all of it
}

TEST(DeviceSelector, ParsesKindsIndicesAndParts) {
  const auto gpu = parse_device_selector("gpu:1");
  ASSERT_TRUE(gpu);
  EXPECT_EQ(gpu->kind, DeviceSelector::Kind::Gpu);
  EXPECT_EQ(gpu->index, 1u);
  const auto parts = parse_device_selector("cpu:0/2");
  ASSERT_TRUE(parts);
  EXPECT_EQ(parts->kind, DeviceSelector::Kind::Cpu);
  EXPECT_EQ(parts->units_per_part, 2u);
  const auto indexed = parse_device_selector("1.0");
  ASSERT_TRUE(indexed);
  EXPECT_EQ(indexed->platform, 1u);
  for (const char* bad : {"gpu", "gpu:x", "tpu:0", "cpu:0/0", "1", "1.", ""})
    EXPECT_FALSE(parse_device_selector(bad)) << bad;
}

TEST(DeviceSelector, ValidateNamesTheEntryAndAnExample) {
  YAML::Node root = YAML::Load(robot_yaml());
  root["compute"] = YAML::Load("{devices: [gpu:0, gpu]}");
  try {
    config_from_yaml(root);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), "compute.devices[1]");
    EXPECT_NE(std::string(error.what()).find("devices: [gpu:0, gpu:1]"), std::string::npos) << error.what();
  }
  root["compute"] = YAML::Load("{devices: [all, cpu:0]}");
  EXPECT_THROW(config_from_yaml(root), ConfigError);
  root["compute"] = YAML::Load("{devices: all}");
  EXPECT_EQ(config_from_yaml(root).compute.devices, std::vector<std::string>{"all"});
}

TEST(SubDevices, DenseSweepIsBitIdenticalToOneDevice) {
  if (cpu_compute_units() < 2) GTEST_SKIP() << "the CPU device has one compute unit: nothing to split";
  const Abstraction a = from_yaml(robot_yaml());
  const Policy one = run(a, SweepChoice::Dense, {});
  SynthesisReport report;
  expect_identical(one, run(a, SweepChoice::Dense, kParts, &report));
  EXPECT_TRUE(has_note(report, "device 1")) << "expected two devices";
  EXPECT_GT(report.exchange_bytes_per_step, 0.0);
  expect_identical(one, run(a, SweepChoice::Dense, kUnequal));
}

TEST(SubDevices, FactoredSweepIsBitIdenticalToOneDevice) {
  if (cpu_compute_units() < 2) GTEST_SKIP() << "the CPU device has one compute unit: nothing to split";
  const Abstraction a = from_yaml(chain_yaml());
  const Policy one = run(a, SweepChoice::Factored, {});
  expect_identical(one, run(a, SweepChoice::Factored, kParts));
  expect_identical(one, run(a, SweepChoice::Factored, kUnequal));
  // The GPU shape (one entry per work-item) splits the same entries.
  expect_identical(one, run(a, SweepChoice::Factored, kParts, nullptr, 0.5, true));
}

TEST(SubDevices, FactoredSweepSplitBeyondTheMajorDigitIsBitIdenticalToOneDevice) {
  if (cpu_compute_units() < 2) GTEST_SKIP() << "the CPU device has one compute unit: nothing to split";
  // x0 on two points: the stages' major digit has fewer values than the three devices, so their
  // rows are split by every digit before the vector digit (the kernels keep rows in output order).
  std::string yaml = chain_yaml();
  yaml.replace(yaml.find("eta: [0.25, 0.25, 0.5]"), 22, "eta: [4.0, 0.05, 0.5]");
  const Abstraction a = from_yaml(yaml);
  std::string reason;
  const auto plan = detail::plan_factored_sweep(a, 1e18, 1e18, &reason);
  ASSERT_TRUE(plan) << reason;
  const std::size_t fewest_devices_of_unequal = 3;  // the whole CPU and at least two parts
  const auto parts = detail::stage_parts(plan->stages.front(), fewest_devices_of_unequal);
  ASSERT_GT(parts.parts, 1u);
  ASSERT_FALSE(parts.by_major_digit);
  expect_identical(run(a, SweepChoice::Factored, {}), run(a, SweepChoice::Factored, kUnequal));
}

TEST(SubDevices, SlicedFactoredSweepIsBitIdenticalToOneDevice) {
  if (cpu_compute_units() < 2) GTEST_SKIP() << "the CPU device has one compute unit: nothing to split";
  const Abstraction a = from_yaml(chain_yaml());
  std::string reason;
  const auto plan = detail::plan_factored_sweep(a, 1e18, 1e18, &reason);
  ASSERT_TRUE(plan) << reason;
  std::vector<EngineNote> notes;
  ComputeConfig cpu;
  cpu.device = DeviceKind::Cpu;
  const double fraction = double(plan->device_bytes) * 0.6 / double(detail::choose_device(cpu, notes).global_memory);
  SynthesisReport one_report, many_report;
  const Policy one = run(a, SweepChoice::Factored, {}, &one_report, fraction);
  ASSERT_TRUE(has_note(one_report, "slices")) << "expected a sliced plan";
  expect_identical(one, run(a, SweepChoice::Factored, kParts, &many_report, fraction));
  EXPECT_TRUE(has_note(many_report, "slices"));
}

TEST(SubDevices, RecordsThatExceedOneDeviceAreStoredAcrossTwo) {
  if (cpu_compute_units() < 2) GTEST_SKIP() << "the CPU device has one compute unit: nothing to split";
  const Abstraction a = from_yaml(robot_yaml());
  std::vector<EngineNote> notes;
  ComputeConfig cpu;
  cpu.device = DeviceKind::Cpu;
  const double memory = double(detail::choose_device(cpu, notes).global_memory);
  // A budget of 70% of the records plus 64 KiB for the value arrays (about 20 KiB): all the
  // records do not fit one device, half of them do.
  const double records = estimate_memory(a).stored_transition_bytes;
  ASSERT_GT(0.3 * records, 65536.0) << "the problem is too small for this test";
  const double fraction = (0.7 * records + 65536.0) / memory;
  SynthesisOptions stored;
  stored.compute.device = DeviceKind::Cpu;
  stored.compute.sweep = SweepChoice::Dense;
  stored.compute.transitions = TransitionStorage::Stored;
  stored.compute.memory_fraction = fraction;
  SynthesisReport refused;
  EXPECT_THROW(detail::synthesize_opencl(a, stored, &refused), DeviceError);
  stored.compute.devices = kParts;
  SynthesisReport report;
  const Policy many = detail::synthesize_opencl(a, stored, &report);
  EXPECT_TRUE(has_note(report, "transitions: stored (requested")) << "expected stored records";
  expect_identical(run(a, SweepChoice::Dense, {}), many);
}

TEST(ScaleOutPlan, DryRunDescribesSlicesMemoryAndExchange) {
  if (cpu_compute_units() < 2) GTEST_SKIP() << "the CPU device has one compute unit: nothing to split";
  SynthesisOptions options;
  options.compute.devices = kParts;
  options.compute.sweep = SweepChoice::Dense;
  const std::vector<std::string> lines = describe_synthesis(from_yaml(robot_yaml()), options);
  auto contains = [&](const std::string& fragment) {
    return std::any_of(lines.begin(), lines.end(),
                       [&](const std::string& l) { return l.find(fragment) != std::string::npos; });
  };
  EXPECT_TRUE(contains("device 0"));
  EXPECT_TRUE(contains("device 1"));
  EXPECT_TRUE(contains("states [0, "));
  EXPECT_TRUE(contains("exchange per step"));
  options.compute.sweep = SweepChoice::Factored;
  const std::vector<std::string> factored = describe_synthesis(from_yaml(chain_yaml()), options);
  EXPECT_TRUE(std::any_of(factored.begin(), factored.end(),
                          [](const std::string& l) { return l.find("stage 0") != std::string::npos; }));
}

}  // namespace
}  // namespace amytiss
