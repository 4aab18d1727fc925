// The factored sweep's row kernels for SIMD devices (src/core/opencl/factored/row_kernel.*,
// fused_stage.*): which digits a work-item takes two or a line at a time, which stages fuse, that
// the kernels of every register budget, streamed or fused, give the bits of one entry per
// work-item on pocl, and the work the profile counts for them.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "execute.hpp"
#include "factored/factored_plan.hpp"
#include "opencl/engine_options.hpp"
#include "opencl/factored/device_parts.hpp"
#include "opencl/factored/fused_stage.hpp"
#include "opencl/factored/program.hpp"
#include "opencl/factored/row_kernel.hpp"
#include "opencl/factored/tables.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using test_support::from_yaml;
using test_support::traffic_yaml;

constexpr double kUnlimitedBudget = 1e12;
// Sums of up to millions of whole numbers in double, in different orders.
constexpr double kCountTolerance = 1e-12;

detail::FactoredPlan traffic_plan(double eta) {
  const Abstraction a = from_yaml(traffic_yaml(eta, 2));
  std::string reason;
  const auto plan = detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason);
  EXPECT_TRUE(plan) << reason;
  return *plan;
}

const detail::FactoredStage& stage_of(const detail::FactoredPlan& plan, std::size_t dimension) {
  for (const detail::FactoredStage& stage : plan.stages)
    if (stage.dimension == dimension) return stage;
  ADD_FAILURE() << "no stage contracts x'" << dimension;
  return plan.stages.front();
}

// The variable (plan.variables index) of an output digit.
std::size_t variable_of(const detail::FactoredStage& stage, std::size_t digit) {
  EXPECT_FALSE(stage.output[digit].post);
  return stage.output[digit].id;
}

TEST(RowKernel, PairsTheFinestDigitThatPicksOnlyMassesAndTilesTheFastestDigit) {
  // Traffic: x'0 = 0.64 x0 + 0.36 x2 + 6 u0. Its stage's output ends with x'2 (the vector digit)
  // then x0 (the next stage's vector digit): rows lie a line apart, so x0 is tiled. Of the
  // digits that pick only masses, x2 (21 values) is paired, not u0 (2 values).
  const detail::FactoredPlan plan = traffic_plan(0.4);
  const detail::StageShape cpu = detail::stage_shape_for(8);
  const detail::FactoredStage& x0 = stage_of(plan, 0);
  const auto paired = detail::paired_digit(x0, cpu);
  const auto tiled = detail::tiled_digit(x0, cpu);
  ASSERT_TRUE(paired);
  ASSERT_TRUE(tiled);
  EXPECT_EQ(variable_of(x0, *paired), 2u);
  EXPECT_EQ(*tiled, x0.output.size() - 1);
  EXPECT_EQ(variable_of(x0, *tiled), 0u);
  // Rows of 21 entries, 3 vectors: 4 rows' accumulators fit AVX-512's 24 registers, not AVX2's 6
  // (12 registers of half the width). 21 rows of x2 in 6 groups of up to 4, 21 of x0 in 3 lines
  // of up to 8.
  EXPECT_EQ(detail::rows_per_item(x0, cpu), detail::kMaxRowsPerItem);
  EXPECT_EQ(detail::rows_per_item(x0, detail::stage_shape_for(4)), 2u);
  const std::uint64_t rows = x0.output_entries / x0.output[*x0.vector_digit].radix;
  EXPECT_EQ(detail::row_work_items(x0, cpu), rows / 21 * 6 / 21 * 3);
  EXPECT_EQ(detail::stage_work_items(x0, cpu), detail::row_work_items(x0, cpu));
  // Rows of 81 entries (11 vectors): pairs.
  EXPECT_EQ(detail::rows_per_item(stage_of(traffic_plan(0.1), 0), cpu), 2u);

  // x'2 = 0.64 x2 + 0.36 x1 + 8 u1: its output ends with u1, the only digit that picks only
  // masses, which is paired (its two windows lie 20 cells apart: the kernel takes a pass each)
  // and so not tiled.
  const detail::FactoredStage& x2 = stage_of(plan, 2);
  ASSERT_TRUE(detail::paired_digit(x2, cpu));
  EXPECT_EQ(*detail::paired_digit(x2, cpu), x2.output.size() - 1);
  EXPECT_FALSE(detail::tiled_digit(x2, cpu));

  // A team splits rows by the digits before the vector digit: x'0's x2 lies before it.
  detail::StageShape team = cpu;
  team.split_by_team = true;
  const auto team_paired = detail::paired_digit(x0, team);
  EXPECT_TRUE(!team_paired || *team_paired > *x0.vector_digit);
  // The SIMT shape takes one entry per work-item, or two along the same paired digit: no rows.
  const detail::StageShape simt = detail::stage_shape_for(1);
  EXPECT_EQ(detail::paired_digit(x0, simt), paired);
  EXPECT_EQ(detail::stage_work_items(x0, simt), x0.output_entries / 21 * 11);
}

