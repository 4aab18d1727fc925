// The factored sweep: its plan (dependencies, order, slices), its mass tables, and its results
// against the reference engine and the dense sweep, sliced and unsliced, on pocl.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "factored/factored_plan.hpp"
#include "opencl/factored/program.hpp"
#include "opencl/factored/tables.hpp"
#include "opencl/device.hpp"
#include "execute.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using detail::FactoredPlan;

// Both engines sum the same exact products in another order: double rounding only.
constexpr double kValueTolerance = 1e-9;
constexpr double kMassTolerance = 1e-15;
constexpr double kUnlimitedBudget = 1e12;

using test_support::from_yaml;
using test_support::has_note;
using test_support::robot_disturbance_yaml;
using test_support::traffic_yaml;

std::string multiplicative_yaml() {
  return "name: multiplicative_small\n"
         "states: {lb: [-2, -2, -1], ub: [2, 2, 1], eta: [0.25, 0.25, 0.5]}\n"
         "inputs: {lb: [-1], ub: [1], eta: [0.5]}\n"
         "dynamics: [\"0.8*x0 + 0.3*u0\", \"0.5*x1 + 0.2*x0*u0\", \"0.9*x2\"]\n"
         "noise: {type: multiplicative, distribution: normal, covariance: [0.04, 0.01, 0.02],\n"
         "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"
         "spec: {type: safety, horizon: 5, safe: {lb: [-1.5, -1.5, -1], ub: [1.5, 1.5, 1]}}\n";
}

SynthesisOptions cpu_options() {
  SynthesisOptions options;
  options.compute.device = DeviceKind::Cpu;
  return options;
}

Policy run(const Abstraction& a, SweepChoice sweep, SynthesisReport* report = nullptr, double memory_fraction = 0.5) {
  SynthesisOptions options = cpu_options();
  options.compute.memory_fraction = memory_fraction;
  options.compute.sweep = sweep;
  SynthesisReport local;
  return detail::synthesize_opencl(a, options, report ? report : &local);
}

double max_difference(const std::vector<double>& a, const std::vector<double>& b) {
  EXPECT_EQ(a.size(), b.size());
  double largest = 0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) largest = std::max(largest, std::fabs(a[i] - b[i]));
  return largest;
}

TEST(FactoredPlan, TrafficReadsTwoStatesAndOneInputPerCoordinate) {
  const Abstraction a = from_yaml(traffic_yaml(0.4, 2));
  std::string reason;
  const auto plan = detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason);
  ASSERT_TRUE(plan) << reason;
  // Variables: x0 x1 x2 u0 u1 = 0..4.
  EXPECT_EQ(plan->reads[0], (std::vector<std::size_t>{0, 2, 3}));
  EXPECT_EQ(plan->reads[1], (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(plan->reads[2], (std::vector<std::size_t>{1, 2, 4}));
  EXPECT_EQ(plan->slices, 1u);
  EXPECT_EQ(plan->q_size, a.pairs());
  // Wide windows and few inputs: variable elimination must save most of the work.
  EXPECT_LT(plan->multiply_adds * 5, plan->dense_multiply_adds) << plan->describe();
}

// The host's line-by-line layout: each stage's output keeps its input's digits in order, less the
// contracted cell, then the variables new to the stage (one line's results side by side), then
// the largest remaining post cell that the next stage does not contract (the next stage's
// neighbouring lines); Q's states come first; no stage has a vector digit.
TEST(FactoredPlan, LinesLayoutWritesEachLinesResultsSideBySide) {
  const Abstraction a = from_yaml(traffic_yaml(0.4, 2));
  std::string reason;
  const auto plan =
      detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason, detail::FactoredLayout::Lines);
  ASSERT_TRUE(plan) << reason;
  auto same = [](const detail::TensorDigit& x, const detail::TensorDigit& y) {
    return x.post == y.post && x.id == y.id;
  };
  std::vector<detail::TensorDigit> input;
  for (std::size_t d = 0; d < a.states.dims(); ++d) input.push_back({true, d, a.states.count(d)});
  for (std::size_t k = 0; k + 1 < plan->stages.size(); ++k) {
    const detail::FactoredStage& stage = plan->stages[k];
    EXPECT_FALSE(stage.vector_digit);
    std::vector<detail::TensorDigit> expected;
    for (const detail::TensorDigit& digit : input)
      if (!(digit.post && digit.id == stage.dimension)) expected.push_back(digit);
    for (std::size_t v : plan->reads[stage.dimension]) {
      const detail::TensorDigit variable{false, v, plan->variables[v].count};
      const auto is_variable = [&](const detail::TensorDigit& digit) { return same(digit, variable); };
      if (std::none_of(input.begin(), input.end(), is_variable)) expected.push_back(variable);
    }
    auto last = expected.end();
    for (auto digit = expected.begin(); digit != expected.end(); ++digit)
      if (digit->post && digit->id != plan->stages[k + 1].dimension &&
          (last == expected.end() || digit->radix > last->radix))
        last = digit;
    if (last != expected.end()) std::rotate(last, last + 1, expected.end());
    ASSERT_EQ(stage.output.size(), expected.size());
    for (std::size_t j = 0; j < expected.size(); ++j)
      EXPECT_TRUE(same(stage.output[j], expected[j])) << "stage " << k << " digit " << j;
    input = stage.output;
  }
  const std::vector<detail::TensorDigit>& q = plan->stages.back().output;
  EXPECT_TRUE(std::is_partitioned(q.begin(), q.end(), [&](const detail::TensorDigit& digit) {
    return plan->variables[digit.id].space == detail::FactorVariable::Space::State;
  }));
}

