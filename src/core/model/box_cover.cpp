#include "model/box_cover.hpp"

#include <algorithm>
#include <cstdint>
#include <map>

namespace amytiss::detail {
namespace {

class CoverSweep {
 public:
  CoverSweep(const std::vector<double>& lo, const std::vector<double>& hi, const std::vector<Box>& boxes,
             const std::vector<double>& slack)
      : lo_(lo), hi_(hi), memo_(lo.size()) {
    for (const Box& box : boxes) {
      bool overlaps = true;
      for (std::size_t d = 0; d < lo.size() && overlaps; ++d)
        overlaps = hi[d] > box.lb[d] + slack[d] && lo[d] < box.ub[d] - slack[d];
      if (!overlaps) continue;
      std::vector<double> from(lo.size()), to(lo.size());
      for (std::size_t d = 0; d < lo.size(); ++d) {
        from[d] = std::max(lo[d], box.lb[d] - slack[d]);
        to[d] = std::min(hi[d], box.ub[d] + slack[d]);
      }
      from_.push_back(std::move(from));
      to_.push_back(std::move(to));
    }
  }

  std::optional<bool> run() {
    std::vector<std::uint32_t> all(from_.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = std::uint32_t(i);
    const bool covered = sweep(0, all);
    if (steps_ > kMaxCoverSteps) return std::nullopt;
    return covered;
  }

 private:
  // Whether one of `active` spans [lo, hi] in every dimension from `dim` on.
  bool one_spans(std::size_t dim, const std::vector<std::uint32_t>& active) const {
    return std::any_of(active.begin(), active.end(), [&](std::uint32_t i) {
      for (std::size_t d = dim; d < lo_.size(); ++d)
        if (from_[i][d] > lo_[d] || to_[i][d] < hi_[d]) return false;
      return true;
    });
  }

  // Whether the boxes `active` (each spanning the slab chosen in every dimension before `dim`)
  // cover [lo, hi] in the dimensions from `dim` on.
  bool sweep(std::size_t dim, const std::vector<std::uint32_t>& active) {
    if (active.empty()) return false;
    if (dim == lo_.size() || one_spans(dim, active)) return true;
    // Past the budget every answer is false and run() discards it.
    if (++steps_ > kMaxCoverSteps) return false;
    const auto known = memo_[dim].find(active);
    if (known != memo_[dim].end()) return known->second;
    std::vector<double> cuts = {lo_[dim], hi_[dim]};
    for (std::uint32_t i : active) {
      cuts.push_back(from_[i][dim]);
      cuts.push_back(to_[i][dim]);
    }
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
    bool covered = true;
    std::vector<std::uint32_t> previous;
    for (std::size_t c = 0; c + 1 < cuts.size() && covered; ++c) {
      const double x = cuts[c], y = cuts[c + 1];
      std::vector<std::uint32_t> spanning;
      for (std::uint32_t i : active)
        if (from_[i][dim] <= x && to_[i][dim] >= y) spanning.push_back(i);
      // Neighbouring slabs spanned by the same boxes have the same answer.
      if (!spanning.empty() && spanning == previous) continue;
      covered = sweep(dim + 1, spanning);
      previous = std::move(spanning);
    }
    memo_[dim].emplace(active, covered);
    return covered;
  }

  const std::vector<double>& lo_;
  const std::vector<double>& hi_;
  std::vector<std::vector<double>> from_, to_;
  std::vector<std::map<std::vector<std::uint32_t>, bool>> memo_;
  std::size_t steps_ = 0;
};

}  // namespace

std::optional<bool> box_covered(const std::vector<double>& lo, const std::vector<double>& hi,
                                const std::vector<Box>& boxes, const std::vector<double>& slack) {
  return CoverSweep(lo, hi, boxes, slack).run();
}

}  // namespace amytiss::detail
