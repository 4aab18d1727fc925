#include "bounds/omax/threshold_expectation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bounds/omax/ordered_expectation.hpp"
#include "bounds/omax/threshold_pass.hpp"

namespace amytiss::detail {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr std::size_t kNoPosition = ScanSums::kNoPosition;

// The outcomes of one key next to t with slack: the window's cells of that key and leave or cut.
struct Group {
  double key;
  double slack = 0.0;
  std::size_t rank;  // the last of the group's cells met in the line's order (the start if none)
};

// Calls visit(rank) for the window's ranks from `from` on in direction kDirection (+1: from and up;
// -1: below from, down) until it returns false.
template <int kDirection, typename Visit>
void window_ranks(const SortedLine& line, const PackedWindow& window, std::size_t from, Visit&& visit) {
  if (line.length() > SortedLine::kMaskedLength) {
    for (std::size_t q = kDirection > 0 ? from : from - 1; q < line.length(); q += kDirection)  // wraps below 0
      if (line.order(q) - window.first < window.count && !visit(q)) return;
    return;
  }
  std::uint64_t mask[2];
  line.ranks_of(window.first, window.count, mask);
  if constexpr (kDirection > 0) {
    for (std::size_t word = from / 64; word < 2; ++word) {
      std::uint64_t bits = mask[word] & (word == from / 64 ? ~std::uint64_t(0) << (from % 64) : ~std::uint64_t(0));
      for (; bits; bits &= bits - 1)
        if (!visit(word * 64 + std::size_t(__builtin_ctzll(bits)))) return;
    }
  } else {
    for (std::size_t word = std::min<std::size_t>(from / 64, 1) + 1; word-- > 0;) {
      std::uint64_t bits = mask[word];
      if (word == from / 64) bits &= (std::uint64_t(1) << (from % 64)) - 1;
      for (; bits; bits &= ~(std::uint64_t(1) << (63 - __builtin_clzll(bits))))
        if (!visit(word * 64 + std::size_t(63 - __builtin_clzll(bits)))) return;
    }
  }
}

// The window's next key past t in direction kDirection (+1 up, -1 down) among its outcomes with
// slack, from rank `start` (whose key is t, or, after leave or cut, lies before t); key
// +-infinity where there is none.
template <int kDirection>
Group next_group(const SortedLine& line, const PackedWindow& window, const double* extra_keys, double t,
                 std::size_t start) {
  Group group{kDirection * kInfinity, 0.0, start};
  auto beyond = [](double a, double b) { return kDirection > 0 ? a > b : a < b; };
  // Keys equal to t on the way are passed over. Equal keys hold neighbouring ranks: past the group's
  // cell, the search goes on only while the next rank's key is the group's.
  window_ranks<kDirection>(line, window, kDirection > 0 ? start + 1 : start, [&](std::size_t q) {
    const double key = line.keys()[line.order(q)];
    if (beyond(key, group.key)) return false;
    const std::size_t j = line.order(q) - window.first;
    const double slack = window.hi[j] - window.lo[j];
    if (!(slack > 0.0 && beyond(key, t))) return true;
    group.key = key;
    group.slack += slack;
    group.rank = q;
    const std::size_t next = q + kDirection;  // wraps below 0
    return next < line.length() && line.keys()[line.order(next)] == key;
  });
  const MassInterval extras[2] = {window.leave, window.cut};
  for (std::size_t e = 0; e < 2; ++e) {
    if (!(extras[e].hi > extras[e].lo) || !beyond(extra_keys[e], t) || beyond(extra_keys[e], group.key)) continue;
    if (extra_keys[e] != group.key) group.slack = 0.0;
    group.key = extra_keys[e];
    group.slack += extras[e].hi - extras[e].lo;
  }
  return group;
}

}  // namespace

