// The product bound over whole tables (bounds/product/whole_tables.hpp): one O-maximisation over a line of
// known order gives robust_expectation()'s result bit for bit (the masked visit and the full scan,
// ties, the leave and cut outcomes), and so do several lines at once; sort_line() is the stable
// sort; the sweep gives
// product_expectation()'s row by row, its estimate for the input choice is never below it, and
// sweeps that share buffers give what each gives alone; rows that share a mean box through what
// the map reads get the bounds they would compute themselves.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "amytiss/enclosure.hpp"
#include "bounds/mean_box.hpp"
#include "bounds/product/whole_tables.hpp"
#include "bounds/row_bounds.hpp"
#include "random_rows.hpp"
#include "test_support.hpp"

namespace amytiss::detail {
namespace {

using namespace amytiss::test_support;
using namespace amytiss::test_rows;

constexpr unsigned kSeed = 20261202;
constexpr int kRandomRows = 4000;

// The line's filling order for `bound` (stable) and its inverse.
void order_of(const std::vector<double>& line, Bound bound, std::vector<std::uint32_t>& order,
              std::vector<std::uint32_t>& rank) {
  const double sign = bound == Bound::Lower ? 1.0 : -1.0;
  order.resize(line.size());
  rank.resize(line.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return sign * line[a] < sign * line[b]; });
  for (std::size_t r = 0; r < order.size(); ++r) rank[order[r]] = std::uint32_t(r);
}

TEST(ProductSweep, OrderedExpectationIsTheSortedOneBitForBit) {
  std::mt19937 random(kSeed);
  // 41: one mask word; 200: several words; 300: the full scan.
  for (std::size_t length : {std::size_t(1), std::size_t(41), std::size_t(200), std::size_t(300)}) {
    for (int trial = 0; trial < kRandomRows; ++trial) {
      const std::vector<double> line = random_line(random, length);
      RandomRow row = random_row(random, length);
      row.window.cells = row.cells.data();
      for (Bound bound : {Bound::Lower, Bound::Upper}) {
        std::vector<std::uint32_t> order, rank;
        order_of(line, bound, order, rank);
        EXPECT_EQ(ordered_expectation(line.data(), order.data(), rank.data(), length, row.window,
                                      window_sums(row.window), bound),
                  sorted_expectation(line, row, bound))
            << "length " << length << " trial " << trial;
      }
    }
  }
}

TEST(ProductSweep, LinesAtOnceGiveEachLineItsOwnBitForBit) {
  std::mt19937 random(kSeed);
  // 41 and 64: batches of short lines; 65 and 200: one line at a time.
  for (std::size_t length : {std::size_t(1), std::size_t(41), std::size_t(64), std::size_t(65), std::size_t(200)}) {
    for (std::size_t line_count = 1; line_count <= 9; ++line_count) {
      for (int trial = 0; trial < kRandomRows / 40; ++trial) {
        RandomRow row = random_row(random, length);
        row.window.cells = row.cells.data();
        std::vector<double> lines;
        for (std::size_t k = 0; k < line_count; ++k) {
          const std::vector<double> line = random_line(random, length);
          lines.insert(lines.end(), line.begin(), line.end());
        }
        for (Bound bound : {Bound::Lower, Bound::Upper}) {
          std::vector<std::uint32_t> orders, ranks;
          for (std::size_t k = 0; k < line_count; ++k) {
            std::vector<std::uint32_t> order, rank;
            order_of(std::vector<double>(lines.begin() + std::ptrdiff_t(k * length),
                                         lines.begin() + std::ptrdiff_t((k + 1) * length)),
                     bound, order, rank);
            orders.insert(orders.end(), order.begin(), order.end());
            ranks.insert(ranks.end(), rank.begin(), rank.end());
          }
          const WindowSums sums = window_sums(row.window);
          std::vector<double> together(line_count);
          ordered_expectations(lines.data(), orders.data(), ranks.data(), length, line_count, row.window, sums, bound,
                               together.data());
          for (std::size_t k = 0; k < line_count; ++k)
            ASSERT_EQ(together[k], ordered_expectation(lines.data() + k * length, orders.data() + k * length,
                                                       ranks.data() + k * length, length, row.window, sums, bound))
                << "length " << length << " lines " << line_count << " line " << k << " trial " << trial;
        }
      }
    }
  }
}

TEST(ProductSweep, SortLineIsTheStableSort) {
  std::mt19937 random(kSeed);
  // 5: one run of insertion; 21 to 256: runs merged; 300: std::stable_sort.
  for (std::size_t length : {std::size_t(1), std::size_t(5), std::size_t(21), std::size_t(41), std::size_t(128),
                             std::size_t(200), std::size_t(256), std::size_t(300)}) {
    for (int trial = 0; trial < kRandomRows / 40; ++trial) {
      const std::vector<double> line = random_line(random, length);
      for (Bound bound : {Bound::Lower, Bound::Upper}) {
        std::vector<std::uint32_t> order, rank, sorted_order(length), sorted_rank(length);
        order_of(line, bound, order, rank);
        sort_line(line.data(), length, bound, sorted_order.data(), sorted_rank.data());
        ASSERT_EQ(sorted_order, order) << "length " << length << " trial " << trial;
        ASSERT_EQ(sorted_rank, rank) << "length " << length << " trial " << trial;
      }
    }
  }
}

std::string system_3d_yaml(const std::string& integrator = "") {
  return "name: sweep_3d\n" + integrator +
         "states: {lb: [-2, -2, -1], ub: [2, 2, 1], eta: [0.25, 0.25, 0.25]}\n"
         "inputs: {lb: [-0.5], ub: [0.5], eta: [0.25]}\n"
         "disturbances: {lb: [-0.1], ub: [0.1], eta: [0.2]}\n"
         "dynamics: [\"x0 + 0.5*x1\", \"0.9*x1 + 0.2*sin(x0) + u0 + w0\", \"0.8*x2 + 0.1*x0*x1\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.04, 0.04, 0.02],\n"
         "        truncation: cutting_probability, cutting_probability: 1.0e-4}\n"
         "spec: {type: safety, horizon: 2}\n"
         "guarantee: system\n";
}

RowBounds bounds_of(const Abstraction& a, const ImageEnclosure& enclosure,
                    const std::vector<std::vector<std::size_t>>& reads) {
  const std::vector<bool> needed(a.states.size(), true);
  return RowBounds(a.states, a.inputs, a.disturbances, *a.noise,
                   enclosure_mean_box(enclosure, a.states, a.inputs, a.disturbances), needed, 2, reads);
}

// Values on a few levels, and values that are 0 but on the grid's first slice along dimension 0
// (rows whose windows miss it see only zeros: the estimate's exact 0).
std::vector<std::vector<double>> test_values(const Grid& states) {
  std::mt19937 random(kSeed);
  std::vector<double> sparse(states.size(), 0.0);
  std::fill(sparse.begin(), sparse.begin() + std::ptrdiff_t(states.size() / states.count(0)), 1.0);
  return {random_line(random, states.size()), sparse};
}

TEST(ProductSweep, SweepGivesTheRowByRowProductBound) {
  const Abstraction a = from_yaml(system_3d_yaml());
  const ImageEnclosure enclosure(a.config);
  const RowBounds rows = bounds_of(a, enclosure, bounds_reads(a));
  std::vector<DimensionView> views(a.states.dims());
  std::size_t zero_estimates = 0;
  for (const std::vector<double>& values : test_values(a.states)) {
    for (Bound bound : {Bound::Lower, Bound::Upper}) {
      ProductSweep sweep(a.states, rows, bound, 2);
      sweep.prepare(values.data());
      ProductScratch scratch;
      for (std::size_t row = 0; row < a.triples(); ++row) {
        rows.dimensions(row, views.data());
        const double expectation = sweep.expectation(row);
        ASSERT_EQ(expectation, product_expectation(a.states, views.data(), values.data(), bound, scratch))
            << "row " << row;
        // What the input choice skips by: never below the row's bound.
        ASSERT_GE(sweep.upper_estimate(row), expectation) << "row " << row;
        zero_estimates += sweep.upper_estimate(row) == 0.0;
      }
    }
  }
  EXPECT_GT(zero_estimates, 0u) << "no window of zeros: the sparse values do not test the exact 0";
}

TEST(ProductSweep, SweepsSharingBuffersGiveWhatEachGivesAlone) {
  const Abstraction a = from_yaml(system_3d_yaml());
  const ImageEnclosure enclosure(a.config);
  const RowBounds rows = bounds_of(a, enclosure, bounds_reads(a));
  const auto buffers = std::make_shared<SweepBuffers>();
  ProductSweep lower(a.states, rows, Bound::Lower, 2, buffers), upper(a.states, rows, Bound::Upper, 2, buffers);
  ProductSweep lower_alone(a.states, rows, Bound::Lower, 2), upper_alone(a.states, rows, Bound::Upper, 2);
  // As the backward driver runs them: one bound's prepare() and rows, then the other's.
  for (const std::vector<double>& values : test_values(a.states)) {
    for (auto [shared, alone] : {std::pair{&lower, &lower_alone}, std::pair{&upper, &upper_alone}}) {
      shared->prepare(values.data());
      alone->prepare(values.data());
      for (std::size_t row = 0; row < a.triples(); ++row) {
        ASSERT_EQ(shared->expectation(row), alone->expectation(row)) << "row " << row;
        ASSERT_EQ(shared->upper_estimate(row), alone->upper_estimate(row)) << "row " << row;
      }
    }
  }
}

void expect_shared_bounds_are_own(const std::string& yaml,
                                  const std::vector<std::vector<std::size_t>>& expected_reads) {
  const Abstraction a = from_yaml(yaml);
  const ImageEnclosure enclosure(a.config);
  const std::vector<std::vector<std::size_t>> reads = bounds_reads(a);
  ASSERT_EQ(reads, expected_reads);
  const RowBounds shared = bounds_of(a, enclosure, reads), own = bounds_of(a, enclosure, {});
  std::vector<DimensionView> mine(a.states.dims()), theirs(a.states.dims());
  for (std::size_t row = 0; row < a.triples(); ++row) {
    shared.dimensions(row, mine.data());
    own.dimensions(row, theirs.data());
    for (std::size_t d = 0; d < a.states.dims(); ++d) {
      ASSERT_EQ(mine[d].first, theirs[d].first) << "row " << row << " dimension " << d;
      ASSERT_EQ(mine[d].count, theirs[d].count) << "row " << row << " dimension " << d;
      for (std::size_t k = 0; k < mine[d].count; ++k) {
        ASSERT_EQ(mine[d].cells[k].lo, theirs[d].cells[k].lo) << "row " << row << " dimension " << d;
        ASSERT_EQ(mine[d].cells[k].hi, theirs[d].cells[k].hi) << "row " << row << " dimension " << d;
      }
      ASSERT_EQ(mine[d].leave.lo, theirs[d].leave.lo);
      ASSERT_EQ(mine[d].leave.hi, theirs[d].leave.hi);
      ASSERT_EQ(mine[d].cut.lo, theirs[d].cut.lo);
      ASSERT_EQ(mine[d].cut.hi, theirs[d].cut.hi);
    }
  }
}

TEST(ProductSweep, SharedMeanBoxesGiveEveryRowItsOwnBounds) {
  // The map itself: x2 is read by no other coordinate.
  expect_shared_bounds_are_own(system_3d_yaml(), {{0, 1}, {0, 1}, {0, 1, 2}});
  // The same expressions as a vector field under RK4: coordinates read the closure.
  expect_shared_bounds_are_own(system_3d_yaml("integrator: {method: rk4, substeps: 2, tau: 0.1}\n"),
                               {{0, 1}, {0, 1}, {0, 1, 2}});
}

}  // namespace
}  // namespace amytiss::detail
