#pragma once
// The O-maximisation by its threshold, for many windows over one line (the variable elimination).
// With keys k_j = value_j (lower bound) or -value_j (upper), the minimum of sum_j p_j k_j over
// lo <= p <= hi, sum_j p_j = 1 equals, by linear-programming duality,
//   max over t of  D(t) = t + sum_j (k_j - t) * (k_j > t ? lo_j : hi_j),
// and D(t) is at most that minimum for every t. The maximiser is the key at which
// robust_expectation()'s filling runs out of budget. A search from a guess (where the search of
// a neighbouring window ended) evaluates D there in one vectorised pass over the window, then
// steps from key to key of the window in the line's sorted order, D and its slope updated as it
// goes, until the slope changes sign; whichever threshold it ends on, the bound is sound. The
// result equals robust_expectation()'s up to rounding, each moved outward by its own error bound.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "bounds/omax/robust_expectation.hpp"

namespace amytiss::detail {

/// Cells per iteration of the search's pass; windows are padded with zero intervals to a multiple of it.
constexpr std::size_t kThresholdLanes = 4;

/// A window as the search reads it: cells first .. first + count - 1 of the line, their lower and
/// upper bounds in two arrays of padded_count() entries (zeros past count) followed by a block of
/// kThresholdLanes entries (leave, cut, zeros), then leave and cut, and the relative rounding of a
/// sum over its count + 2 outcomes (robust_expectation_rounding()).
struct PackedWindow {
  std::uint32_t first = 0, count = 0;
  const double* lo = nullptr;
  const double* hi = nullptr;
  MassInterval leave, cut;
  double rounding = 0.0;
  std::size_t padded_count() const { return padded(count); }
  static std::size_t padded(std::size_t count) {
    return (count + kThresholdLanes - 1) / kThresholdLanes * kThresholdLanes;
  }
};

/// The windows of one dimension, packed (views into storage the object owns; not copyable).
class PackedWindows {
 public:
  explicit PackedWindows(const std::vector<DimensionView>& windows);
  PackedWindows(const PackedWindows&) = delete;
  PackedWindows& operator=(const PackedWindows&) = delete;
  PackedWindows(PackedWindows&&) = default;
  const PackedWindow& operator[](std::size_t k) const { return views_[k]; }
  std::size_t size() const { return views_.size(); }

 private:
  std::vector<double> lo_, hi_;
  std::vector<PackedWindow> views_;
};

/// One line of keys (value for Bound::Lower, -value for Bound::Upper; values in [0, 1]) as the
/// search reads it: the keys, padded with kThresholdLanes zeros; their increasing order; and, for
/// lines up to kMaskedLength long, the ranks of the positions before each position as bits, so
/// that a window's ranks are two lookups.
class SortedLine {
 public:
  static constexpr std::size_t kMaskedLength = 128;
  explicit SortedLine(std::size_t length);
  std::size_t length() const { return length_; }
  /// The keys: write keys()[0..length()) before sort().
  double* keys() { return keys_.data(); }
  const double* keys() const { return keys_.data(); }
  /// Sorts the keys and builds the tables: from the order of the line sorted before (a
  /// neighbour: faster; ties then keep that order), or afresh (ties in position order).
  void sort(bool from_last);
  /// The position of rank r, the rank of a position.
  std::size_t order(std::size_t r) const { return order_[r]; }
  std::size_t rank(std::size_t position) const { return rank_[position]; }
  /// Lines up to kMaskedLength long: the ranks of positions first .. first + count - 1 as bits of
  /// two words.
  void ranks_of(std::size_t first, std::size_t count, std::uint64_t* mask) const;

 private:
  std::size_t length_;
  bool sorted_before_ = false;
  std::vector<double> keys_;
  std::vector<std::uint32_t> order_, rank_;
  std::vector<std::uint64_t> rank_bits_;  // [position * 2 + word]: ranks of positions before it
};

/// The instructions of the search's vectorised pass: the baseline's, or AVX2 with FMA (x86-64).
enum class VectorUnit { Baseline, Avx2 };
/// The widest unit this processor has; every unit it can run (the tests take each).
VectorUnit widest_vector_unit();
std::vector<VectorUnit> vector_units();

/// The bound of one window over a sorted line: robust_expectation()'s up to rounding, moved
/// outward by its error bound and clipped to [0, 1]. `start`: the rank whose key the search starts
/// from on entry, where it ended on return (a good start for an overlapping window). `unit`: one of
/// vector_units(); every unit gives the same bound up to the order of additions.
double threshold_expectation(const SortedLine& line, const PackedWindow& window, Bound bound, std::size_t& start,
                             VectorUnit unit);

/// Where D still rises from a threshold whose slope weights are `above` (just above it) and `below`
/// (just below): +1 above, -1 below, 0 neither (the threshold is the maximiser).
inline int rising_direction(double above, double below) { return above < 1.0 ? 1 : below > 1.0 ? -1 : 0; }

/// threshold_expectation() of many windows over one line, the same bounds bit for bit: every search
/// first evaluates D where it starts, all in one loop (independent passes overlap), and those
/// that must move then step on. Holds its working storage (one object per thread).
class ThresholdSearches {
 public:
  /// A search after its first pass: the threshold t (a key), D(t) less its error bound, and the
  /// weights of D's slope just above and just below t.
  struct Opened {
    double t, best, above, below;
    int direction() const { return rising_direction(above, below); }
  };
  /// `windows[0..count)`; `positions[i]`: the position (not the rank) of the cell whose key search i
  /// starts from, on return where it ended; `bounds[i]`: its bound.
  void run(const SortedLine& line, const PackedWindow* const* windows, std::size_t count, Bound bound,
           std::uint32_t* positions, double* bounds, VectorUnit unit);

 private:
  std::vector<Opened> opened_;
  std::vector<std::uint32_t> pending_;
};

/// The same bound without a sorted line, for lines that few windows read (a sort would cost more
/// than it saves): each step is a pass over the window. `keys`: the line's keys (as SortedLine
/// holds them) followed by kThresholdLanes readable entries. `start`: the position whose key the
/// search starts from on entry, on return the position of the last cell it stepped to (unchanged
/// when none).
double threshold_scan(const double* keys, const PackedWindow& window, Bound bound, std::size_t& start,
                      VectorUnit unit);

}  // namespace amytiss::detail
