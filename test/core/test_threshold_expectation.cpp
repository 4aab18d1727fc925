// The O-maximisation by its threshold (bounds/omax/threshold_expectation.hpp): a sorted line holds an
// increasing order (line after line, neighbours and lines drawn afresh) and its windows' ranks;
// from any starting rank,
// on lines of every length (ranks as bits up to 128 cells, scanned beyond), with ties, cells
// without slack, and leave or cut taking the whole budget, the search gives robust_expectation()'s
// bound within rounding, never past the exact value's sound side, and ends on a rank of the line,
// with each vector unit the processor has (AVX2 and the baseline giving the same search); so does
// the search of an unsorted line.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "bounds/omax/ordered_expectation.hpp"
#include "bounds/omax/threshold_expectation.hpp"
#include "random_rows.hpp"

namespace amytiss::detail {
namespace {

using namespace amytiss::test_rows;

constexpr unsigned kSeed = 20261202;
constexpr int kTrials = 300;
// Both bounds are robust_expectation()'s exact value moved outward by at most a few 1e-14.
constexpr double kAgreement = 1e-12;

const std::size_t kLengths[] = {1, 2, 5, 41, 64, 65, 128, 129, 200, 300};

SortedLine sorted_line(const std::vector<double>& values, Bound bound) {
  SortedLine line(values.size());
  for (std::size_t a = 0; a < values.size(); ++a) line.keys()[a] = (bound == Bound::Lower ? 1.0 : -1.0) * values[a];
  line.sort(false);
  return line;
}

// Sorted lines in a row: each a neighbour of the last (a few values moved a little), now and then
// one drawn afresh.
TEST(ThresholdExpectation, SortedLineHoldsAnIncreasingOrderAndEachWindowsRanks) {
  std::mt19937 random(kSeed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t length : kLengths) {
    SortedLine line(length);
    std::vector<double> values = random_smooth_line(random, length);
    for (int trial = 0; trial < kTrials / 10; ++trial) {
      if (trial % 7 == 0) values = trial % 2 ? random_line(random, length) : random_smooth_line(random, length);
      for (double& value : values)
        if (unit(random) < 0.1) value = std::clamp(value + 0.05 * (unit(random) - 0.5), 0.0, 1.0);
      for (std::size_t a = 0; a < length; ++a) line.keys()[a] = -values[a];
      line.sort(trial % 3 != 0);
      std::vector<char> seen(length, 0);
      for (std::size_t r = 0; r < length; ++r) {
        ASSERT_LT(line.order(r), length);
        ASSERT_FALSE(seen[line.order(r)]) << "order is a permutation";
        seen[line.order(r)] = 1;
        ASSERT_EQ(line.rank(line.order(r)), r);
        const double key = line.keys()[line.order(r)];
        ASSERT_TRUE(r == 0 || line.keys()[line.order(r - 1)] <= key) << "length " << length << " trial " << trial;
      }
      if (length > SortedLine::kMaskedLength) continue;
      for (std::size_t first = 0; first < length; ++first)
        for (std::size_t count = 0; first + count <= length; count += 7) {
          std::uint64_t mask[2], expected[2] = {0, 0};
          line.ranks_of(first, count, mask);
          for (std::size_t position = first; position < first + count; ++position)
            expected[line.rank(position) / 64] |= std::uint64_t(1) << (line.rank(position) % 64);
          ASSERT_EQ(mask[0], expected[0]) << "length " << length << " first " << first << " count " << count;
          ASSERT_EQ(mask[1], expected[1]) << "length " << length << " first " << first << " count " << count;
        }
    }
  }
}

// For each vector unit, on random lines and windows, from the first, middle and last starts and a
// random one: search(line's values, window, bound, start (in and out), unit) gives
// robust_expectation()'s bound within rounding, on the exact value's sound side of it, and ends
// on an index of the line.
template <typename Search>
void expect_the_sorted_bound_from_any_start(Search&& search) {
  for (VectorUnit unit : vector_units()) {
    std::mt19937 random(kSeed);
    for (std::size_t length : kLengths)
      for (int trial = 0; trial < kTrials; ++trial) {
        // Values on a few levels (long runs of ties) or drawn from [0, 1].
        const std::vector<double> values = trial % 2 ? random_line(random, length) : random_smooth_line(random, length);
        RandomRow row = random_row(random, length);
        row.window.cells = row.cells.data();
        const PackedWindows packed(std::vector<DimensionView>{row.window});
        const double rounding = robust_expectation_rounding(row.cells.size() + 2);
        for (Bound bound : {Bound::Lower, Bound::Upper}) {
          const double sorted = sorted_expectation(values, row, bound);
          std::uniform_int_distribution<std::size_t> any_start(0, length - 1);
          for (std::size_t start : {std::size_t(0), length / 2, length - 1, any_start(random)}) {
            std::size_t end = start;
            const double bound_value = search(values, packed[0], bound, end, unit);
            ASSERT_LT(end, length);
            EXPECT_NEAR(bound_value, sorted, kAgreement)
                << "length " << length << " trial " << trial << " start " << start;
            // The sorted bound lies within twice its rounding of the exact value; ours lies on its
            // sound side of it.
            if (bound == Bound::Lower)
              EXPECT_LE(bound_value, sorted + 2 * rounding) << "length " << length << " trial " << trial;
            else
              EXPECT_GE(bound_value, sorted - 2 * rounding) << "length " << length << " trial " << trial;
          }
        }
      }
  }
}

TEST(ThresholdExpectation, FromAnyStartItIsTheSortedOneWithinRoundingOnItsSoundSide) {
  expect_the_sorted_bound_from_any_start([](const std::vector<double>& values, const PackedWindow& window, Bound bound,
                                            std::size_t& start, VectorUnit unit) {
    return threshold_expectation(sorted_line(values, bound), window, bound, start, unit);  // start: a rank
  });
}

// The search without a sort, from a position of the line.
TEST(ThresholdExpectation, TheScanFromAnyStartIsTheSortedOneWithinRoundingOnItsSoundSide) {
  expect_the_sorted_bound_from_any_start([](const std::vector<double>& values, const PackedWindow& window, Bound bound,
                                            std::size_t& start, VectorUnit unit) {
    std::vector<double> keys(values.size() + kThresholdLanes, 0.0);
    for (std::size_t a = 0; a < values.size(); ++a) keys[a] = (bound == Bound::Lower ? 1.0 : -1.0) * values[a];
    return threshold_scan(keys.data(), window, bound, start, unit);
  });
}

// Many windows over one line in one batch (their first passes in one loop, then the searches that
// move on): each search's bound and end as threshold_expectation() gives them alone, bit for bit.
TEST(ThresholdExpectation, ABatchGivesEachSearchsBoundAndEndBitForBit) {
  constexpr std::size_t kWindowsPerLine = 12;
  std::mt19937 random(kSeed);
  ThresholdSearches batch;
  for (VectorUnit unit : vector_units())
    for (std::size_t length : kLengths)
      for (int trial = 0; trial < kTrials / 10; ++trial) {
        const std::vector<double> values = trial % 2 ? random_line(random, length) : random_smooth_line(random, length);
        std::vector<RandomRow> rows;
        std::vector<DimensionView> views;
        for (std::size_t w = 0; w < kWindowsPerLine; ++w) rows.push_back(random_row(random, length));
        for (RandomRow& row : rows) {
          row.window.cells = row.cells.data();
          views.push_back(row.window);
        }
        const PackedWindows packed(views);
        std::vector<const PackedWindow*> windows;
        for (std::size_t w = 0; w < kWindowsPerLine; ++w) windows.push_back(&packed[w]);
        std::uniform_int_distribution<std::uint32_t> any_position(0, std::uint32_t(length - 1));
        for (Bound bound : {Bound::Lower, Bound::Upper}) {
          const SortedLine line = sorted_line(values, bound);
          std::vector<std::uint32_t> positions(kWindowsPerLine);
          for (std::uint32_t& position : positions) position = any_position(random);
          const std::vector<std::uint32_t> starts = positions;
          std::vector<double> bounds(kWindowsPerLine);
          batch.run(line, windows.data(), kWindowsPerLine, bound, positions.data(), bounds.data(), unit);
          for (std::size_t w = 0; w < kWindowsPerLine; ++w) {
            std::size_t end = line.rank(starts[w]);
            EXPECT_EQ(bounds[w], threshold_expectation(line, packed[w], bound, end, unit))
                << "length " << length << " trial " << trial << " window " << w;
            EXPECT_EQ(positions[w], line.order(end)) << "length " << length << " trial " << trial << " window " << w;
          }
        }
      }
}

TEST(ThresholdExpectation, EveryVectorUnitGivesTheBaselinesBoundUpToTheOrderOfAdditions) {
  std::mt19937 random(kSeed);
  const std::vector<VectorUnit> units = vector_units();
  if (units.size() == 1) GTEST_SKIP() << "this processor has the baseline vector unit only";
  for (std::size_t length : kLengths)
    for (int trial = 0; trial < kTrials; ++trial) {
      const std::vector<double> values = random_smooth_line(random, length);
      RandomRow row = random_row(random, length);
      row.window.cells = row.cells.data();
      const PackedWindows packed(std::vector<DimensionView>{row.window});
      for (Bound bound : {Bound::Lower, Bound::Upper}) {
        const SortedLine line = sorted_line(values, bound);
        std::size_t baseline_end = length / 2;
        const double baseline = threshold_expectation(line, packed[0], bound, baseline_end, VectorUnit::Baseline);
        for (VectorUnit unit : units) {
          std::size_t end = length / 2;
          EXPECT_NEAR(threshold_expectation(line, packed[0], bound, end, unit), baseline, kAgreement);
          EXPECT_EQ(end, baseline_end) << "length " << length << " trial " << trial;
        }
      }
    }
}

}  // namespace
}  // namespace amytiss::detail
