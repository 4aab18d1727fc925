#include "bounds/robust_step.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace amytiss::detail {
namespace {

// The cells with dimension 0 varying fastest: neighbours in this order share their coordinates
// of dimensions 1.., hence usually the suffix classes of their rows and the stage-0 lines the
// sweep reads for them, which then stay in cache.
std::vector<std::uint32_t> first_dimension_fastest(const Grid& states) {
  std::vector<std::uint32_t> order(states.size());
  std::vector<std::size_t> multi(states.dims(), 0);
  for (std::size_t visit = 0; visit < order.size(); ++visit) {
    order[visit] = std::uint32_t(states.flat_index(multi.data()));
    for (std::size_t d = 0; d < multi.size() && ++multi[d] == states.count(d); ++d) multi[d] = 0;
  }
  return order;
}

}  // namespace

RobustStep::RobustStep(const Abstraction& abstraction, const RowBounds& rows, std::vector<CellRole> roles,
                       Bound bound, const MethodChoice& choice, unsigned threads,
                       std::shared_ptr<SweepBuffers> sweep_buffers)
    : a_(abstraction), rows_(rows), roles_(std::move(roles)), bound_(bound), choice_(choice), threads_(threads) {
  const std::size_t dims = a_.states.dims();
  stage_caches_.resize(dims);
  stage_cache_entries_.assign(dims, 0);
  switch (choice_.method) {
    case BoundsMethod::Joint: return;
    case BoundsMethod::WholeTables:
      sweep_ = std::make_unique<ProductSweep>(a_.states, rows_, bound_, threads_, std::move(sweep_buffers));
      last_choice_.assign(a_.states.size(), kNoChoice);
      visit_order_ = first_dimension_fastest(a_.states);
      return;
    case BoundsMethod::Elimination: {
      std::vector<bool> has_rows(roles_.size());
      for (std::size_t cell = 0; cell < roles_.size(); ++cell) has_rows[cell] = roles_[cell] == CellRole::Free;
      factored_ = std::make_unique<RobustFactoredSweep>(a_, rows_, has_rows, *choice_.plan, bound_, threads_,
                                                        std::move(sweep_buffers));
      return;
    }
    case BoundsMethod::Rows: break;
    case BoundsMethod::Auto: throw std::logic_error("RobustStep needs a method chosen by choose_bounds_method()");
  }
  // Deepest stages first: their lines are the most numerous and the most shared. A cache pays
  // when it has fewer entries than the lines the rows would compute (kLinesPerRow per row and
  // stage at least) and fits the budget; clearing it at every step is then cheap.
  constexpr std::size_t kLinesPerRow = 16;
  std::size_t budget = kMaxStageCacheEntries, prefixes = a_.states.size();
  for (std::size_t d = dims; d-- > 1;) {
    prefixes /= a_.states.count(d);
    const std::size_t entries = prefixes * rows_.suffix_classes(d);
    if (entries == 0 || entries > budget || entries > kLinesPerRow * a_.triples()) continue;
    stage_caches_[d].reset(new std::atomic<double>[entries]);
    stage_cache_entries_[d] = entries;
    budget -= entries;
  }
}

std::string RobustStep::method() const {
  const std::string text = method_text(choice_.method) + " (" + choice_.reason;
  if (!factored_) return text + ")";
  std::string order, pairs;
  for (std::size_t d : factored_->order()) order += " x'" + std::to_string(d);
  for (const RobustFactoredSweep::StageRun& run : factored_->runs())
    if (run.last > run.first)
      pairs += "; x'" + std::to_string(factored_->order()[run.first]) + " and x'" +
               std::to_string(factored_->order()[run.last]) + " as a pair";
  return text + "; eliminates" + order + pairs + ")";
}

std::vector<std::pair<std::string, double>> RobustStep::stage_seconds() const {
  std::vector<std::pair<std::string, double>> stages;
  if (!factored_) return stages;
  auto dimension = [&](std::size_t k) { return "x'" + std::to_string(factored_->order()[k]); };
  for (const RobustFactoredSweep::StageRun& run : factored_->runs()) {
    const std::string stage =
        run.last > run.first
            ? "stages " + std::to_string(run.first) + "-" + std::to_string(run.last) + " (" + dimension(run.first) +
                  " " + dimension(run.last)
            : "stage " + std::to_string(run.first) + " (" + dimension(run.first);
    stages.emplace_back(stage + ", all steps)", run.seconds);
  }
  return stages;
}

void RobustStep::reset_stage_caches() {
  for (std::size_t d = 0; d < stage_caches_.size(); ++d)
    for (std::size_t i = 0; i < stage_cache_entries_[d]; ++i)
      stage_caches_[d][i].store(std::numeric_limits<double>::quiet_NaN(), std::memory_order_relaxed);
}