PackedWindows::PackedWindows(const std::vector<DimensionView>& windows) {
  std::size_t total = 0;
  for (const DimensionView& window : windows) {
    window_sums(window);  // a feasible row, or std::logic_error
    total += PackedWindow::padded(window.count) + kThresholdLanes;
  }
  lo_.assign(total, 0.0);
  hi_.assign(total, 0.0);
  std::size_t offset = 0;
  for (const DimensionView& window : windows) {
    PackedWindow packed{std::uint32_t(window.first), std::uint32_t(window.count), lo_.data() + offset,
                        hi_.data() + offset, window.leave, window.cut, robust_expectation_rounding(window.count + 2)};
    for (std::size_t j = 0; j < window.count; ++j) {
      lo_[offset + j] = window.cells[j].lo;
      hi_[offset + j] = window.cells[j].hi;
    }
    offset += packed.padded_count();
    const MassInterval outcomes[2] = {window.leave, window.cut};
    for (std::size_t e = 0; e < 2; ++e) {
      lo_[offset + e] = outcomes[e].lo;
      hi_[offset + e] = outcomes[e].hi;
    }
    offset += kThresholdLanes;
    views_.push_back(packed);
  }
}

SortedLine::SortedLine(std::size_t length)
    : length_(length),
      keys_(length + kThresholdLanes, 0.0),
      order_(length),
      rank_(length) {
  if (length <= kMaskedLength) rank_bits_.assign((length + 1) * 2, 0);
}

void SortedLine::sort(bool from_last) {
  // Neighbouring lines hold close values, so the last line's order is nearly this one's: insertion
  // from it costs a comparison per key and a move per pair out of order. A line far from the last
  // (more than kMovesPerKey moves per key) is sorted afresh.
  constexpr std::size_t kMovesPerKey = 2;
  bool sorted = false;
  if (from_last && sorted_before_) {
    sorted = true;
    for (std::size_t i = 1, moves = 0; i < length_ && sorted; ++i) {
      const std::uint32_t position = order_[i];
      std::size_t j = i;
      for (; j > 0 && keys_[order_[j - 1]] > keys_[position]; --j) order_[j] = order_[j - 1];
      order_[j] = position;
      moves += i - j;
      sorted = moves <= kMovesPerKey * length_;
    }
  }
  if (sorted)
    for (std::size_t r = 0; r < length_; ++r) rank_[order_[r]] = std::uint32_t(r);
  else
    sort_line(keys_.data(), length_, Bound::Lower, order_.data(), rank_.data());
  sorted_before_ = true;
  if (rank_bits_.empty()) return;
  // Ranks are distinct: the bits of positions first .. last - 1 are prefix(last) minus prefix(first).
  std::uint64_t low = 0, high = 0;  // in registers: not a chain of stores and loads
  for (std::size_t position = 0; position < length_; ++position) {
    const std::size_t r = rank_[position];
    const std::uint64_t bit = std::uint64_t(1) << (r % 64), in_high = -std::uint64_t(r >= 64);
    low |= bit & ~in_high;
    high |= bit & in_high;
    rank_bits_[(position + 1) * 2] = low;
    rank_bits_[(position + 1) * 2 + 1] = high;
  }
}

void SortedLine::ranks_of(std::size_t first, std::size_t count, std::uint64_t* mask) const {
  for (std::size_t word = 0; word < 2; ++word)
    mask[word] = rank_bits_[(first + count) * 2 + word] & ~rank_bits_[first * 2 + word];
}

