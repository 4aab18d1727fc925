#include "bounds/omax/threshold_pass.hpp"

#include <cmath>
#include <cstring>
#include <type_traits>

// The pass is the hot loop of the variable elimination: built for AVX2 with FMA as well as for the
// baseline instruction set.
#if defined(__x86_64__) && defined(__GNUC__)
#define AMYTISS_HAS_AVX2_PASS 1
#endif
#pragma GCC diagnostic ignored "-Wpsabi"

namespace amytiss::detail {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr std::size_t kNoPosition = ScanSums::kNoPosition;

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

// What a pass computes: D's value and the weights of its slope either side of t, and with them
// the neighbouring keys.
enum class PassKind { Slopes, Neighbours };
template <PassKind kKind>
using SumsOf = std::conditional_t<kKind == PassKind::Neighbours, ScanSums, PassSums>;

// One block of kThresholdLanes outcomes into D's sums at threshold t; the lanes whose key is above t.
__attribute__((always_inline)) inline LaneMask add_block(Lanes key, Lanes low, Lanes high, Lanes threshold,
                                                         Lanes& above, Lanes& weighted, Lanes& below) {
  const LaneMask over = key > threshold;
  const Lanes weight = select(over, low, high);
  above += weight;
  weighted += weight * key;
  below += select(key < threshold, high, low);
  return over;
}

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
    const LaneMask over = add_block(key, low, high, threshold, above, weighted, below);
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
    add_block(key, low, high, threshold, above, weighted, below);
  }
  SumsOf<kKind> sums;
  sums.above = lane_sum(above);
  sums.weighted = lane_sum(weighted);
  sums.below = lane_sum(below);
  if constexpr (kKind == PassKind::Neighbours)
    for (std::size_t lane = 0; lane < kThresholdLanes; ++lane) {
      if (up[lane] < sums.up) {
        sums.up = up[lane];
        sums.up_position = std::size_t(up_at[lane]);
      }
      if (down[lane] > sums.down) {
        sums.down = down[lane];
        sums.down_position = std::size_t(down_at[lane]);
      }
    }
  return sums;
}

// The unsorted search's pass over a window's cells, one function per instruction set.
ScanSums baseline_scan_pass(const double* keys, const double* lo, const double* hi, std::size_t padded_count,
                            double t) {
  return pass_body<PassKind::Neighbours>(keys, lo, hi, padded_count, t);
}

#ifdef AMYTISS_HAS_AVX2_PASS
__attribute__((target("avx2,fma"))) ScanSums avx2_scan_pass(const double* keys, const double* lo, const double* hi,
                                                            std::size_t padded_count, double t) {
  return pass_body<PassKind::Neighbours>(keys, lo, hi, padded_count, t);
}
#endif

// Leave or cut, one outcome as the unsorted search's pass takes a cell.
void add_outcome(ScanSums& sums, double key, const MassInterval& mass, double t) {
  const double weight = key > t ? mass.lo : mass.hi;
  sums.above += weight;
  sums.weighted += weight * key;
  sums.below += key < t ? mass.hi : mass.lo;
  if (mass.hi > mass.lo && key > t && key < sums.up) {
    sums.up = key;
    sums.up_position = kNoPosition;
  }
  if (mass.hi > mass.lo && key < t && key > sums.down) {
    sums.down = key;
    sums.down_position = kNoPosition;
  }
}

// D(t) from a window's sums (with leave and cut) less its error bound: at most `outcomes` + 2
// roundings of terms whose magnitudes sum to at most |t| + above * (1 + |t|), keys lying in [-1, 1].
__attribute__((always_inline)) inline double dual_less_error(const PackedWindow& window, double t,
                                                             const PassSums& sums) {
  const double error = window.rounding * (1.0 + std::abs(t) + sums.above * (1.0 + std::abs(t)));
  return t * (1.0 - sums.above) + sums.weighted - error;
}

}  // namespace

