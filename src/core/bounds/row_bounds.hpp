#pragma once
// The per-dimension transition bounds of every row (state cell, input, disturbance) of the
// interval MDP of a configuration (docs/semantics.md, "Interval transition bounds"), computed once
// on the host's cores. A dimension's bounds depend only on its mean interval and scale range:
// rows that share them (post coordinates that read few variables) share one entry, computed once.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "bounds/omax/robust_expectation.hpp"
#include "bounds/cell_roles.hpp"
#include "common/parallel_for.hpp"  // the threads RowBounds and its users work on

namespace amytiss::detail {

class RowBounds {
 public:
  /// Bounds of the rows of every cell with needed[cell] true, from mean boxes (state units) of
  /// f(x, u, w) over the cell and the noise's MassBounds per dimension; `threads` workers (>= 1).
  /// reads[d]: the state dimensions that dimension d's mean box (and noise scale) depend on; rows
  /// of cells that agree on them (and on the input and disturbance) share dimension d's bounds
  /// without a new mean box. Empty: every dimension depends on every state dimension.
  RowBounds(const Grid& states, const Grid& inputs, const Grid& disturbances, const NoiseModel& noise,
            const MeanBox& mean_box, const std::vector<bool>& needed, unsigned threads,
            const std::vector<std::vector<std::size_t>>& reads = {});

  /// Row of (cell, input, disturbance); the cell must be one the store was built for.
  std::size_t row(std::size_t cell, std::size_t input, std::size_t disturbance) const {
    return (cell * inputs_ + input) * disturbances_ + disturbance;
  }
  /// Index of the row's bounds of dimension d among distinct_bounds(d) entries.
  std::uint32_t bounds_index(std::size_t row, std::size_t d) const { return index_[row * dims_ + d]; }
  /// The row's bounds, one view per state dimension, written to out[0..dims) (valid while the
  /// store lives).
  void dimensions(std::size_t row, DimensionView* out) const {
    for (std::size_t d = 0; d < dims_; ++d) out[d] = distinct_[d][index_[row * dims_ + d]];
  }
  /// Distinct bounds of dimension d, and one of them.
  std::size_t distinct_bounds(std::size_t d) const { return distinct_[d].size(); }
  const DimensionView& distinct(std::size_t d, std::uint32_t index) const { return distinct_[d][index]; }
  /// The class of the row's bounds of dimensions d..dims-1 (1 <= d < dims): rows of one class
  /// have the same bounds in all of them, so the product set's stages d..dims-1 give them the same
  /// results on the same window line. Classes are numbered 0..suffix_classes(d)-1.
  std::uint32_t suffix_class(std::size_t row, std::size_t d) const {
    return d + 1 == dims_ ? index_[row * dims_ + d] : suffix_class_[row * (dims_ - 2) + d - 1];
  }
  std::size_t suffix_classes(std::size_t d) const { return suffix_classes_[d]; }
  /// What suffix class `suffix_class` of dimension d (1 <= d < dims) is made of: the index of its
  /// bounds of dimension d and its class of dimension d + 1 (0 for the last dimension).
  struct SuffixParts {
    std::uint32_t bounds, next;
  };
  SuffixParts suffix_parts(std::size_t d, std::uint32_t suffix_class) const { return suffix_parts_[d][suffix_class]; }
  /// Mass intervals stored, and bytes in all.
  std::size_t intervals() const { return pool_size_; }
  std::size_t bytes() const;

  /// Whether dimension d is a lattice dimension (bounds/lattice.hpp): noise-free, and every row
  /// sends its cell into one cell; its rows then have the point mass [1, 1] on that cell.
  bool lattice(std::size_t d) const { return lattice_[d]; }

  /// What determines one dimension's bounds: the mean interval, the noise's scale range and, for a
  /// noise-free dimension, the expansion of the map along it (0 for the others).
  struct BoundsKey {
    double m_lo, m_hi, s_lo, s_hi, expansion;
  };

 private:
  // The bounds of each distinct key, once, on `threads` workers; the pool and the views.
  void compute_bounds(const Grid& states, const std::vector<MassBounds>& per_dimension,
                      const std::vector<std::vector<BoundsKey>>& keys, unsigned threads);
  std::size_t dims_, inputs_, disturbances_;
  std::vector<std::uint32_t> index_;                 // [row * dims + d]; rows of unneeded cells: 0
  std::vector<std::vector<DimensionView>> distinct_;  // per dimension
  // [row * (dims - 2) + d - 1] for 1 <= d < dims - 1; the last dimension's classes are its
  // bounds' indices.
  std::vector<std::uint32_t> suffix_class_;
  std::vector<std::size_t> suffix_classes_;           // per dimension (0 for d = 0)
  std::vector<std::vector<SuffixParts>> suffix_parts_;  // per dimension, per class
  void number_suffix_classes(const std::vector<bool>& needed);
  std::vector<MassInterval> pool_;  // the views point into it
  std::vector<bool> lattice_;       // per dimension
  std::size_t pool_size_ = 0;
};

/// The key of dimension d's bounds of a row whose mean interval along d is [lo, hi] (state units),
/// in a cell of index k along d; `expansion`: the map's least expansion along d (0 where the
/// dimension is noisy, so that it does not split keys).
RowBounds::BoundsKey bounds_key(const Grid& states, const MassBounds& mass, std::size_t d, std::size_t k, double lo,
                                double hi, double expansion);
/// Per dimension, how many distinct bounds the rows of every cell have (what RowBounds stores
/// when every cell is needed; at least what it stores for some), from the mean boxes of one cell
/// per combination of the coordinates the dimension reads, on `threads` workers; nothing once a
/// worker meets more than `max_keys`.
std::optional<std::vector<std::size_t>> count_distinct_bounds(const Abstraction& a, const MeanBox& mean_box,
                                                              unsigned threads, std::size_t max_keys);

/// RowBounds' `reads` for an abstraction: per dimension, what its coordinate of the map reads and
/// the dimension itself (the noise's scale may depend on it); empty when the model does not say.
std::vector<std::vector<std::size_t>> bounds_reads(const Abstraction& a);

}  // namespace amytiss::detail
