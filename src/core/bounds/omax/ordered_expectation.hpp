#pragma once
// One O-maximisation of robust_expectation() over a window of a line whose filling order is
// known: the expectation at the lower bounds, then the budget given in sorted order. The sort is
// done once per line (sort_line()), and every window applied to the line is a scan: the product
// sweep applies one window to many lines (ordered_expectations()). Results are
// robust_expectation()'s, bit for bit. (The variable elimination, many windows to one line, takes
// the threshold form instead: bounds/omax/threshold_expectation.hpp.)
#include <cstddef>
#include <cstdint>
#include <vector>

#include "bounds/omax/robust_expectation.hpp"

namespace amytiss::detail {

/// Sums of a window's lower and upper bounds (cells, then leave, then cut: robust_expectation()'s
/// order); window_sums() checks that they make a feasible row (std::logic_error otherwise).
struct WindowSums {
  double lo = 0.0, hi = 0.0;
};
WindowSums window_sums(const DimensionView& window);

/// Sorts one line of `length` values: order[r] is the position of the r-th value in `bound`'s
/// filling order (increasing values for the lower bound, decreasing for the upper; stable), rank
/// the inverse.
void sort_line(const double* values, std::size_t length, Bound bound, std::uint32_t* order, std::uint32_t* rank);

/// Sort order of every line of `count` lines of `length` values: order[line * length + r] is the
/// position of the r-th value of the line in a bound's filling order (stable), rank the inverse.
struct LineOrder {
  std::vector<std::uint32_t> order, rank;
};

/// sort_line() of each of `count` lines of `length` values (line k at lines + k * length) into
/// `sorted`, on `threads` workers.
void sort_lines(const double* lines, std::size_t count, std::size_t length, Bound bound, unsigned threads,
                LineOrder& sorted);

/// One O-maximisation of robust_expectation() over a window of a line whose filling order is
/// known: `line` holds the values of the dimension's grid cells, `order` their positions in the
/// bound's filling order and `rank` each position's place in it, `window` the intervals (cells
/// first.. of the line, leave worth 0, cut worth cut_value(bound)) with their window_sums(). The
/// result is robust_expectation()'s, bit for bit.
double ordered_expectation(const double* line, const std::uint32_t* order, const std::uint32_t* rank,
                           std::size_t length, const DimensionView& window, const WindowSums& sums, Bound bound);

/// ordered_expectation() of `line_count` consecutive lines (line k at lines + k * length, its
/// order and rank at the same offsets) with one window, into out[0..line_count): the same results,
/// bit for bit, several short lines at a time.
void ordered_expectations(const double* lines, const std::uint32_t* orders, const std::uint32_t* ranks,
                          std::size_t length, std::size_t line_count, const DimensionView& window,
                          const WindowSums& sums, Bound bound, double* out);

}  // namespace amytiss::detail