void RobustStep::use_stage_caches(ProductScratch& scratch) const {
  scratch.views.resize(a_.states.dims());
  scratch.caches.assign(a_.states.dims(), {});
  for (std::size_t d = 1; d < stage_caches_.size(); ++d)
    if (stage_cache_entries_[d]) scratch.caches[d] = {stage_caches_[d].get(), rows_.suffix_classes(d), 0};
}

double RobustStep::expectation(std::size_t row, const double* in, ProductScratch& scratch) const {
  if (sweep_) return sweep_->expectation(row);
  DimensionView* views = scratch.views.data();
  rows_.dimensions(row, views);
  for (std::size_t d = 1; d < scratch.caches.size(); ++d)
    if (scratch.caches[d].table) scratch.caches[d].row_class = rows_.suffix_class(row, d);
  if (choice_.method != BoundsMethod::Joint) return product_expectation(a_.states, views, in, bound_, scratch);
  return joint_expectation(joint_row(a_.states, views), in, bound_);
}

double RobustStep::worst_case(std::size_t cell, std::size_t input, const double* in, ProductScratch& scratch) const {
  double worst = std::numeric_limits<double>::infinity();
  for (std::size_t w = 0; w < a_.disturbances.size(); ++w)
    worst = std::min(worst, factored_ ? factored_->expectation(cell, input, w)
                                      : expectation(rows_.row(cell, input, w), in, scratch));
  return worst;
}

double RobustStep::estimate(std::size_t cell, std::size_t input) const {
  double estimate = std::numeric_limits<double>::infinity();
  for (std::size_t w = 0; w < a_.disturbances.size(); ++w)
    estimate = std::min(estimate, sweep_->upper_estimate(rows_.row(cell, input, w)));
  return estimate;
}

double RobustStep::choose(std::size_t cell, const double* in, ProductScratch& scratch, std::vector<double>& estimates,
                            std::uint32_t& chosen) const {
  // The maximiser with the lowest index. With the sweep, every input's estimate is read first (the
  // reads overlap), the input chosen at the previous step goes first (before any choice, the one
  // with the highest estimate), and an input whose estimate cannot beat the best so far is
  // skipped: it can only tie with it when its index is lower, so those need a strictly lower
  // estimate.
  std::size_t seed = 0;
  if (sweep_) {
    estimates.resize(a_.inputs.size());
    for (std::size_t u = 0; u < a_.inputs.size(); ++u) estimates[u] = estimate(cell, u);
    seed = last_choice_[cell];
    if (seed == kNoChoice) seed = std::size_t(std::max_element(estimates.begin(), estimates.end()) - estimates.begin());
  }
  double best = worst_case(cell, seed, in, scratch);
  chosen = std::uint32_t(seed);
  for (std::size_t u = 0; u < a_.inputs.size(); ++u) {
    if (u == seed) continue;
    if (sweep_ && (estimates[u] < best || (estimates[u] == best && u > chosen))) continue;
    const double value = worst_case(cell, u, in, scratch);
    if (value > best || (value == best && u < chosen)) {
      best = value;
      chosen = std::uint32_t(u);
    }
  }
  return best;
}

void RobustStep::prepare(const double* in) {
  if (factored_) return factored_->prepare(in);
  reset_stage_caches();
  if (sweep_) sweep_->prepare(in);
}

void RobustStep::apply(const double* in, double* out, std::uint32_t* chosen) {
  prepare(in);
  parallel_for(a_.states.size(), threads_, [&](unsigned, std::size_t first, std::size_t last) {
    ProductScratch scratch;
    use_stage_caches(scratch);
    std::vector<double> estimates;
    for (std::size_t visit = first; visit < last; ++visit) {
      const std::size_t cell = visit_order_.empty() ? visit : visit_order_[visit];
      chosen[cell] = 0;
      if (roles_[cell] != CellRole::Free) {
        out[cell] = a_.terminal_value(roles_[cell]);
        continue;
      }
      out[cell] = choose(cell, in, scratch, estimates, chosen[cell]);
      if (sweep_) last_choice_[cell] = chosen[cell];
    }
  });
}

void RobustStep::evaluate(const double* in, double* out, const std::uint32_t* controller) {
  prepare(in);
  parallel_for(a_.states.size(), threads_, [&](unsigned, std::size_t first, std::size_t last) {
    ProductScratch scratch;
    use_stage_caches(scratch);
    for (std::size_t cell = first; cell < last; ++cell)
      out[cell] = roles_[cell] == CellRole::Free ? worst_case(cell, controller[cell], in, scratch)
                                                 : a_.terminal_value(roles_[cell]);
  });
}

}  // namespace amytiss::detail
