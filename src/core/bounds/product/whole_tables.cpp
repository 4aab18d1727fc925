#include "bounds/product/whole_tables.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

#include "common/parallel_for.hpp"

namespace amytiss::detail {
bool ProductSweep::pays(const Grid& states, const RowBounds& rows, std::size_t row_count) {
  std::size_t prefixes = 1;
  for (std::size_t d = 0; d < states.dims(); ++d) {
    std::size_t window_cells = 0;
    for (std::uint32_t b = 0; b < rows.distinct_bounds(d); ++b) window_cells += rows.distinct(d, b).count + 2;
    if (states.count(d) * rows.distinct_bounds(d) > kScanLengthPerOutcome * window_cells) return false;
    if (d == 0) continue;
    prefixes *= states.count(d - 1);
    if (prefixes * rows.suffix_classes(d) > kLinesPerRow * row_count) return false;
  }
  return fits(states, rows);
}

bool ProductSweep::fits(const Grid& states, const RowBounds& rows) {
  std::size_t entries = 0, prefixes = 1;
  for (std::size_t d = 1; d < states.dims(); ++d) {
    prefixes *= states.count(d - 1);
    entries += prefixes * rows.suffix_classes(d);
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
