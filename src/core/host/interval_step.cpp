#include "host/interval_step.hpp"

#include <limits>

namespace amytiss::detail {

IntervalStep::IntervalStep(const Abstraction& abstraction, const RowBounds& rows, std::vector<CellRole> roles,
                           Bound bound, AmbiguitySet set, unsigned threads)
    : a_(abstraction), rows_(rows), roles_(std::move(roles)), bound_(bound), set_(set), threads_(threads) {
  const std::size_t dims = a_.states.dims();
  if (set_ != AmbiguitySet::Product || dims < 2) return;
  const std::size_t prefixes = a_.states.size() / a_.states.count(dims - 1);
  const std::size_t entries = prefixes * rows_.distinct_bounds(dims - 1);
  // Clearing it at every step costs little beside the lines the rows compute (a window's width
  // per row and more); a cache far larger than that would not pay.
  constexpr std::size_t kLinesPerRow = 16;
  if (entries == 0 || entries > kMaxLineCacheEntries || entries > kLinesPerRow * a_.triples()) return;
  line_cache_.reset(new std::atomic<double>[entries]);
  line_cache_entries_ = entries;
}

void IntervalStep::reset_line_cache() {
  for (std::size_t i = 0; i < line_cache_entries_; ++i)
    line_cache_[i].store(std::numeric_limits<double>::quiet_NaN(), std::memory_order_relaxed);
}

void IntervalStep::use_line_cache(ProductScratch& scratch) const {
  scratch.views.resize(a_.states.dims());
  if (!line_cache_entries_) return;
  scratch.line_cache = line_cache_.get();
  scratch.line_cache_stride = rows_.distinct_bounds(a_.states.dims() - 1);
}

double IntervalStep::role_value(CellRole role) const {
  if (role == CellRole::FixedOne) return 1.0;
  if (role == CellRole::FixedZero) return 0.0;
  return a_.spec == SpecType::Safety ? 1.0 : 0.0;
}

double IntervalStep::expectation(std::size_t row, const double* in, ProductScratch& scratch) const {
  DimensionView* views = scratch.views.data();
  rows_.dimensions(row, views);
  if (scratch.line_cache) scratch.line_bounds = rows_.bounds_index(row, a_.states.dims() - 1);
  if (set_ == AmbiguitySet::Product) return product_expectation(a_.states, views, in, bound_, scratch);
  return joint_expectation(joint_row(a_.states, views), in, bound_);
}

double IntervalStep::worst_case(std::size_t cell, std::size_t input, const double* in, ProductScratch& scratch) const {
  double worst = std::numeric_limits<double>::infinity();
  for (std::size_t w = 0; w < a_.disturbances.size(); ++w)
    worst = std::min(worst, expectation(rows_.row(cell, input, w), in, scratch));
  return worst;
}

void IntervalStep::apply(const double* in, double* out, std::uint32_t* chosen) {
  reset_line_cache();
  parallel_for(a_.states.size(), threads_, [&](unsigned, std::size_t first, std::size_t last) {
    ProductScratch scratch;
    use_line_cache(scratch);
    for (std::size_t cell = first; cell < last; ++cell) {
      chosen[cell] = 0;
      if (roles_[cell] != CellRole::Free) {
        out[cell] = role_value(roles_[cell]);
        continue;
      }
      double best = -1.0;
      for (std::size_t u = 0; u < a_.inputs.size(); ++u) {
        const double value = worst_case(cell, u, in, scratch);
        if (value > best) {  // ties keep the lowest input
          best = value;
          chosen[cell] = std::uint32_t(u);
        }
      }
      out[cell] = best;
    }
  });
}

void IntervalStep::evaluate(const double* in, double* out, const std::uint32_t* controller) {
  reset_line_cache();
  parallel_for(a_.states.size(), threads_, [&](unsigned, std::size_t first, std::size_t last) {
    ProductScratch scratch;
    use_line_cache(scratch);
    for (std::size_t cell = first; cell < last; ++cell)
      out[cell] = roles_[cell] == CellRole::Free ? worst_case(cell, controller[cell], in, scratch)
                                                 : role_value(roles_[cell]);
  });
}

}  // namespace amytiss::detail
