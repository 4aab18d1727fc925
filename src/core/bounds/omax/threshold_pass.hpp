#pragma once
// The threshold search's vectorised pass over a window (bounds/omax/threshold_expectation.hpp): D at a
// threshold t, D(t) = t (1 - above) + weighted, with the weights of its slope either side of t
// and, for the unsorted search, the window's nearest keys with slack either side. Built for AVX2
// with FMA as well as for the baseline instruction set; every unit gives the same sums up to the
// order of additions.
#include <cstddef>
#include <cstdint>
#include <limits>

#include "bounds/omax/threshold_expectation.hpp"

namespace amytiss::detail {

/// D at threshold t over a window, D(t) = t (1 - above) + weighted, and the weights of its slope
/// on either side of t.
struct PassSums {
  double above = 0.0;     // sum of (key > t ? lo : hi): 1 - D's slope just above t; D's weights
  double weighted = 0.0;  // sum of key * (key > t ? lo : hi)
  double below = 0.0;     // sum of (key < t ? hi : lo): 1 - D's slope just below t
};
/// And the nearest keys with slack above and below t (+-infinity: none), with the position of one
/// cell of each in the window (kNoPosition: none, or leave or cut). Apart: the sorted search's
/// passes return the smaller struct.
struct ScanSums : PassSums {
  static constexpr std::size_t kNoPosition = ~std::size_t(0);
  double up = std::numeric_limits<double>::infinity(), down = -std::numeric_limits<double>::infinity();
  std::size_t up_position = kNoPosition, down_position = kNoPosition;
};

/// The keys of leave and cut for a bound, then zeros: the lanes of a window's outcome block.
struct ExtraKeys {
  explicit ExtraKeys(Bound bound) : keys{0.0, (bound == Bound::Lower ? 1.0 : -1.0) * cut_value(bound), 0.0, 0.0} {}
  double keys[kThresholdLanes];
};

/// D(t) of a window over keys[window.first ..] (with leave and cut, keys extra.keys[0..1]) less its
/// error bound, with the sums behind it and the nearest keys (the unsorted search's pass).
double sound_dual(VectorUnit unit, const double* keys, const PackedWindow& window, const ExtraKeys& extra, double t,
                  ScanSums& sums);

/// A sorted search's pass at threshold t (a key of the line `keys`, or of leave or cut).
ThresholdSearches::Opened open_search(VectorUnit unit, const double* keys, const PackedWindow& window,
                                      const ExtraKeys& extra, double t);

/// The searches that move on after their first pass: up (ranks rising) and down.
struct Moving {
  std::size_t up = 0, down = 0;
};

/// Every search's first pass (windows[i] from the key of position positions[i]), in one loop
/// without a branch on a search's outcome, with the same roundings as open_search(); the searches
/// that move on: those that move up at the front of `moving` (count entries), those that move down
/// at its back, each in order.
Moving open_searches(VectorUnit unit, const double* keys, const PackedWindow* const* windows, std::size_t count,
                     const ExtraKeys& extra, const std::uint32_t* positions, ThresholdSearches::Opened* opened,
                     std::uint32_t* moving);

}  // namespace amytiss::detail