TEST(FactoredPlan, SlicesWhenTheTensorsDoNotFitAndRefusesWhatCannotFit) {
  const Abstraction a = from_yaml(traffic_yaml(0.4, 2));
  std::string reason;
  const auto whole = detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason);
  ASSERT_TRUE(whole) << reason;
  const double sliced_budget = double(whole->device_bytes) * 0.6;
  const auto sliced = detail::plan_factored_sweep(a, sliced_budget, kUnlimitedBudget, &reason);
  ASSERT_TRUE(sliced) << reason;
  EXPECT_GT(sliced->slices, 1u);
  EXPECT_LE(double(sliced->device_bytes), sliced_budget);
  EXPECT_EQ(a.states.count(sliced->order.back()) % sliced->slices, 0u);
  EXPECT_DOUBLE_EQ(sliced->multiply_adds, whole->multiply_adds);
  EXPECT_FALSE(detail::plan_factored_sweep(a, 1000.0, kUnlimitedBudget, &reason));
  EXPECT_NE(reason.find("budget"), std::string::npos) << reason;
}

// Traffic on 15 cells per dimension: a row of 15 values spans 16 doubles (two cache lines).
std::string padded_traffic_yaml(unsigned horizon) { return traffic_yaml(0.5, horizon, 7.0); }