TEST(RowKernel, SmallerRegisterBudgetsTakeARowInMorePasses) {
  const detail::FactoredPlan plan = traffic_plan(0.15);  // rows of 54: 7 vectors of 8
  const Abstraction a = from_yaml(traffic_yaml(0.15, 2));
  // AVX-512 (32 registers): a pair's 14 accumulators in one pass; AVX2 (16): 3 vectors per row.
  const std::string wide = detail::factored_program_source(a, plan, detail::stage_shape_for(8));
  const std::string narrow = detail::factored_program_source(a, plan, detail::stage_shape_for(4));
  EXPECT_NE(wide.find("sum_b6 = fma"), std::string::npos);
  EXPECT_EQ(narrow.find("sum_b6 = fma"), std::string::npos);
  EXPECT_NE(narrow.find("sum_b2 = fma"), std::string::npos);
}

// Multiply-adds, value loads and memory bytes of every stage of `plan`, summed over the stages.
detail::StageWork total_work(const Abstraction& a, const detail::FactoredPlan& plan, const detail::StageShape& shape) {
  const std::vector<detail::MassTable> tables = detail::factored_mass_tables(a, plan);
  detail::StageWork total;
  for (std::size_t k = 0; k < plan.stages.size(); ++k) {
    const detail::StageWork work = detail::stage_work(a, plan, k, tables[plan.stages[k].dimension], shape);
    EXPECT_GT(work.multiply_adds, 0.0);
    EXPECT_LE(work.value_loads, work.multiply_adds);
    EXPECT_GT(work.memory_bytes, 8.0 * double(plan.stages[k].output_size));
    total.multiply_adds += work.multiply_adds;
    total.value_loads += work.value_loads;
  }
  return total;
}

TEST(RowKernel, StageWorkCountsEveryCellOnceWhateverTheSlicesAndPairedRowsLoadOnce) {
  const Abstraction a = from_yaml(traffic_yaml(0.4, 2));
  std::string reason;
  const auto whole = detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason);
  ASSERT_TRUE(whole) << reason;
  const auto sliced = detail::plan_factored_sweep(a, double(whole->device_bytes) * 0.6, kUnlimitedBudget, &reason);
  ASSERT_TRUE(sliced) << reason;
  ASSERT_GT(sliced->slices, 1u);
  // A slice's stages contract its share of the tensors, and its last stage only the slice's cells
  // of the last dimension: the multiply-adds of a step do not depend on the slices.
  const detail::StageShape entries = detail::stage_shape_for(1), rows = detail::stage_shape_for(8);
  const detail::StageWork once = total_work(a, *whole, entries), in_slices = total_work(a, *sliced, entries);
  EXPECT_NEAR(in_slices.multiply_adds, once.multiply_adds, kCountTolerance * once.multiply_adds);
  // Pairs of entries that share a pass load each value once for both (x'0's x2 and x'1's x1
  // neighbours: windows a fraction of a cell apart); groups of 4 rows load less again; a team
  // pairs no digit before the vector digit, so that x'0's x2 neighbours load their values once each.
  EXPECT_LT(once.value_loads, 0.7 * once.multiply_adds);
  EXPECT_GT(once.value_loads, 0.5 * once.multiply_adds);
  const detail::StageWork grouped = total_work(a, *whole, rows);
  EXPECT_NEAR(grouped.multiply_adds, once.multiply_adds, kCountTolerance * once.multiply_adds);
  EXPECT_LT(grouped.value_loads, 0.9 * once.value_loads);
  detail::StageShape team = entries;
  team.split_by_team = true;
  EXPECT_GT(total_work(a, *whole, team).value_loads, once.value_loads);
}

// Policies of the factored sweep on pocl with kernels for vector width `width` (1: one entry per
// work-item); `stream_bytes`: outputs above it stored past the caches (0: every aligned one).
Policy factored_policy(const Abstraction& a, unsigned width, double stream_bytes = detail::kStreamOutputBytes,
                       SynthesisReport* report = nullptr) {
  SynthesisOptions options;
  options.compute.device = DeviceKind::Cpu;
  options.compute.sweep = SweepChoice::Factored;
  detail::OpenClEngineOptions engine;
  engine.factored_vector_width = width;
  engine.factored_stream_bytes = stream_bytes;
  SynthesisReport own_report;
  return detail::synthesize_opencl(a, options, report ? report : &own_report, engine);
}

