// The product bound by variable elimination (bounds/product/elimination.hpp): every (cell, input,
// disturbance) gets product_expectation_in_order() of its row in the plan's order, within rounding,
// with sorted lines and with unsorted ones, with tuples that share a window sharing a search, and
// with a pair of stages run at once (a run of one stage's lines giving whole lines of the next);
// the same bits on any number of workers;
// that oracle is product_expectation() in the order (d-1, ..., 0) and lies within the joint
// interval MDP's bounds in every order; the step takes this way where the sweep over whole tables
// does not pay, and its bounds then stay sound against the joint reference; the profile's breakdown
// gives the stages' seconds.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "amytiss/enclosure.hpp"
#include "amytiss/engine.hpp"
#include "robust_oracle.hpp"
#include "bounds/mean_box.hpp"
#include "bounds/robust_step.hpp"
#include "bounds/product/elimination.hpp"
#include "bounds/cell_roles.hpp"
#include "test_support.hpp"

namespace amytiss::detail {
namespace {

using namespace amytiss::test_support;

constexpr unsigned kSeed = 20261202;
// The product set lies inside the joint one; its bounds may differ from the joint's by rounding.
constexpr double kOrderSlack = 1e-12;
// The sweep's O-maximisations (threshold form) and the oracle's (filling order) are each the exact
// one moved outward by a few 1e-14, stage by stage.
constexpr double kSweepAgreement = 1e-12;

// Three coordinates that each read two or three components (an input and a disturbance among
// them), without truncation: the windows span the grid.
std::string sparse_3d_yaml(unsigned horizon = 2) {
  return "name: sparse_3d\n"
         "states: {lb: [-1, -1, -1], ub: [1, 1, 1], eta: [0.25, 0.5, 0.5]}\n"
         "inputs: {lb: [-0.2], ub: [0.2], eta: [0.2]}\n"
         "disturbances: {lb: [-0.05], ub: [0.05], eta: [0.1]}\n"
         "dynamics: [\"0.9*x0 + 0.05*x2 + u0\", \"0.9*x1 + 0.1*x0 + w0\", \"0.8*x2 + 0.1*x1\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.02, 0.03, 0.05]}\n"
         "spec: {type: safety, horizon: " +
         std::to_string(horizon) + "}\nguarantee: system\n";
}

RowBounds all_rows(const Abstraction& a, const ImageEnclosure& enclosure) {
  return RowBounds(a.states, a.inputs, a.disturbances, *a.noise,
                   enclosure_mean_box(enclosure, a.states, a.inputs, a.disturbances),
                   std::vector<bool>(a.states.size(), true), 2, bounds_reads(a));
}

// Values on a few levels (ties), and values that are 1 on one corner only.
std::vector<std::vector<double>> test_values(std::size_t cells) {
  std::mt19937 random(kSeed);
  std::uniform_int_distribution<int> level(0, 6);
  std::vector<double> levels(cells), corner(cells, 0.0);
  for (double& value : levels) value = level(random) / 6.0;
  std::fill(corner.begin(), corner.begin() + std::ptrdiff_t(cells / 5), 1.0);
  return {levels, corner};
}

TEST(RobustFactored, TheOracleInTheLastDimensionFirstOrderIsTheProductBound) {
  const Abstraction a = from_yaml(sparse_3d_yaml());
  const ImageEnclosure enclosure(a.config);
  const RowBounds rows = all_rows(a, enclosure);
  std::vector<DimensionView> views(a.states.dims());
  const std::vector<std::size_t> last_first{2, 1, 0};
  for (const std::vector<double>& values : test_values(a.states.size()))
    for (Bound bound : {Bound::Lower, Bound::Upper}) {
      ProductScratch scratch;
      for (std::size_t row = 0; row < a.triples(); ++row) {
        rows.dimensions(row, views.data());
        ASSERT_EQ(product_expectation_in_order(a.states, views.data(), values.data(), bound, last_first),
                  product_expectation(a.states, views.data(), values.data(), bound, scratch))
            << "row " << row;
      }
    }
}

TEST(RobustFactored, EveryOrderLiesWithinTheJointBounds) {
  const Abstraction a = from_yaml(sparse_3d_yaml());
  const ImageEnclosure enclosure(a.config);
  const RowBounds rows = all_rows(a, enclosure);
  std::vector<DimensionView> views(a.states.dims());
  std::vector<std::size_t> order{0, 1, 2};
  const std::vector<double> values = test_values(a.states.size()).front();
  do {
    for (std::size_t row = 0; row < a.triples(); row += 7) {
      rows.dimensions(row, views.data());
      const IntervalRow joint = joint_row(a.states, views.data());
      EXPECT_GE(product_expectation_in_order(a.states, views.data(), values.data(), Bound::Lower, order),
                joint_expectation(joint, values.data(), Bound::Lower) - kOrderSlack);
      EXPECT_LE(product_expectation_in_order(a.states, views.data(), values.data(), Bound::Upper, order),
                joint_expectation(joint, values.data(), Bound::Upper) + kOrderSlack);
    }
  } while (std::next_permutation(order.begin(), order.end()));
}

// The sparse 3-d system, every row's bounds and the sweep's plan.
class SparseSweep : public ::testing::Test {
 protected:
  const Abstraction a = from_yaml(sparse_3d_yaml());
  const ImageEnclosure enclosure{a.config};
  const RowBounds rows = all_rows(a, enclosure);
  std::string reason;
  const std::optional<FactoredPlan> plan = RobustFactoredSweep::plan(a, &reason);
};

using LineSearch = RobustFactoredSweep::LineSearch;
constexpr LineSearch kLineSearches[] = {LineSearch::Sorted, LineSearch::Scan, LineSearch::Auto};

// Every row's bound from sweeps with each way of searching lines, against the oracle.
void expect_every_row_in_the_plans_order(const Abstraction& a, const RowBounds& rows, const FactoredPlan& plan) {
  std::vector<DimensionView> views(a.states.dims());
  // The upper bound's sweep reuses the tensors the lower bound's left behind.
  const auto buffers = std::make_shared<SweepBuffers>();
  for (LineSearch search : kLineSearches)
    for (Bound bound : {Bound::Lower, Bound::Upper}) {
      RobustFactoredSweep sweep(a, rows, std::vector<bool>(a.states.size(), true), plan, bound, 2, buffers, search);
      for (const std::vector<double>& values : test_values(a.states.size())) {
        sweep.prepare(values.data());
        for (std::size_t cell = 0; cell < a.states.size(); ++cell)
          for (std::size_t input = 0; input < a.inputs.size(); ++input)
            for (std::size_t w = 0; w < a.disturbances.size(); ++w) {
              rows.dimensions(rows.row(cell, input, w), views.data());
              ASSERT_NEAR(sweep.expectation(cell, input, w),
                          product_expectation_in_order(a.states, views.data(), values.data(), bound, sweep.order()),
                          kSweepAgreement)
                  << "search " << int(search) << " cell " << cell << " input " << input << " disturbance " << w;
            }
      }
    }
}

TEST_F(SparseSweep, GivesEveryRowItsBoundInThePlansOrder) {
  ASSERT_TRUE(plan) << reason;
  expect_every_row_in_the_plans_order(a, rows, *plan);
}

TEST_F(SparseSweep, GivesTheSameBitsOnAnyNumberOfWorkers) {
  ASSERT_TRUE(plan) << reason;
  const std::vector<double> values = test_values(a.states.size()).front();
  for (LineSearch search : kLineSearches)
    for (Bound bound : {Bound::Lower, Bound::Upper}) {
      RobustFactoredSweep one(a, rows, std::vector<bool>(a.states.size(), true), *plan, bound, 1, nullptr, search);
      RobustFactoredSweep three(a, rows, std::vector<bool>(a.states.size(), true), *plan, bound, 3, nullptr, search);
      one.prepare(values.data());
      three.prepare(values.data());
      for (std::size_t cell = 0; cell < a.states.size(); ++cell)
        for (std::size_t input = 0; input < a.inputs.size(); ++input)
          for (std::size_t w = 0; w < a.disturbances.size(); ++w)
            ASSERT_EQ(one.expectation(cell, input, w), three.expectation(cell, input, w))
                << "search " << int(search) << " cell " << cell << " input " << input << " disturbance " << w;
    }
}

// The 3-d traffic network's shape on 17^3 cells of 0.1: x'1 reads x0 and x1 with commensurate
// coefficients, so that cells i, j of x0, x1 with one 2 i + j share a mean in exact arithmetic
// (not in floating point: 0.1 has no exact binary form); the input moves x'0's mean by 6 cells.
std::string shared_windows_yaml() {
  return "name: shared_windows\n"
         "states: {lb: [0, 0, 0], ub: [1.6, 1.6, 1.6], eta: [0.1, 0.1, 0.1]}\n"
         "inputs: {lb: [0], ub: [1], eta: [1]}\n"
         "dynamics: [\"0.64*x0 + 0.36*x2 + 0.6*u0\", \"0.36*x0 + 0.18*x1 + 0.5\", \"0.64*x2 + 0.36*x1\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.04, 0.04, 0.04],\n"
         "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"
         "spec: {type: safety, horizon: 2}\nguarantee: system\n";
}

TEST(RobustFactored, TuplesThatShareAWindowShareASearch) {
  const Abstraction a = from_yaml(shared_windows_yaml());
  const ImageEnclosure enclosure(a.config);
  const RowBounds rows = all_rows(a, enclosure);
  std::string reason;
  const std::optional<FactoredPlan> plan = RobustFactoredSweep::plan(a, &reason);
  ASSERT_TRUE(plan) << reason;
  ASSERT_EQ(plan->order.front(), 1u) << "the cheapest order eliminates x'1 first, as in the traffic network";
  const RobustFactoredSweep sweep(a, rows, std::vector<bool>(a.states.size(), true), *plan, Bound::Lower, 2);
  // 17 x 17 tuples, 49 values of 2 i + j (91 distinct boxes without their rounding to a binary
  // grid); a mean next to a point of that grid might split from its class.
  constexpr std::size_t kMeans = 2 * 16 + 16 + 1, kSplitAtMost = 2;
  EXPECT_GE(sweep.searches_per_line(0), kMeans);
  EXPECT_LE(sweep.searches_per_line(0), kMeans + kSplitAtMost);
  // As in the traffic network, a stage contracts the fastest digit of the stage before's lines:
  // the pair runs at once, its results checked against the oracle below.
  EXPECT_TRUE(sweep.fused_with_next(0) || sweep.fused_with_next(1));
  expect_every_row_in_the_plans_order(a, rows, *plan);
}

// The plan alone says which stages run as a pair (what the memory estimate counts), as the sweep
// pairs them; the mean boxes of a cell per combination of what each dimension reads count the
// distinct bounds that the row bounds store for every cell (and at least those for some).
TEST(RobustFactored, ThePlanAndTheMeanBoxesGiveTheSweepsRunsAndTheDistinctBounds) {
  const Abstraction a = from_yaml(shared_windows_yaml());
  const ImageEnclosure enclosure(a.config);
  std::string reason;
  const std::optional<FactoredPlan> plan = RobustFactoredSweep::plan(a, &reason);
  ASSERT_TRUE(plan) << reason;
  std::vector<bool> some(a.states.size());
  for (std::size_t cell = 0; cell < some.size(); cell += 3) some[cell] = true;
  for (const std::vector<bool>& needed : {std::vector<bool>(a.states.size(), true), some}) {
    const MeanBox mean_box = enclosure_mean_box(enclosure, a.states, a.inputs, a.disturbances);
    const RowBounds rows(a.states, a.inputs, a.disturbances, *a.noise, mean_box, needed, 2, bounds_reads(a));
    const RobustFactoredSweep sweep(a, rows, needed, *plan, Bound::Lower, 2);
    const auto runs = RobustFactoredSweep::stage_runs(*plan, a.states.counts());
    ASSERT_EQ(runs.size(), sweep.runs().size());
    for (std::size_t r = 0; r < runs.size(); ++r) {
      EXPECT_EQ(runs[r].first, sweep.runs()[r].first);
      EXPECT_EQ(runs[r].last, sweep.runs()[r].last);
    }
    const auto counted = count_distinct_bounds(a, mean_box, 2, std::size_t(1) << 20);
    ASSERT_TRUE(counted);
    for (std::size_t d = 0; d < a.states.dims(); ++d) {
      if (needed == some)
        EXPECT_GE((*counted)[d], rows.distinct_bounds(d)) << d;
      else
        EXPECT_EQ((*counted)[d], rows.distinct_bounds(d)) << d;
    }
    EXPECT_FALSE(count_distinct_bounds(a, mean_box, 2, 1));  // past its budget
  }
}

// Long lines and narrow windows: the sweep over whole tables does not pay, variable elimination
// does; a reach-avoid specification with a disturbance.
std::string narrow_2d_yaml() {
  return "name: narrow_2d\n"
         "states: {lb: [-3, -3], ub: [3, 3], eta: [0.1, 0.1]}\n"
         "inputs: {lb: [-0.4], ub: [0.4], eta: [0.4]}\n"
         "disturbances: {lb: [-0.05], ub: [0.05], eta: [0.1]}\n"
         "dynamics: [\"0.95*x0 + 0.1*x1\", \"0.9*x1 + u0 + w0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.01, 0.01],\n"
         "        truncation: cutting_probability, cutting_probability: 1.0e-4}\n"
         "spec: {type: reach_avoid, horizon: 3, target: {lb: [-0.5, -0.5], ub: [0.5, 0.5]},\n"
         "       avoid: {lb: [2.1, -3], ub: [3, 3]}}\n"
         "guarantee: system\n";
}

TEST(RobustFactored, StepTakesVariableEliminationAndStaysWithinTheJointBounds) {
  const Abstraction a = from_yaml(narrow_2d_yaml());
  const ImageEnclosure enclosure(a.config);
  const RowBounds rows = all_rows(a, enclosure);
  RobustStep step(a, rows, robust_cell_roles(a.states, a.config.spec, Bound::Lower), Bound::Lower,
                  choose_bounds_method(a, rows, BoundsMethod::Auto), 2);
  EXPECT_EQ(step.bounds_method(), BoundsMethod::Elimination) << step.method();
  // x'0 is counted fastest by x'1's lines: the two run as a pair, and the note says so.
  EXPECT_NE(step.method().find("x'1 and x'0 as a pair"), std::string::npos) << step.method();
  SynthesisOptions product, joint;
  joint.compute.bounds_method = BoundsMethod::Joint;
  SynthesisReport report;
  const Policy factored = synthesize(a, product, &report);
  // The profile's breakdown: the pair's seconds, within the steps' (both bounds).
  double step_seconds = 0, pair_seconds = -1;
  for (const PhaseReport& phase : report.phases) {
    if (phase.kind == PhaseKind::Step) step_seconds += phase.seconds;
    if (phase.is_breakdown() && phase.name == "stages 0-1 (x'1 x'0, all steps)") pair_seconds = phase.seconds;
  }
  EXPECT_GT(pair_seconds, 0.0) << "a breakdown phase for the pair";
  EXPECT_LE(pair_seconds, step_seconds);
  const Policy reference = synthesize(a, joint, nullptr);
  for (std::size_t x = 0; x < a.states.size(); ++x) {
    EXPECT_GE(factored.value(0, x), reference.value(0, x) - kOrderSlack) << "cell " << x;
    EXPECT_LE(factored.upper_value(0, x), reference.upper_value(0, x) + kOrderSlack) << "cell " << x;
    EXPECT_LE(factored.value(0, x), factored.upper_value(0, x) + kOrderSlack) << "cell " << x;
  }
}

TEST(RobustFactored, UnboundedBoundsByVariableEliminationAreSoundAroundTheBoundedOnes) {
  // Interval iteration and the certification of its controller run the same step: reaching
  // within 3 steps is no more likely than ever reaching.
  std::string unbounded = narrow_2d_yaml();
  unbounded.replace(unbounded.find("horizon: 3"), 10, "horizon: infinite, tolerance: 1.0e-4");
  const Policy stationary = synthesize(from_yaml(unbounded), SynthesisOptions{}, nullptr);
  const Policy bounded = synthesize(from_yaml(narrow_2d_yaml()), SynthesisOptions{}, nullptr);
  ASSERT_TRUE(stationary.stationary);
  EXPECT_GT(stationary.iterations, 0u);
  bool reaches = false;
  for (std::size_t x = 0; x < stationary.states.size(); ++x) {
    EXPECT_LE(stationary.value(0, x), stationary.upper_value(0, x) + kOrderSlack) << "cell " << x;
    EXPECT_LE(bounded.value(0, x), stationary.upper_value(0, x) + kOrderSlack) << "cell " << x;
    reaches = reaches || (stationary.roles[x] == CellRole::Free && stationary.value(0, x) > 0.5);
  }
  EXPECT_TRUE(reaches) << "no free cell with a certified chance above one half: the test checks nothing";
  EXPECT_EQ(stationary.converged, stationary.gap <= 1.0e-4);
}

}  // namespace
}  // namespace amytiss::detail
