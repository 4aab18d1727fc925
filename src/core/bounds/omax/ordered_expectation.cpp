#include "bounds/omax/ordered_expectation.hpp"

#include <algorithm>
#include <numeric>

#include "bounds/row_bounds.hpp"
#include "common/parallel_for.hpp"
#include "common/require.hpp"

namespace amytiss::detail {
namespace {

constexpr Require require{"ordered expectation: "};

// Lines up to this long visit only the window's cells (a bit per rank).
constexpr std::size_t kMaskBits = 256;
// Lines up to this long are sorted here (runs of kRunLength by insertion, then merged), longer
// ones by std::stable_sort.
constexpr std::size_t kMergeSortLength = 256;
constexpr std::size_t kRunLength = 8;

}  // namespace

WindowSums window_sums(const DimensionView& window) {
  // robust_expectation()'s order: the window's cells, then leave, then cut.
  WindowSums sums;
  for (std::size_t j = 0; j < window.count; ++j) {
    sums.lo += window.cells[j].lo;
    sums.hi += window.cells[j].hi;
  }
  sums.lo += window.leave.lo;
  sums.hi += window.leave.hi;
  sums.lo += window.cut.lo;
  sums.hi += window.cut.hi;
  const double rounding = robust_expectation_rounding(window.count + 2);
  require(sums.lo <= 1.0 + rounding && sums.hi >= 1.0 - rounding, "a row with sum lo <= 1 <= sum hi");
  return sums;
}

namespace {

// The rest of an O-maximisation once `result` holds the expectation at the lower bounds: the
// budget 1 - sums.lo goes to the window's cells with slack in filling order, leave and cut at their
// places, as robust_expectation() gives it; then the outward rounding and the clamp. `mask` (lines
// up to kMaskBits long) has the bits of those cells' ranks set; null: a scan of the whole order.
double give_budget(double result, const double* line, const std::uint32_t* order, std::size_t length,
                   const DimensionView& window, const WindowSums& sums, Bound bound, const std::uint64_t* mask) {
  const std::size_t count = window.count, first = std::size_t(window.first);
  const MassInterval* cells = window.cells;
  const double cut = cut_value(bound);
  const double rounding = robust_expectation_rounding(count + 2);
  // Leave and cut come after the line's cells of the same value (their index is larger).
  struct Extra {
    double key, value, slack;
  };
  const double sign = bound == Bound::Lower ? 1.0 : -1.0;
  const Extra leave{0.0, 0.0, window.leave.hi - window.leave.lo};
  const Extra cut_mass{sign * cut, cut, window.cut.hi - window.cut.lo};
  const Extra extras[2] = {bound == Bound::Lower ? leave : cut_mass, bound == Bound::Lower ? cut_mass : leave};
  std::size_t next_extra = 0;
  double budget = 1.0 - sums.lo;
  // An outcome with slack takes min(slack, budget); one without takes no part, as in
  // robust_expectation(). The minimum as a branch: while the whole slack fits, the budget's chain
  // of dependent operations is one subtraction per outcome.
  auto give = [&](double value, double slack) {
    if (!(slack > 0.0)) return;
    if (slack < budget) {
      result += slack * value;
      budget -= slack;
    } else {
      result += budget * value;
      budget = 0.0;
    }
  };
  auto give_extras_below = [&](double key) {
    for (; next_extra < 2 && extras[next_extra].key < key && budget > 0.0; ++next_extra)
      give(extras[next_extra].value, extras[next_extra].slack);
  };
  if (mask) {
    for (std::size_t word = 0; word * 64 < length && budget > 0.0; ++word) {
      for (std::uint64_t bits = mask[word]; bits && budget > 0.0; bits &= bits - 1) {
        const std::size_t position = order[word * 64 + std::size_t(__builtin_ctzll(bits))];
        const double value = line[position];
        give_extras_below(sign * value);
        if (!(budget > 0.0)) break;
        const MassInterval& cell = cells[position - first];  // in the window
        give(value, cell.hi - cell.lo);
      }
    }
  } else {
    for (std::size_t r = 0; r < length && budget > 0.0; ++r) {
      const std::size_t position = order[r], k = position - first;  // k wraps above count before the window
      const double value = line[position];
      give_extras_below(sign * value);
      if (k < count && budget > 0.0) give(value, cells[k].hi - cells[k].lo);
    }
  }
  for (; next_extra < 2 && budget > 0.0; ++next_extra) give(extras[next_extra].value, extras[next_extra].slack);
  result = bound == Bound::Lower ? result - rounding : result + rounding;
  return std::clamp(result, 0.0, 1.0);
}

// ordered_expectations() of kLines lines at once, each at most 64 long: the sums at the lower
// bounds of several lines are independent chains of additions, which the processor overlaps.
template <std::size_t kLines>
void short_lines_expectations(const double* lines, const std::uint32_t* orders, const std::uint32_t* ranks,
                              std::size_t length, const DimensionView& window, const WindowSums& sums, Bound bound,
                              double* out) {
  const std::size_t count = window.count, first = std::size_t(window.first);
  const MassInterval* cells = window.cells;
  double result[kLines] = {};
  std::uint64_t mask[kLines] = {};
  for (std::size_t j = 0; j < count; ++j) {
    const double lo = cells[j].lo;
    const std::uint64_t slack = cells[j].hi - cells[j].lo > 0.0;
    for (std::size_t k = 0; k < kLines; ++k) {
      result[k] += lo * lines[k * length + first + j];
      mask[k] |= slack << ranks[k * length + first + j];
    }
  }
  const double cut = cut_value(bound);
  for (std::size_t k = 0; k < kLines; ++k) {
    result[k] += window.leave.lo * 0.0;
    result[k] += window.cut.lo * cut;
    out[k] = give_budget(result[k], lines + k * length, orders + k * length, length, window, sums, bound, &mask[k]);
  }
}

}  // namespace

double ordered_expectation(const double* line, const std::uint32_t* order, const std::uint32_t* rank,
                           std::size_t length, const DimensionView& window, const WindowSums& sums, Bound bound) {
  const std::size_t count = window.count, first = std::size_t(window.first);
  require(window.first >= 0 && first + count <= length, "a window inside its line");
  const MassInterval* cells = window.cells;
  // The expectation at the lower bounds in robust_expectation()'s order. Lines up to kMaskBits
  // long also mark the window's cells with slack as bits at their ranks: visiting the set bits in
  // increasing order visits exactly them, in filling order.
  const bool masked = length <= kMaskBits;
  std::uint64_t mask[kMaskBits / 64] = {};
  double result = 0.0;
  for (std::size_t j = 0; j < count; ++j) {
    result += cells[j].lo * line[first + j];
    if (masked) {
      const std::uint32_t r = rank[first + j];
      mask[r / 64] |= std::uint64_t(cells[j].hi - cells[j].lo > 0.0) << (r % 64);
    }
  }
  result += window.leave.lo * 0.0;
  result += window.cut.lo * cut_value(bound);
  return give_budget(result, line, order, length, window, sums, bound, masked ? mask : nullptr);
}

void ordered_expectations(const double* lines, const std::uint32_t* orders, const std::uint32_t* ranks,
                          std::size_t length, std::size_t line_count, const DimensionView& window,
                          const WindowSums& sums, Bound bound, double* out) {
  require(window.first >= 0 && std::size_t(window.first) + window.count <= length, "a window inside its line");
  constexpr std::size_t kBatch = 4;
  std::size_t k = 0;
  if (length <= 64)
    for (; k + kBatch <= line_count; k += kBatch)
      short_lines_expectations<kBatch>(lines + k * length, orders + k * length, ranks + k * length, length, window,
                                       sums, bound, out + k);
  for (; k < line_count; ++k)
    out[k] = ordered_expectation(lines + k * length, orders + k * length, ranks + k * length, length, window, sums,
                                 bound);
}

void sort_line(const double* values, std::size_t length, Bound bound, std::uint32_t* order, std::uint32_t* rank) {
  const double sign = bound == Bound::Lower ? 1.0 : -1.0;
  if (length > kMergeSortLength) {
    std::iota(order, order + length, 0u);
    std::stable_sort(order, order + length,
                     [&](std::uint32_t a, std::uint32_t b) { return sign * values[a] < sign * values[b]; });
  } else {
    double keys[kMergeSortLength];
    for (std::size_t j = 0; j < length; ++j) keys[j] = sign * values[j];
    // Runs of kRunLength by insertion, then merges between `order` and a buffer; a merge takes
    // the right element only when its key is smaller (stable), chosen without a branch, which a
    // merge of unordered keys mispredicts half the time.
    std::uint32_t buffer[kMergeSortLength];
    for (std::size_t run = 0; run < length; run += kRunLength) {
      const std::size_t end = std::min(run + kRunLength, length);
      for (std::size_t i = run; i < end; ++i) {
        std::size_t j = i;
        for (; j > run && keys[i] < keys[order[j - 1]]; --j) order[j] = order[j - 1];
        order[j] = std::uint32_t(i);
      }
    }
    std::uint32_t *from = order, *to = buffer;
    for (std::size_t width = kRunLength; width < length; width *= 2) {
      for (std::size_t left = 0; left < length; left += 2 * width) {
        const std::size_t middle = std::min(left + width, length), end = std::min(left + 2 * width, length);
        std::size_t i = left, j = middle, out = left;
        while (i < middle && j < end) {
          const bool right = keys[from[j]] < keys[from[i]];
          to[out++] = right ? from[j] : from[i];
          j += right;
          i += !right;
        }
        while (i < middle) to[out++] = from[i++];
        while (j < end) to[out++] = from[j++];
      }
      std::swap(from, to);
    }
    if (from != order) std::copy(from, from + length, order);
  }
  for (std::size_t r = 0; r < length; ++r) rank[order[r]] = std::uint32_t(r);
}

void sort_lines(const double* lines, std::size_t count, std::size_t length, Bound bound, unsigned threads,
                LineOrder& sorted) {
  sorted.order.resize(count * length);
  sorted.rank.resize(count * length);
  parallel_for(count, threads, [&](unsigned, std::size_t first, std::size_t last) {
    for (std::size_t line = first; line < last; ++line)
      sort_line(lines + line * length, length, bound, sorted.order.data() + line * length,
                sorted.rank.data() + line * length);
  });
}

}  // namespace amytiss::detail