TEST(RowKernel, EveryRegisterBudgetGivesTheBitsOfOneEntryPerWorkItem) {
  // Traffic on 21 cells: groups sharing a pass (x2 in x'0's stage, x1 in x'1's), pairs a pass
  // each (u1 in x'2's), odd radices (a last group of one row, a last line of 5 rows). Long rows:
  // 101 entries, 13 vectors, the last partial. Room temperature 5-d: rows of 6 in groups of 4,
  // the last of 2 rows, stored without lines of rows (x'4's stage).
  const std::vector<Abstraction> problems = {
      from_yaml(traffic_yaml(0.4, 3)), from_yaml(test_support::long_rows_yaml()),
      Abstraction::from_config(test_support::shipped_abstraction("room_temperature_5d.yaml"))};
  for (const Abstraction& a : problems) {
    const Policy entries = factored_policy(a, 1);
    for (unsigned width : {2u, 4u, 8u}) {
      const Policy rows = factored_policy(a, width);
      EXPECT_EQ(rows.values, entries.values) << a.config.name << ", width " << width;
      EXPECT_EQ(rows.input_index, entries.input_index) << a.config.name << ", width " << width;
    }
  }
}

TEST(RowKernel, OutputsStoredPastTheCachesGiveTheSameBits) {
  // Stage tensors padded to whole lines: traffic on 15 cells (x'1's rows of 15 values in 16
  // doubles, x'0's lines of kept rows along x0, the last line of 7 rows ending in the padding);
  // long rows of 101 values in 104 doubles. Streamed whatever their size (threshold 0).
  for (const std::string& yaml : {traffic_yaml(0.5, 3, 7.0), test_support::long_rows_yaml()}) {
    const Abstraction a = from_yaml(yaml);
    std::string reason;
    const auto plan = detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason);
    ASSERT_TRUE(plan) << reason;
    detail::StageShape streamed = detail::stage_shape_for(8);
    streamed.stream_output_bytes = 0;
    const auto streams = [&](const detail::StageShape& shape) {
      return std::count_if(plan->stages.begin(), plan->stages.end(),
                           [&](const detail::FactoredStage& stage) { return detail::streams_output(stage, shape); });
    };
    EXPECT_EQ(streams(detail::stage_shape_for(8)), 0) << a.config.name << ": too small to stream by default";
    EXPECT_EQ(streams(streamed), a.states.dims() - 1) << a.config.name << ": every stage tensor streams";
    const Policy entries = factored_policy(a, 1);
    for (unsigned width : {4u, 8u}) {
      const Policy rows = factored_policy(a, width, 0.0);
      EXPECT_EQ(rows.values, entries.values) << a.config.name << ", width " << width;
      EXPECT_EQ(rows.input_index, entries.input_index) << a.config.name << ", width " << width;
    }
  }
}

TEST(RowKernel, TheLastStageFusesWithTheStageWhoseLinesOfRowsItContracts) {
  // Traffic: x'2 (the last stage) contracts x'0's vector digit (x'2's post cell) and computes
  // along x0, the digit along which x'0 keeps lines of rows: x'0's work-items contract their
  // lines into Q, and x'0's tensor is never written.
  const Abstraction a = from_yaml(traffic_yaml(0.4, 3));
  std::string reason;
  const auto plan = detail::plan_factored_sweep(a, kUnlimitedBudget, kUnlimitedBudget, &reason);
  ASSERT_TRUE(plan) << reason;
  ASSERT_EQ(plan->stages.size(), 3u);
  ASSERT_EQ(plan->stages[1].dimension, 0u);
  const detail::StageShape cpu = detail::stage_shape_for(8);
  EXPECT_FALSE(detail::fuses_next(*plan, 0, cpu)) << "x'0 does not contract x'1's lines";
  EXPECT_TRUE(detail::fuses_next(*plan, 1, cpu));
  EXPECT_FALSE(detail::fuses_next(*plan, 2, cpu)) << "the last stage has no next";
  EXPECT_FALSE(detail::fuses_next(*plan, 1, detail::stage_shape_for(1))) << "one entry per work-item keeps no lines";
  detail::StageShape team = cpu;
  team.split_by_team = true;
  EXPECT_FALSE(detail::fuses_next(*plan, 1, team)) << "a team splits and exchanges every stage";
  const auto sliced = detail::plan_factored_sweep(a, double(plan->device_bytes) * 0.6, kUnlimitedBudget, &reason);
  ASSERT_TRUE(sliced) << reason;
  ASSERT_GT(sliced->slices, 1u);
  EXPECT_FALSE(detail::fuses_next(*sliced, 1, cpu)) << "slices accumulate into Q stage by stage";
  // The same bits as the stages apart (one entry per work-item), in less device memory.
  SynthesisReport fused_report, apart_report;
  const Policy fused = factored_policy(a, 8, detail::kStreamOutputBytes, &fused_report);
  const Policy apart = factored_policy(a, 1, detail::kStreamOutputBytes, &apart_report);
  EXPECT_TRUE(test_support::has_note(fused_report, "stages 1 and 2 fused"));
  EXPECT_FALSE(test_support::has_note(apart_report, "fused"));
  EXPECT_EQ(fused.values, apart.values);
  EXPECT_EQ(fused.input_index, apart.input_index);
  EXPECT_EQ(apart_report.device_bytes - fused_report.device_bytes, 8 * plan->stages[1].output_size);
}

}  // namespace
}  // namespace amytiss