TEST(FactoredPlan, StageTensorsSpanWholeCacheLinesWhereThatCostsAnEighthAtMost) {
  std::string reason;
  const Abstraction padded = from_yaml(padded_traffic_yaml(2));
  const auto plan = detail::plan_factored_sweep(padded, kUnlimitedBudget, kUnlimitedBudget, &reason);
  ASSERT_TRUE(plan) << reason;
  ASSERT_EQ(plan->stages.size(), 3u);
  for (std::size_t k = 0; k < plan->stages.size(); ++k) {
    const detail::FactoredStage& stage = plan->stages[k];
    const std::size_t digits = stage.output.size();
    if (k + 1 == plan->stages.size()) {  // Q: never padded (its last digit is u1, 2 values)
      EXPECT_EQ(stage.output_size, stage.output_entries);
      continue;
    }
    ASSERT_EQ(stage.output.back().radix, 15u) << "stage " << k;
    EXPECT_EQ(stage.output_stride[digits - 2], 16u) << "stage " << k;
    EXPECT_EQ(stage.output_size, stage.output_entries / 15 * 16) << "stage " << k;
    // The next stage reads this one's entries where this one wrote them.
    const detail::FactoredStage& next = plan->stages[k + 1];
    for (std::size_t j = 0; j < next.output.size(); ++j)
      for (std::size_t i = 0; i < digits; ++i)
        if (next.output[j].post == stage.output[i].post && next.output[j].id == stage.output[i].id)
          EXPECT_EQ(next.input_stride[j], stage.output_stride[i]) << "stage " << k + 1 << " digit " << j;
  }
  // The two stage buffers' padding is in the device bytes; a budget without room for it keeps the
  // tensors unpadded rather than slicing them.
  const double padding_bytes =
      2.0 * sizeof(double) * double(plan->largest_stage_tensor - plan->largest_stage_tensor / 16 * 15);
  const auto tight = detail::plan_factored_sweep(padded, double(plan->device_bytes) - 1, kUnlimitedBudget, &reason);
  ASSERT_TRUE(tight) << reason;
  EXPECT_EQ(tight->slices, 1u);
  EXPECT_EQ(double(tight->device_bytes), double(plan->device_bytes) - padding_bytes);
  for (const detail::FactoredStage& stage : tight->stages) EXPECT_EQ(stage.output_size, stage.output_entries);
  // 21 cells would span 24 doubles (a seventh more): unpadded; the host's lines layout never pads.
  const auto coarse = detail::plan_factored_sweep(from_yaml(traffic_yaml(0.4, 2)), kUnlimitedBudget, kUnlimitedBudget,
                                                  &reason);
  ASSERT_TRUE(coarse) << reason;
  for (const detail::FactoredStage& stage : coarse->stages) EXPECT_EQ(stage.output_size, stage.output_entries);
  const auto lines = detail::plan_factored_sweep(padded, kUnlimitedBudget, kUnlimitedBudget, &reason,
                                                 detail::FactoredLayout::Lines);
  ASSERT_TRUE(lines) << reason;
  for (const detail::FactoredStage& stage : lines->stages) EXPECT_EQ(stage.output_size, stage.output_entries);
}

TEST(FactoredPlan, DynamicsWithoutDependenciesAreRefusedWithTheReason) {
  using namespace test_support;
  const Abstraction a = random_affine_abstraction(3, 2, 1, false, safety_spec(2));
  std::string reason;
  EXPECT_FALSE(detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason));
  EXPECT_NE(reason.find("do not say which components"), std::string::npos) << reason;
}

TEST(FactoredPlan, MultiplicativeNoiseReadsTheCoordinateItScales) {
  const Abstraction a = from_yaml(multiplicative_yaml());
  std::string reason;
  const auto plan = detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason);
  ASSERT_TRUE(plan) << reason;
  EXPECT_EQ(plan->reads[1], (std::vector<std::size_t>{0, 1, 3}));  // x0, u0 by f; x1 by the scale
  EXPECT_EQ(plan->reads[2], (std::vector<std::size_t>{2}));
}

TEST(FactoredPlan, MassTablesAreTheNoiseModelsKeptMasses) {
  const Abstraction a = from_yaml(robot_disturbance_yaml());
  std::string reason;
  const auto plan = detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason);
  ASSERT_TRUE(plan) << reason;
  const auto tables = detail::factored_mass_tables(a, *plan);
  // Every (x, u, w) triple: each dimension's row at its tuple equals the window masses.
  std::vector<double> post(2);
  std::vector<std::int64_t> first(2), last(2);
  std::size_t checked = 0;
  for (std::size_t x = 0; x < a.states.size(); x += 7)
    for (std::size_t u = 0; u < a.inputs.size(); u += 3)
      for (std::size_t w = 0; w < a.disturbances.size(); ++w) {
        const auto xs = a.states.point(x), us = a.inputs.point(u), ws = a.disturbances.point(w);
        a.dynamics->evaluate(xs.data(), us.data(), ws.data(), post.data());
        std::vector<std::size_t> xm(2), um(2), wm(1);
        a.states.multi_index(x, xm.data());
        a.inputs.multi_index(u, um.data());
        a.disturbances.multi_index(w, wm.data());
        const std::size_t digits[] = {xm[0], xm[1], um[0], um[1], wm[0]};
        for (std::size_t dim = 0; dim < 2; ++dim) {
          const detail::MassTable& table = tables[dim];
          std::size_t tuple = 0;
          for (std::size_t v : table.variables) tuple = tuple * plan->variables[v].count + digits[v];
          std::int64_t lo = 0, hi = -1;
          const bool kept = a.noise->dimension_window(a.states, dim, post[dim], &lo, &hi);
          ASSERT_EQ(table.count[tuple], kept ? std::uint32_t(hi - lo + 1) : 0u);
          if (!kept) continue;
          ASSERT_EQ(table.first[tuple], std::uint32_t(lo));
          for (std::int64_t k = lo; k <= hi; ++k) {
            const double expected = a.noise->cell_mass(dim, std::size_t(k), post[dim], a.noise->scale(dim, xs.data()));
            EXPECT_NEAR(table.masses[tuple * table.width + std::size_t(k - lo)], expected, kMassTolerance);
          }
          ++checked;
        }
      }
  EXPECT_GT(checked, 100u);
}