double sound_dual(VectorUnit unit, const double* keys, const PackedWindow& window, const ExtraKeys& extra, double t,
                  ScanSums& sums) {
  const double* cells = keys + window.first;
#ifdef AMYTISS_HAS_AVX2_PASS
  if (unit == VectorUnit::Avx2)
    sums = avx2_scan_pass(cells, window.lo, window.hi, window.padded_count(), t);
  else
#endif
    sums = baseline_scan_pass(cells, window.lo, window.hi, window.padded_count(), t);
  add_outcome(sums, extra.keys[0], window.leave, t);
  add_outcome(sums, extra.keys[1], window.cut, t);
  return dual_less_error(window, t, sums);
}

namespace {

using Opened = ThresholdSearches::Opened;

// A search's pass at threshold t; inlined into one function per instruction set, which the batch's
// loop and the single search share (the same roundings).
__attribute__((always_inline)) inline Opened open_body(const double* keys, const PackedWindow& window,
                                                       const double* extra_keys, double t) {
  const PassSums sums =
      pass_body<PassKind::Slopes>(keys + window.first, window.lo, window.hi, window.padded_count(), t, extra_keys);
  return {t, dual_less_error(window, t, sums), sums.above, sums.below};
}

// Every search's first pass, and the searches that move on: those that move up at the front of
// `moving` and those that move down at its back, each in order. No branch on a search's outcome.
__attribute__((always_inline)) inline Moving open_all_body(const double* keys, const PackedWindow* const* windows,
                                                           std::size_t count, const double* extra_keys,
                                                           const std::uint32_t* positions, Opened* opened,
                                                           std::uint32_t* moving) {
  Moving counts;
  for (std::size_t s = 0; s < count; ++s) {
    opened[s] = open_body(keys, *windows[s], extra_keys, keys[positions[s]]);
    const int direction = opened[s].direction();
    moving[counts.up] = std::uint32_t(s);
    moving[count - 1 - counts.down] = std::uint32_t(s);  // the same slot only when both hold s
    counts.up += direction > 0;
    counts.down += direction < 0;
  }
  return counts;
}

Opened baseline_open(const double* keys, const PackedWindow& window, const double* extra_keys, double t) {
  return open_body(keys, window, extra_keys, t);
}

Moving baseline_open_all(const double* keys, const PackedWindow* const* windows, std::size_t count,
                         const double* extra_keys, const std::uint32_t* positions, Opened* opened,
                         std::uint32_t* moving) {
  return open_all_body(keys, windows, count, extra_keys, positions, opened, moving);
}

#ifdef AMYTISS_HAS_AVX2_PASS
__attribute__((target("avx2,fma"))) Opened avx2_open(const double* keys, const PackedWindow& window,
                                                     const double* extra_keys, double t) {
  return open_body(keys, window, extra_keys, t);
}

__attribute__((target("avx2,fma"))) Moving avx2_open_all(const double* keys, const PackedWindow* const* windows,
                                                         std::size_t count, const double* extra_keys,
                                                         const std::uint32_t* positions, Opened* opened,
                                                         std::uint32_t* moving) {
  return open_all_body(keys, windows, count, extra_keys, positions, opened, moving);
}
#endif

}  // namespace

ThresholdSearches::Opened open_search(VectorUnit unit, const double* keys, const PackedWindow& window,
                                      const ExtraKeys& extra, double t) {
#ifdef AMYTISS_HAS_AVX2_PASS
  if (unit == VectorUnit::Avx2) return avx2_open(keys, window, extra.keys, t);
#endif
  return baseline_open(keys, window, extra.keys, t);
}

Moving open_searches(VectorUnit unit, const double* keys, const PackedWindow* const* windows, std::size_t count,
                     const ExtraKeys& extra, const std::uint32_t* positions, ThresholdSearches::Opened* opened,
                     std::uint32_t* moving) {
#ifdef AMYTISS_HAS_AVX2_PASS
  if (unit == VectorUnit::Avx2) return avx2_open_all(keys, windows, count, extra.keys, positions, opened, moving);
#endif
  return baseline_open_all(keys, windows, count, extra.keys, positions, opened, moving);
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

}  // namespace amytiss::detail