namespace {

using Opened = ThresholdSearches::Opened;

// The search from its first threshold on in direction kDirection, in keys (the bound's sign applied).
template <int kDirection>
double steps_from(const SortedLine& line, const PackedWindow& window, const ExtraKeys& extra, Opened opened,
                  std::size_t& start, VectorUnit unit) {
  const std::size_t outcomes = window.count + 2;
  // D is linear between neighbouring keys with slack: with slope 1 - above above t, 1 - below
  // below it. Each step moves to the next such key, where D's slope is updated by the key's slack,
  // while D still rises. A step's own rounding: that of the sums behind the slope and of three
  // operations, within the bound for `outcomes` + 2 terms. After more than kStepsInOnePass steps
  // their roundings would add up: D is evaluated afresh where the search ends.
  constexpr std::size_t kStepsInOnePass = 2;
  const double step_rounding = robust_expectation_rounding(outcomes + 2);
  double t = opened.t, best = opened.best, dual = best;
  double slope_weight = kDirection > 0 ? opened.above : opened.below;
  std::size_t steps = 0;  // taken
  while (steps < outcomes) {
    const Group next = next_group<kDirection>(line, window, extra.keys, t, start);
    if (std::abs(next.key) == kInfinity) break;
    dual += (next.key - t) * (1.0 - slope_weight) - step_rounding * (1.0 + slope_weight);
    best = std::max(best, dual);
    t = next.key;
    start = next.rank;
    slope_weight += kDirection * next.slack;
    ++steps;
    if (kDirection > 0 ? slope_weight >= 1.0 : slope_weight <= 1.0) break;
  }
  if (steps > kStepsInOnePass) best = std::max(best, open_search(unit, line.keys(), window, extra, t).best);
  return best;
}

double step_search(const SortedLine& line, const PackedWindow& window, const ExtraKeys& extra, Opened opened,
                   std::size_t& start, VectorUnit unit) {
  const int direction = opened.direction();
  if (direction > 0) return steps_from<1>(line, window, extra, opened, start, unit);
  if (direction < 0) return steps_from<-1>(line, window, extra, opened, start, unit);
  return opened.best;
}

double bound_of_keys(double best, Bound bound) {
  return std::clamp((bound == Bound::Lower ? 1.0 : -1.0) * best, 0.0, 1.0);
}

}  // namespace

double threshold_expectation(const SortedLine& line, const PackedWindow& window, Bound bound, std::size_t& start,
                             VectorUnit unit) {
  const ExtraKeys extra(bound);
  const Opened opened = open_search(unit, line.keys(), window, extra, line.keys()[line.order(start)]);
  return bound_of_keys(step_search(line, window, extra, opened, start, unit), bound);
}

void ThresholdSearches::run(const SortedLine& line, const PackedWindow* const* windows, std::size_t count, Bound bound,
                            std::uint32_t* positions, double* bounds, VectorUnit unit) {
  const ExtraKeys extra(bound);
  opened_.resize(count);
  pending_.resize(count);
  // Every search's first pass, in one loop without a branch on its outcome: the passes of
  // neighbouring searches are independent and overlap. Most searches end there.
  const Moving moving =
      open_searches(unit, line.keys(), windows, count, extra, positions, opened_.data(), pending_.data());
  for (std::size_t s = 0; s < count; ++s) bounds[s] = bound_of_keys(opened_[s].best, bound);
  // Then the searches that move on, up first, then down: one direction at a time.
  auto move_on = [&](auto steps, const std::uint32_t* searches, std::size_t searches_count) {
    for (std::size_t m = 0; m < searches_count; ++m) {
      const std::size_t s = searches[m];
      std::size_t start = line.rank(positions[s]);
      bounds[s] = bound_of_keys(steps(line, *windows[s], extra, opened_[s], start, unit), bound);
      positions[s] = std::uint32_t(line.order(start));
    }
  };
  move_on(steps_from<1>, pending_.data(), moving.up);
  std::reverse(pending_.end() - moving.down, pending_.end());
  move_on(steps_from<-1>, pending_.data() + count - moving.down, moving.down);
}

double threshold_scan(const double* keys, const PackedWindow& window, Bound bound, std::size_t& start,
                      VectorUnit unit) {
  const ExtraKeys extra(bound);
  // Each pass finds D's value and slopes at t and the window's next keys with slack either side;
  // the search moves to the next key while D rises there, which is a fresh pass away.
  ScanSums sums;
  double t = keys[start];
  double best = sound_dual(unit, keys, window, extra, t, sums);
  const int direction = rising_direction(sums.above, sums.below);
  for (std::size_t steps = 0; direction != 0 && steps < window.count + 2; ++steps) {
    const double next = direction > 0 ? sums.up : sums.down;
    const std::size_t position = direction > 0 ? sums.up_position : sums.down_position;
    if (std::abs(next) == kInfinity) break;
    t = next;
    if (position != kNoPosition) start = window.first + position;
    best = std::max(best, sound_dual(unit, keys, window, extra, t, sums));
    if (direction > 0 ? sums.above >= 1.0 : sums.below <= 1.0) break;
  }
  return bound_of_keys(best, bound);
}

}  // namespace amytiss::detail