// Agreement of the factored sweep with the reference and the dense sweep: test_engine_matrix.cpp.

// The factored sweep of `a` on pocl in the device's shape (a row of entries per work-item) and
// with one entry per work-item (the GPU's shape).
struct BothShapes {
  SynthesisReport rows_report, entries_report;
  Policy rows, entries;
};
BothShapes run_both_shapes(const Abstraction& a) {
  SynthesisOptions options = cpu_options();
  options.compute.sweep = SweepChoice::Factored;
  BothShapes both;
  both.rows = detail::synthesize_opencl(a, options, &both.rows_report);
  detail::OpenClEngineOptions entries_engine;
  entries_engine.factored_vector_width = 1;
  both.entries = detail::synthesize_opencl(a, options, &both.entries_report, entries_engine);
  return both;
}

TEST(FactoredSweep, GpuShapeOneEntryPerWorkItemIsBitIdenticalToRowsOfVectors) {
  for (const std::string& yaml :
       {traffic_yaml(0.4, 3), robot_disturbance_yaml(), multiplicative_yaml(), test_support::long_rows_yaml()}) {
    const Abstraction a = from_yaml(yaml);
    const BothShapes both = run_both_shapes(a);
    EXPECT_TRUE(has_note(both.rows_report, "a row of entries per work-item"));
    EXPECT_TRUE(has_note(both.entries_report, "one entry per work-item"));
    EXPECT_EQ(both.rows.values, both.entries.values) << a.config.name;
    EXPECT_EQ(both.rows.input_index, both.entries.input_index) << a.config.name;
  }
}

TEST(FactoredSweep, RowsTakenWindowByWindowAreBitIdenticalToOneEntryPerWorkItem) {
  // 54 cells per dimension and windows of 33: in output order the first two stages would read
  // megabytes of values between two visits of a block, so SIMD devices take their rows window by
  // window (the digits that pick only masses fastest).
  const Abstraction a = from_yaml(traffic_yaml(0.15, 2));
  std::string reason;
  const auto plan = detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason);
  ASSERT_TRUE(plan) << reason;
  const detail::StageShape by_window = detail::stage_shape_for(8);
  detail::StageShape in_output_order = by_window;
  in_output_order.rows_in_output_order = true;
  ASSERT_NE(detail::factored_program_source(a, *plan, by_window),
            detail::factored_program_source(a, *plan, in_output_order))
      << "expected the rows of some stage taken window by window";
  const BothShapes both = run_both_shapes(a);
  ASSERT_TRUE(has_note(both.rows_report, "a row of entries per work-item"));
  EXPECT_EQ(both.rows.values, both.entries.values);
  EXPECT_EQ(both.rows.input_index, both.entries.input_index);
}

