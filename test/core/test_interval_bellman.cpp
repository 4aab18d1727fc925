// The robust Bellman step (bounds/omax/robust_expectation.hpp): the O-maximisation against a hand-worked row
// and against enumeration of the vertices of random rows; joint rows as rounded products; the
// product (orthogonal) bound against the joint one on random per-dimension bounds.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

#include "bounds/omax/robust_expectation.hpp"
#include "test_support.hpp"

namespace amytiss::detail {
namespace {

using namespace amytiss::test_support;

// The vertex enumeration's own rounding (sums of at most 6 terms).
constexpr double kEnumerationRounding = 1e-15;
// The orthogonal bound may fall below the joint one by accumulated outward rounding only.
constexpr double kOrthogonalSlack = 1e-12;

double optimum(const std::vector<double>& lo, const std::vector<double>& hi, const std::vector<double>& values,
               Bound bound) {
  std::vector<OutcomeSlack> order;
  return robust_expectation(lo.data(), hi.data(), values.data(), lo.size(), bound, order);
}

TEST(IntervalBellman, HandWorkedRow) {
  const std::vector<double> lo = {0.1, 0.2, 0.3}, hi = {0.5, 0.6, 0.4}, values = {1.0, 0.5, 0.0};
  const double rounding = robust_expectation_rounding(3);
  // Lower: budget 0.4 goes to value 0 (0.1 fits), then value 0.5 (0.3): p = (0.1, 0.5, 0.4) -> 0.35.
  const double lower = optimum(lo, hi, values, Bound::Lower);
  EXPECT_LE(lower, 0.35);
  EXPECT_GE(lower, 0.35 - 2 * rounding);
  // Upper: all 0.4 to value 1: p = (0.5, 0.2, 0.3) -> 0.6.
  const double upper = optimum(lo, hi, values, Bound::Upper);
  EXPECT_GE(upper, 0.6);
  EXPECT_LE(upper, 0.6 + 2 * rounding);
}

// The optimum of a linear function over {lo <= p <= hi, sum p = 1} is at a vertex: all but one
// coordinate at a bound, the last one taking the rest.
double vertex_optimum(const std::vector<double>& lo, const std::vector<double>& hi, const std::vector<double>& values,
                      Bound bound) {
  const std::size_t n = lo.size();
  double best = bound == Bound::Lower ? std::numeric_limits<double>::infinity() : -1.0;
  for (std::size_t free = 0; free < n; ++free) {
    for (std::size_t mask = 0; mask < (std::size_t(1) << n); ++mask) {
      double sum = 0, value = 0;
      for (std::size_t j = 0; j < n; ++j) {
        if (j == free) continue;
        const double p = (mask >> j) & 1 ? hi[j] : lo[j];
        sum += p;
        value += p * values[j];
      }
      const double rest = 1.0 - sum;
      if (rest < lo[free] - kEnumerationRounding || rest > hi[free] + kEnumerationRounding) continue;
      value += rest * values[free];
      best = bound == Bound::Lower ? std::min(best, value) : std::max(best, value);
    }
  }
  return best;
}

TEST(IntervalBellman, MatchesVertexEnumeration) {
  std::mt19937_64 generator(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = 2 + std::size_t(trial % 5);
    // A distribution q, and intervals around it: always feasible.
    std::vector<double> q(n), lo(n), hi(n), values(n);
    double total = 0;
    for (double& x : q) total += (x = unit(generator));
    for (std::size_t j = 0; j < n; ++j) {
      q[j] /= total;
      lo[j] = q[j] * unit(generator);
      hi[j] = std::min(1.0, q[j] + (1 - q[j]) * unit(generator));
      values[j] = trial % 3 == 0 ? double(j % 2) : unit(generator);
    }
    for (Bound bound : {Bound::Lower, Bound::Upper}) {
      const double exact = vertex_optimum(lo, hi, values, bound), got = optimum(lo, hi, values, bound);
      const double allowed = robust_expectation_rounding(n) * 2 + kEnumerationRounding * double(n);
      if (bound == Bound::Lower) {
        EXPECT_LE(got, exact + kEnumerationRounding * double(n));
        EXPECT_GE(got, exact - allowed);
      } else {
        EXPECT_GE(got, exact - kEnumerationRounding * double(n));
        EXPECT_LE(got, exact + allowed);
      }
    }
  }
}

TEST(IntervalBellman, InfeasibleRowIsALogicError) {
  const std::vector<double> lo = {0.1, 0.2}, hi = {0.3, 0.3}, values = {0.0, 1.0};
  EXPECT_THROW(optimum(lo, hi, values, Bound::Lower), std::logic_error);
}

// Random per-dimension bounds of a row around random 1-d distributions (window inside the grid):
// the window's cells, the mass leaving the grid and, `with_cut`, cut mass.
std::vector<DimensionBounds> random_row(const Grid& grid, bool with_cut, std::mt19937_64& generator) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<DimensionBounds> row(grid.dims());
  for (std::size_t d = 0; d < grid.dims(); ++d) {
    DimensionBounds& dimension = row[d];
    const auto count = std::int64_t(grid.count(d));
    dimension.first = std::int64_t(unit(generator) * double(count - 1));
    dimension.last = std::min<std::int64_t>(count - 1, dimension.first + 1 + std::int64_t(unit(generator) * 3));
    std::vector<double> q(std::size_t(dimension.last - dimension.first + 3));
    double total = 0;
    for (double& x : q) total += (x = unit(generator));
    if (!with_cut) total -= q.back(), q.back() = 0;
    std::vector<MassInterval> masses;
    for (double x : q) {
      const double p = x / total;
      masses.push_back({p * (0.7 + 0.3 * unit(generator)), std::min(1.0, p * (1.0 + 0.5 * unit(generator)))});
    }
    dimension.cut = masses.back();
    masses.pop_back();
    dimension.leave = masses.back();
    masses.pop_back();
    dimension.cells = masses;
  }
  return row;
}

TEST(IntervalBellman, OrthogonalLowerBoundIsAtLeastTheJointOne) {
  std::mt19937_64 generator(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const GridSpec& spec : {grid_spec({0, 0}, {5, 4}, {1, 1}), grid_spec({0, 0, 0}, {3, 3, 2}, {1, 1, 1})}) {
    const Grid grid(spec);
    for (int trial = 0; trial < 100; ++trial) {
      // Without cut mass the upper bound compares the same way (all mass outside the window is
      // then worth 0 to both); with it the product set may value differently the mass one
      // dimension cuts and another sends off the grid.
      const bool with_cut = trial % 2 == 1;
      const std::vector<DimensionBounds> row = random_row(grid, with_cut, generator);
      std::vector<double> values(grid.size());
      for (double& v : values) v = unit(generator);
      const IntervalRow joint = joint_row(grid, row);
      const double product_lower = product_expectation(grid, row, values.data(), Bound::Lower);
      const double product_upper = product_expectation(grid, row, values.data(), Bound::Upper);
      EXPECT_GE(product_lower, joint_expectation(joint, values.data(), Bound::Lower) - kOrthogonalSlack);
      if (!with_cut) {
        EXPECT_LE(product_upper, joint_expectation(joint, values.data(), Bound::Upper) + kOrthogonalSlack);
      }
      EXPECT_LE(product_lower, product_upper);
    }
  }
}

TEST(IntervalBellman, OneScratchServesGridsOfTheSameDimensions) {
  // A scratch first used on one grid gives on another the bound a fresh scratch gives.
  std::mt19937_64 generator(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  ProductScratch scratch;
  for (const GridSpec& spec : {grid_spec({0, 0}, {5, 4}, {1, 1}), grid_spec({0, 0}, {3, 6}, {1, 1})}) {
    const Grid grid(spec);
    for (int trial = 0; trial < 20; ++trial) {
      const std::vector<DimensionBounds> row = random_row(grid, trial % 2 == 1, generator);
      std::vector<double> values(grid.size());
      for (double& v : values) v = unit(generator);
      std::vector<DimensionView> views;
      for (const DimensionBounds& dimension : row) views.push_back(view_of(dimension));
      for (Bound bound : {Bound::Lower, Bound::Upper})
        EXPECT_EQ(product_expectation(grid, views.data(), values.data(), bound, scratch),
                  product_expectation(grid, row, values.data(), bound));
    }
  }
}

TEST(IntervalBellman, OneDimensionOrthogonalEqualsJoint) {
  std::mt19937_64 generator(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Grid grid(grid_spec({0}, {9}, {1}));
  for (int trial = 0; trial < 100; ++trial) {
    const std::vector<DimensionBounds> row = random_row(grid, trial % 2 == 1, generator);
    std::vector<double> values(grid.size());
    for (double& v : values) v = unit(generator);
    const IntervalRow joint = joint_row(grid, row);
    for (Bound bound : {Bound::Lower, Bound::Upper})
      EXPECT_EQ(product_expectation(grid, row, values.data(), bound), joint_expectation(joint, values.data(), bound));
  }
}

TEST(IntervalBellman, JointRowIsTheRoundedProduct) {
  const Grid grid(grid_spec({0, 0}, {3, 3}, {1, 1}));
  std::vector<DimensionBounds> row(2);
  row[0].first = 1;
  row[0].last = 2;
  row[0].cells = {{0.3, 0.5}, {0.4, 0.6}};
  row[1].first = 0;
  row[1].last = 0;
  row[1].cells = {{0.7, 0.9}};
  row[0].leave = {0.0, 0.1};
  row[0].cut = {0.0, 0.2};
  row[1].leave = {0.05, 0.2};
  row[1].cut = {0.05, 0.1};
  const IntervalRow joint = joint_row(grid, row);
  ASSERT_EQ(joint.targets.size(), 2u);
  EXPECT_EQ(joint.targets[0], grid.flat_index(std::vector<std::size_t>{1, 0}.data()));
  EXPECT_EQ(joint.targets[1], grid.flat_index(std::vector<std::size_t>{2, 0}.data()));
  // lo rounded down below the exact product, hi up above it, by one rounding at most.
  EXPECT_LE(joint.lo[0], 0.3 * 0.7);
  EXPECT_GE(joint.lo[0], round_down(0.3 * 0.7, 2));
  EXPECT_GE(joint.hi[1], 0.6 * 0.9);
  EXPECT_LE(joint.hi[1], round_up(0.6 * 0.9, 2));
  // Leave: [max 0.05, 0.1 + 0.2]; cut: [0 (two dimensions), 0.2 + 0.1]; both at most 1 - sum lo
  // = 1 - (0.21 + 0.28) = 0.51.
  ASSERT_EQ(joint.lo.size(), 4u);
  EXPECT_EQ(joint.lo[2], 0.05);
  EXPECT_NEAR(joint.hi[2], 0.3, 1e-15);
  EXPECT_GE(joint.hi[2], 0.3);
  EXPECT_EQ(joint.lo[3], 0.0);
  EXPECT_NEAR(joint.hi[3], 0.3, 1e-15);
  EXPECT_GE(joint.hi[3], 0.3);
}

}  // namespace
}  // namespace amytiss::detail
