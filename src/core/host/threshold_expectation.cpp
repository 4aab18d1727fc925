#include "host/threshold_expectation.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "host/ordered_expectation.hpp"

// The pass is the hot loop of the variable elimination: built for AVX2 with FMA as well as for the
// baseline instruction set.
#if defined(__x86_64__) && defined(__GNUC__)
#define AMYTISS_HAS_AVX2_PASS 1
#endif
#pragma GCC diagnostic ignored "-Wpsabi"

namespace amytiss::detail {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr std::size_t kNoPosition = ~std::size_t(0);

typedef double Lanes __attribute__((vector_size(kThresholdLanes * sizeof(double))));
typedef long LaneMask __attribute__((vector_size(kThresholdLanes * sizeof(double))));

// mask ? a : b lane by lane, in bit operations: GCC turns a vector ?: into scalar code. Always
// inlined into the passes, so the baseline's ABI for vector arguments never applies (the -Wpsabi
// note, which GCC gives at the end of the file, is switched off above).
__attribute__((always_inline)) inline Lanes select(LaneMask mask, Lanes a, Lanes b) {
  return reinterpret_cast<Lanes>((mask & reinterpret_cast<LaneMask>(a)) | (~mask & reinterpret_cast<LaneMask>(b)));
}

__attribute__((always_inline)) inline LaneMask select(LaneMask mask, LaneMask a, LaneMask b) {
  return (mask & a) | (~mask & b);
}

// The sum of the lanes, pairwise (halves, then their two lanes: few instructions, short latency).
__attribute__((always_inline)) inline double lane_sum(Lanes lanes) {
  typedef double Pair __attribute__((vector_size(2 * sizeof(double))));
  const Pair halves = Pair{lanes[0], lanes[1]} + Pair{lanes[2], lanes[3]};
  return halves[0] + halves[1];
}

// D at threshold t over a window, D(t) = t (1 - above) + weighted, and the weights of its slope
// on either side of t.
struct PassSums {
  double above = 0.0;     // sum of (key > t ? lo : hi): 1 - D's slope just above t; D's weights
  double weighted = 0.0;  // sum of key * (key > t ? lo : hi)
  double below = 0.0;     // sum of (key < t ? hi : lo): 1 - D's slope just below t
};
// And the nearest keys with slack above and below t (+-infinity: none), with the position of one
// cell of each in the window (kNoPosition: none, or leave or cut). Apart: the sorted search's
// passes return the smaller struct.
struct ScanSums : PassSums {
  double up = kInfinity, down = -kInfinity;
  std::size_t up_position = kNoPosition, down_position = kNoPosition;
};

// What a pass computes: D's value and the weights of its slope either side of t, and with them
// the neighbouring keys.
enum class PassKind { Slopes, Neighbours };
template <PassKind kKind>
using SumsOf = std::conditional_t<kKind == PassKind::Neighbours, ScanSums, PassSums>;

// The pass's body, inlined into one function per instruction set.
template <PassKind kKind>
__attribute__((always_inline)) inline SumsOf<kKind> pass_body(const double* keys, const double* lo, const double* hi,
                                                               std::size_t padded_count, double t,
                                                               const double* outcome_keys = nullptr) {
  const Lanes threshold = Lanes{} + t;
  Lanes above{}, weighted{}, below{}, up = Lanes{} + kInfinity, down = Lanes{} - kInfinity;
  LaneMask position = {0, 1, 2, 3}, up_at = LaneMask{} - 1, down_at = LaneMask{} - 1;
  static_assert(kThresholdLanes == 4, "one position per lane");
  for (std::size_t j = 0; j < padded_count; j += kThresholdLanes, position += long(kThresholdLanes)) {
    Lanes key, low, high;
    std::memcpy(&key, keys + j, sizeof key);
    std::memcpy(&low, lo + j, sizeof low);
    std::memcpy(&high, hi + j, sizeof high);
    const LaneMask over = key > threshold;
    const Lanes weight = select(over, low, high);
    above += weight;
    weighted += weight * key;
    below += select(key < threshold, high, low);
    if constexpr (kKind == PassKind::Neighbours) {
      const LaneMask under = key < threshold;
      const LaneMask slack = high > low;
      const LaneMask nearer_up = over & slack & (key < up), nearer_down = under & slack & (key > down);
      up = select(nearer_up, key, up);
      up_at = select(nearer_up, position, up_at);
      down = select(nearer_down, key, down);
      down_at = select(nearer_down, position, down_at);
    }
  }
  if (outcome_keys) {  // leave and cut as one more block: the window's after its padded cells
    Lanes key, low, high;
    std::memcpy(&key, outcome_keys, sizeof key);
    std::memcpy(&low, lo + padded_count, sizeof low);
    std::memcpy(&high, hi + padded_count, sizeof high);
    const Lanes weight = select(key > threshold, low, high);
    above += weight;
    weighted += weight * key;
    below += select(key < threshold, high, low);
  }
  SumsOf<kKind> sums;
  sums.above = lane_sum(above);
  sums.weighted = lane_sum(weighted);
  sums.below = lane_sum(below);
  for (std::size_t lane = 0; lane < kThresholdLanes; ++lane) {
    if constexpr (kKind == PassKind::Neighbours) {
      if (up[lane] < sums.up) {
        sums.up = up[lane];
        sums.up_position = std::size_t(up_at[lane]);
      }
      if (down[lane] > sums.down) {
        sums.down = down[lane];
        sums.down_position = std::size_t(down_at[lane]);
      }
    }
  }
  return sums;
}

template <PassKind kKind>
SumsOf<kKind> baseline_pass(const double* keys, const double* lo, const double* hi, std::size_t padded_count,
                            double t) {
  return pass_body<kKind>(keys, lo, hi, padded_count, t);
}

#ifdef AMYTISS_HAS_AVX2_PASS
template <PassKind kKind>
__attribute__((target("avx2,fma"))) SumsOf<kKind> avx2_pass(const double* keys, const double* lo, const double* hi,
                                                            std::size_t padded_count, double t) {
  return pass_body<kKind>(keys, lo, hi, padded_count, t);
}
#endif

template <PassKind kKind>
SumsOf<kKind> cells_pass(VectorUnit unit, const double* keys, const double* lo, const double* hi,
                         std::size_t padded_count, double t) {
#ifdef AMYTISS_HAS_AVX2_PASS
  if (unit == VectorUnit::Avx2) return avx2_pass<kKind>(keys, lo, hi, padded_count, t);
#endif
  return baseline_pass<kKind>(keys, lo, hi, padded_count, t);
}

// Leave or cut, one outcome as the pass takes a cell.
template <typename Sums>
__attribute__((always_inline)) inline void add_outcome(Sums& sums, double key, const MassInterval& mass, double t) {
  const double weight = key > t ? mass.lo : mass.hi;
  sums.above += weight;
  sums.weighted += weight * key;
  sums.below += key < t ? mass.hi : mass.lo;
  if constexpr (std::is_same_v<Sums, ScanSums>) {
    if (mass.hi > mass.lo && key > t && key < sums.up) {
      sums.up = key;
      sums.up_position = kNoPosition;
    }
    if (mass.hi > mass.lo && key < t && key > sums.down) {
      sums.down = key;
      sums.down_position = kNoPosition;
    }
  }
}

// D(t) from a window's sums (with leave and cut) less its error bound: at most `outcomes` + 2
// roundings of terms whose magnitudes sum to at most |t| + above * (1 + |t|), keys lying in [-1, 1].
__attribute__((always_inline)) inline double dual_less_error(const PackedWindow& window, double t,
                                                             const PassSums& sums) {
  const double error =
      window.rounding * (1.0 + std::abs(t) + sums.above * (1.0 + std::abs(t)));
  return t * (1.0 - sums.above) + sums.weighted - error;
}

// D(t) of a window over keys[window.first ..] less its error bound.
template <PassKind kKind>
double sound_dual(VectorUnit unit, const double* keys, const PackedWindow& window, const double* extra_keys, double t,
                  SumsOf<kKind>& sums) {
  sums = cells_pass<kKind>(unit, keys + window.first, window.lo, window.hi, window.padded_count(), t);
  add_outcome(sums, extra_keys[0], window.leave, t);
  add_outcome(sums, extra_keys[1], window.cut, t);
  return dual_less_error(window, t, sums);
}

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

VectorUnit widest_vector_unit() {
#ifdef AMYTISS_HAS_AVX2_PASS
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return VectorUnit::Avx2;
#endif
  return VectorUnit::Baseline;
}

std::vector<VectorUnit> vector_units() {
  std::vector<VectorUnit> units{VectorUnit::Baseline};
  if (widest_vector_unit() == VectorUnit::Avx2) units.push_back(VectorUnit::Avx2);
  return units;
}

namespace {

// The keys of leave and cut for a bound.
struct ExtraKeys {
  explicit ExtraKeys(Bound bound) : keys{0.0, (bound == Bound::Lower ? 1.0 : -1.0) * cut_value(bound), 0.0, 0.0} {}
  double keys[kThresholdLanes];  // leave, cut, then zeros: the lanes of the window's outcome block
};

using Opened = ThresholdSearches::Opened;

// A search's first pass, at the key of `position`; inlined into one function per instruction set,
// which the batch's loop and the single search share (the same roundings).
__attribute__((always_inline)) inline Opened open_body(const double* keys, const PackedWindow& window,
                                                       const double* extra_keys, std::size_t position) {
  const double t = keys[position];
  const PassSums sums =
      pass_body<PassKind::Slopes>(keys + window.first, window.lo, window.hi, window.padded_count(), t, extra_keys);
  return {t, dual_less_error(window, t, sums), sums.above, sums.below};
}

// The searches that move on after their first pass: up (ranks rising) and down.
struct Moving {
  std::size_t up = 0, down = 0;
};

// Every search's first pass, and the searches that move on: those that move up at the front of
// `moving` and those that move down at its back, each in order. No branch on a search's outcome.
__attribute__((always_inline)) inline Moving open_all_body(const double* keys, const PackedWindow* const* windows,
                                                                std::size_t count, const double* extra_keys,
                                                                const std::uint32_t* positions, Opened* opened,
                                                                std::uint32_t* moving) {
  Moving counts;
  for (std::size_t s = 0; s < count; ++s) {
    opened[s] = open_body(keys, *windows[s], extra_keys, positions[s]);
    const int direction = opened[s].direction();
    moving[counts.up] = std::uint32_t(s);
    moving[count - 1 - counts.down] = std::uint32_t(s);  // the same slot only when both hold s
    counts.up += direction > 0;
    counts.down += direction < 0;
  }
  return counts;
}

Opened baseline_open(const double* keys, const PackedWindow& window, const double* extra_keys, std::size_t position) {
  return open_body(keys, window, extra_keys, position);
}

Moving baseline_open_all(const double* keys, const PackedWindow* const* windows, std::size_t count,
                              const double* extra_keys, const std::uint32_t* positions, Opened* opened,
                              std::uint32_t* moving) {
  return open_all_body(keys, windows, count, extra_keys, positions, opened, moving);
}

#ifdef AMYTISS_HAS_AVX2_PASS
__attribute__((target("avx2,fma"))) Opened avx2_open(const double* keys, const PackedWindow& window,
                                                     const double* extra_keys, std::size_t position) {
  return open_body(keys, window, extra_keys, position);
}

__attribute__((target("avx2,fma"))) Moving avx2_open_all(const double* keys, const PackedWindow* const* windows,
                                                              std::size_t count, const double* extra_keys,
                                                              const std::uint32_t* positions, Opened* opened,
                                                              std::uint32_t* moving) {
  return open_all_body(keys, windows, count, extra_keys, positions, opened, moving);
}
#endif

Opened open_search(const SortedLine& line, const PackedWindow& window, const ExtraKeys& extra, std::size_t start,
                   VectorUnit unit) {
#ifdef AMYTISS_HAS_AVX2_PASS
  if (unit == VectorUnit::Avx2) return avx2_open(line.keys(), window, extra.keys, line.order(start));
#endif
  return baseline_open(line.keys(), window, extra.keys, line.order(start));
}

Moving open_searches(const SortedLine& line, const PackedWindow* const* windows, std::size_t count,
                          const ExtraKeys& extra, const std::uint32_t* positions, Opened* opened,
                          std::uint32_t* moving, VectorUnit unit) {
#ifdef AMYTISS_HAS_AVX2_PASS
  if (unit == VectorUnit::Avx2)
    return avx2_open_all(line.keys(), windows, count, extra.keys, positions, opened, moving);
#endif
  return baseline_open_all(line.keys(), windows, count, extra.keys, positions, opened, moving);
}

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
  if (steps > kStepsInOnePass) {
    PassSums sums;
    best = std::max(best, sound_dual<PassKind::Slopes>(unit, line.keys(), window, extra.keys, t, sums));
  }
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
  return bound_of_keys(step_search(line, window, extra, open_search(line, window, extra, start, unit), start, unit),
                       bound);
}

void ThresholdSearches::run(const SortedLine& line, const PackedWindow* const* windows, std::size_t count, Bound bound,
                            std::uint32_t* positions, double* bounds, VectorUnit unit) {
  const ExtraKeys extra(bound);
  opened_.resize(count);
  pending_.resize(count);
  // Every search's first pass, in one loop without a branch on its outcome: the passes of
  // neighbouring searches are independent and overlap. Most searches end there.
  const Moving moving = open_searches(line, windows, count, extra, positions, opened_.data(), pending_.data(), unit);
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
  const double sign = bound == Bound::Lower ? 1.0 : -1.0;
  const double extra_keys[2] = {0.0, sign * cut_value(bound)};  // leave, cut
  // Each pass finds D's value and slopes at t and the window's next keys with slack either side;
  // the search moves to the next key while D rises there, which is a fresh pass away.
  ScanSums sums;
  double t = keys[start];
  double best = sound_dual<PassKind::Neighbours>(unit, keys, window, extra_keys, t, sums);
  const int direction = sums.above < 1.0 ? 1 : sums.below > 1.0 ? -1 : 0;
  for (std::size_t steps = 0; direction != 0 && steps < window.count + 2; ++steps) {
    const double next = direction > 0 ? sums.up : sums.down;
    const std::size_t position = direction > 0 ? sums.up_position : sums.down_position;
    if (std::abs(next) == kInfinity) break;
    t = next;
    if (position != kNoPosition) start = window.first + position;
    best = std::max(best, sound_dual<PassKind::Neighbours>(unit, keys, window, extra_keys, t, sums));
    if (direction > 0 ? sums.above >= 1.0 : sums.below <= 1.0) break;
  }
  return std::clamp(sign * best, 0.0, 1.0);
}

}  // namespace amytiss::detail