// A run in slices (a memory fraction that leaves room for a third of the stage tensors) gives the
// unsliced run's inputs and values up to rounding. `padded`: the sliced plan's tensors too.
void expect_sliced_run_equals_unsliced_run(const Abstraction& a, bool padded) {
  SynthesisReport whole_report, sliced_report;
  const Policy whole = run(a, SweepChoice::Factored, &whole_report);
  std::string reason;
  const auto plan = detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason);
  ASSERT_TRUE(plan) << reason;
  const double sliced_budget = double(plan->device_bytes) * 0.6;
  const auto sliced_plan = detail::plan_factored_sweep(a, sliced_budget, kUnlimitedBudget, &reason);
  ASSERT_TRUE(sliced_plan) << reason;
  const auto stage_padded = [](const detail::FactoredStage& stage) { return stage.output_size > stage.output_entries; };
  const bool sliced_plan_padded = std::any_of(sliced_plan->stages.begin(), sliced_plan->stages.end(), stage_padded);
  EXPECT_EQ(sliced_plan_padded, padded);
  std::vector<EngineNote> notes;
  const double global_memory = double(detail::choose_device(cpu_options().compute, notes).global_memory);
  ASSERT_GT(global_memory, 0.0);
  const Policy sliced = run(a, SweepChoice::Factored, &sliced_report, sliced_budget / global_memory);
  EXPECT_TRUE(has_note(sliced_report, "slices")) << "expected a sliced plan";
  EXPECT_LE(max_difference(whole.values, sliced.values), kValueTolerance);
  EXPECT_EQ(whole.input_index, sliced.input_index);
}

TEST(FactoredSweep, SlicedRunEqualsUnslicedRun) {
  // Unpadded tensors (21 cells), and x'0's tensor padded to whole cache lines (15 cells in 16
  // doubles; x'1's ends with a slice of x'2's cells, too few to pad).
  expect_sliced_run_equals_unsliced_run(from_yaml(traffic_yaml(0.4, 3)), false);
  expect_sliced_run_equals_unsliced_run(from_yaml(padded_traffic_yaml(3)), true);
}

TEST(FactoredSweep, AutoChoosesFactoredWhereItSavesWorkAndDenseOtherwise) {
  SynthesisReport traffic_report, lambda_report;
  run(from_yaml(traffic_yaml(0.4, 1)), SweepChoice::Auto, &traffic_report);
  EXPECT_TRUE(has_note(traffic_report, "factored sweep: eliminates"));
  using namespace test_support;
  run(random_affine_abstraction(5, 2, 1, false, safety_spec(2)), SweepChoice::Auto, &lambda_report);
  EXPECT_TRUE(has_note(lambda_report, "dense sweep"));
  EXPECT_TRUE(has_note(lambda_report, "do not say which components"));
}

TEST(FactoredSweep, ReportsPhasesStagesAndProgress) {
  const Abstraction a = from_yaml(traffic_yaml(0.4, 2));
  SynthesisOptions options = cpu_options();
  options.profile = true;
  std::vector<Phase> seen;
  options.progress = [&](const Progress& progress) {
    seen.push_back(progress.phase);
    return true;
  };
  options.compute.sweep = SweepChoice::Factored;
  SynthesisReport report;
  detail::synthesize_opencl(a, options, &report);
  std::vector<std::string> names;
  double stage_multiply_adds = 0, step_multiply_adds = 0;
  for (const auto& phase : report.phases) {
    names.push_back(phase.name);
    if (phase.name.rfind("stage", 0) == 0) stage_multiply_adds += phase.multiply_adds;
    if (phase.name.rfind("step", 0) == 0) step_multiply_adds += phase.multiply_adds;
  }
  // Stage 0, then stages 1 and 2 in one launch (x'2 contracts x'0's lines of rows), the choice.
  ASSERT_GE(names.size(), 8u);
  EXPECT_EQ(std::vector<std::string>(names.begin(), names.begin() + 5),
            (std::vector<std::string>{"device setup", "kernel build", "construction", "step 1", "step 0"}));
  EXPECT_EQ(names[5].rfind("stage 0 (x'", 0), 0u) << names[5];
  EXPECT_EQ(names[6], "stages 1+2 (x'0 + x'2 fused, all steps)");
  // The stages' multiply-adds over all steps are the steps' multiply-adds.
  EXPECT_GT(step_multiply_adds, 0);
  EXPECT_NEAR(stage_multiply_adds, step_multiply_adds, 1e-9 * step_multiply_adds);
  EXPECT_EQ(seen, (std::vector<Phase>{Phase::Setup, Phase::Construction, Phase::Synthesis, Phase::Done}));
}

}  // namespace
}  // namespace amytiss
