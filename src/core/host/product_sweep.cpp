#include "host/product_sweep.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace amytiss::detail {
namespace {

void require(bool invariant, const char* what) {
  if (!invariant) throw std::logic_error(std::string("product sweep: ") + what);
}

// A scan is cheaper than robust_expectation()'s sort while the line is at most this many times
// longer than the window.
constexpr std::size_t kScanLengthPerOutcome = 4;
// Lines up to this long visit only the window's cells (a bit per rank).
constexpr std::size_t kMaskBits = 256;

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
  const Extra leave{0.0, 0.0, window.leave.hi - window.leave.lo}, cut_mass{sign * cut, cut, window.cut.hi - window.cut.lo};
  const Extra extras[2] = {bound == Bound::Lower ? leave : cut_mass, bound == Bound::Lower ? cut_mass : leave};
  std::size_t next_extra = 0;
  double budget = 1.0 - sums.lo;
  // An outcome with slack takes min(slack, budget); one without takes no part, as in
  // robust_expectation().
  auto give = [&](double value, double slack) {
    const double given = slack > 0.0 ? std::min(slack, budget) : 0.0;
    result += given * value;
    budget -= given;
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
        const MassInterval& cell = cells[position - first];  // in the window, with slack
        const double given = std::min(cell.hi - cell.lo, budget);
        result += given * value;
        budget -= given;
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

// ordered_expectation() of kWindows windows of one line at most 128 long: the sums at the lower
// bounds are independent chains of additions, which the processor overlaps, and each window's
// mask of ranks stays in two registers.
template <std::size_t kWindows>
void line_windows_expectations(const double* line, const std::uint32_t* order, const std::uint32_t* rank,
                               std::size_t length, const DimensionView* const* windows, const WindowSums* const* sums,
                               Bound bound, double* out) {
  double result[kWindows] = {};
  std::uint64_t mask[kWindows][2] = {};
  std::size_t common = windows[0]->count;
  for (std::size_t k = 1; k < kWindows; ++k) common = std::min(common, windows[k]->count);
  auto add = [&](std::size_t k, std::size_t j) {
    const MassInterval& cell = windows[k]->cells[j];
    const std::size_t position = std::size_t(windows[k]->first) + j;
    result[k] += cell.lo * line[position];
    const std::uint32_t r = rank[position];
    const std::uint64_t slack = cell.hi - cell.lo > 0.0;
    mask[k][0] |= r < 64 ? slack << r : 0;
    mask[k][1] |= r < 64 ? 0 : slack << (r - 64);
  };
  for (std::size_t j = 0; j < common; ++j)
    for (std::size_t k = 0; k < kWindows; ++k) add(k, j);
  const double cut = cut_value(bound);
  for (std::size_t k = 0; k < kWindows; ++k) {
    for (std::size_t j = common; j < windows[k]->count; ++j) add(k, j);
    result[k] += windows[k]->leave.lo * 0.0;
    result[k] += windows[k]->cut.lo * cut;
    out[k] = give_budget(result[k], line, order, length, *windows[k], *sums[k], bound, mask[k]);
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

void ordered_expectations_of_line(const double* line, const std::uint32_t* order, const std::uint32_t* rank,
                                  std::size_t length, const DimensionView* const* windows,
                                  const WindowSums* const* sums, std::size_t window_count, Bound bound, double* out) {
  constexpr std::size_t kBatch = 4;
  for (std::size_t k = 0; k < window_count; ++k)
    require(windows[k]->first >= 0 && std::size_t(windows[k]->first) + windows[k]->count <= length,
            "a window inside its line");
  std::size_t k = 0;
  if (length <= 128)
    for (; k + kBatch <= window_count; k += kBatch)
      line_windows_expectations<kBatch>(line, order, rank, length, windows + k, sums + k, bound, out + k);
  for (; k < window_count; ++k) out[k] = ordered_expectation(line, order, rank, length, *windows[k], *sums[k], bound);
}

bool ProductSweep::pays(const Grid& states, const RowBounds& rows, std::size_t row_count) {
  constexpr std::size_t kLinesPerRow = 64;
  std::size_t entries = 0, prefixes = 1;
  for (std::size_t d = 0; d < states.dims(); ++d) {
    std::size_t window_cells = 0;
    for (std::uint32_t b = 0; b < rows.distinct_bounds(d); ++b) window_cells += rows.distinct(d, b).count + 2;
    if (states.count(d) * rows.distinct_bounds(d) > kScanLengthPerOutcome * window_cells) return false;
    if (d == 0) continue;
    prefixes *= states.count(d - 1);
    const std::size_t stage = prefixes * rows.suffix_classes(d);
    if (stage > kLinesPerRow * row_count) return false;
    entries += stage;
  }
  return entries <= kMaxTableEntries;
}

ProductSweep::ProductSweep(const Grid& states, const RowBounds& rows, Bound bound, unsigned threads,
                           std::shared_ptr<SweepBuffers> buffers)
    : states_(states), rows_(rows), bound_(bound), threads_(threads), buffers_(std::move(buffers)) {
  if (!buffers_) buffers_ = std::make_shared<SweepBuffers>();
  const std::size_t dims = states.dims();
  prefixes_.assign(dims, 1);
  sums_.resize(dims);
  for (std::size_t d = 0; d < dims; ++d)
    for (std::uint32_t b = 0; b < rows.distinct_bounds(d); ++b) sums_[d].push_back(window_sums(rows.distinct(d, b)));
  for (std::size_t d = 1; d < dims; ++d) prefixes_[d] = prefixes_[d - 1] * states.count(d - 1);
  for (std::uint32_t b = 0; b < rows.distinct_bounds(0); ++b) {
    const DimensionView& window = rows.distinct(0, b);
    const auto first = std::int32_t(window.first), last = std::int32_t(window.first + std::int64_t(window.count)) - 1;
    estimate_windows_.push_back({first, last, window.cut.hi});
  }
}

void sort_line(const double* values, std::size_t length, Bound bound, std::uint32_t* order, std::uint32_t* rank) {
  const double sign = bound == Bound::Lower ? 1.0 : -1.0;
  std::iota(order, order + length, 0u);
  std::stable_sort(order, order + length,
                   [&](std::uint32_t a, std::uint32_t b) { return sign * values[a] < sign * values[b]; });
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

void ProductSweep::run_stage(std::size_t d, const double* source) {
  const std::size_t length = states_.count(d), prefixes = prefixes_[d];
  const std::size_t source_classes = d + 1 == states_.dims() ? 1 : rows_.suffix_classes(d + 1);
  // Line (next, p) of the source: the values at prefix p * length + k of class next.
  LineOrder& source_order = buffers_->source_order;
  sort_lines(source, source_classes * prefixes, length, bound_, threads_, source_order);
  std::vector<double>& stage = buffers_->tables[d];
  stage.resize(prefixes * rows_.suffix_classes(d));
  double* table = stage.data();
  parallel_for(rows_.suffix_classes(d), threads_, [&](unsigned, std::size_t first, std::size_t last) {
    for (std::size_t suffix_class = first; suffix_class < last; ++suffix_class) {
      const RowBounds::SuffixParts parts = rows_.suffix_parts(d, std::uint32_t(suffix_class));
      const DimensionView& window = rows_.distinct(d, parts.bounds);
      const WindowSums& sums = sums_[d][parts.bounds];
      // The source's lines of class `next` are consecutive: prefix p at (next * prefixes + p) * length.
      const std::size_t lines = std::size_t(parts.next) * prefixes * length;
      ordered_expectations(source + lines, source_order.order.data() + lines, source_order.rank.data() + lines,
                           length, prefixes, window, sums, bound_, table + suffix_class * prefixes);
    }
  });
}

void ProductSweep::prepare(const double* values) {
  const std::size_t dims = states_.dims();
  std::vector<std::vector<double>>& tables = buffers_->tables;
  tables.resize(dims);
  for (std::size_t d = dims; d-- > 1;) run_stage(d, d + 1 == dims ? values : tables[d + 1].data());
  stage0_lines_ = dims == 1 ? values : tables[1].data();
  const std::size_t lines = dims == 1 ? 1 : rows_.suffix_classes(1), length = states_.count(0);
  sort_lines(stage0_lines_, lines, length, bound_, threads_, buffers_->stage0_order);
  std::vector<double>& rising = buffers_->rising_max;
  std::vector<double>& falling = buffers_->falling_max;
  rising.resize(lines * length);
  falling.resize(lines * length);
  parallel_for(lines, threads_, [&](unsigned, std::size_t first, std::size_t last) {
    for (std::size_t start = first * length; start < last * length; start += length) {
      rising[start] = stage0_lines_[start];
      for (std::size_t k = 1; k < length; ++k)
        rising[start + k] = std::max(rising[start + k - 1], stage0_lines_[start + k]);
      falling[start + length - 1] = stage0_lines_[start + length - 1];
      for (std::size_t k = length - 1; k-- > 0;)
        falling[start + k] = std::max(falling[start + k + 1], stage0_lines_[start + k]);
    }
  });
}

double ProductSweep::expectation(std::size_t row) const {
  const std::size_t length = states_.count(0);
  const std::size_t line = (states_.dims() == 1 ? 0 : rows_.suffix_class(row, 1)) * length;
  const std::uint32_t bounds = rows_.bounds_index(row, 0);
  const LineOrder& sorted = buffers_->stage0_order;
  return ordered_expectation(stage0_lines_ + line, sorted.order.data() + line, sorted.rank.data() + line, length,
                             rows_.distinct(0, bounds), sums_[0][bounds], bound_);
}

double ProductSweep::upper_estimate(std::size_t row) const {
  const std::size_t length = states_.count(0);
  const std::size_t line = (states_.dims() == 1 ? 0 : rows_.suffix_class(row, 1)) * length;
  const EstimateWindow& window = estimate_windows_[rows_.bounds_index(row, 0)];
  // The window's largest value is at most the largest of the line up to its end and the largest
  // from its start (equal to it where the line rises to one peak and falls). Leave is worth 0.
  const double largest = window.last < window.first
                             ? 0.0
                             : std::min(buffers_->rising_max[line + std::size_t(window.last)],
                                        buffers_->falling_max[line + std::size_t(window.first)]);
  // Any distribution's expectation is at most its largest value; the cut (worth 1 to the upper
  // bound) takes at most cut.hi. expectation() clamps to [0, 1], and the lower bound of a window
  // of zeros is exactly 0 (every term is a product with 0, the rounding is clamped away).
  if (bound_ == Bound::Lower && largest == 0.0) return 0.0;
  const double estimate = bound_ == Bound::Upper ? largest + window.cut_hi * (1.0 - largest) : largest;
  return std::min(1.0, estimate + kEstimateMargin);
}

}  // namespace amytiss::detail
