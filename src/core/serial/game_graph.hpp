#pragma once
// The support structure of the abstraction seen as a game (the controller picks u, the
// disturbance w, then the noise moves the state), for interval iteration's precomputations:
// which cells each row can reach, which rows lose mass (off the grid or cut), attractors and
// end components. Rows are the (Free cell, input, disturbance) triples.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "amytiss/abstraction.hpp"

namespace amytiss::detail {

class GameSupports {
 public:
  /// Computes every row's support: per dimension the first and last cell of non-zero mass (the
  /// support of a separable row is that box; for a full covariance, its window), and whether the
  /// row loses mass (off the grid or to the truncation: the row "leaks"), decided from the noise
  /// law's support against the box's cells (NoiseModel::unit_support), never from a sum of masses.
  explicit GameSupports(const Abstraction& abstraction);

  std::size_t free_cells() const { return free_list_.size(); }
  std::size_t free_cell(std::size_t rank) const { return free_list_[rank]; }
  std::size_t inputs() const { return inputs_; }
  std::size_t disturbances() const { return disturbances_; }
  std::size_t row(std::size_t rank, std::size_t input, std::size_t disturbance) const {
    return (rank * inputs_ + input) * disturbances_ + disturbance;
  }
  bool leaks(std::size_t row) const { return leaks_[row] != 0; }
  bool empty(std::size_t row) const { return empty_[row] != 0; }
  /// first[d], last[d] of the row's box (valid when !empty(row)).
  const std::uint32_t* box(std::size_t row) const { return &boxes_[row * 2 * dims_]; }
  /// Calls visit(cell) for every cell of the row's box, in ascending flat order.
  void for_each_cell(std::size_t row, const std::function<void(std::size_t)>& visit) const;
  /// Number of cells with member[cell] != 0 in the row's box, in O(2^dims) after set_members().
  void set_members(const std::vector<char>& member);
  std::size_t members_in(std::size_t row) const;
  std::size_t box_cells(std::size_t row) const;

 private:
  const Abstraction& a_;
  std::size_t dims_, inputs_, disturbances_;
  std::vector<std::size_t> free_list_;
  std::vector<std::uint32_t> boxes_;
  std::vector<char> leaks_, empty_;
  std::vector<std::size_t> prefix_strides_;
  std::vector<std::uint32_t> prefix_;  // inclusive prefix counts over the grid, shifted by one
};

/// Reachability and reach-avoid: cells from which the controller can make reaching the target
/// possible (positive probability) whatever the disturbance: the target, and every Free cell with
/// an input whose every disturbance's row reaches a cell already in the set. Outside it the
/// value is 0.
std::vector<char> positive_attractor(const Abstraction& abstraction, GameSupports& supports);

/// Safety: the Free cells from which the controller can stay among them with probability 1
/// (an input whose every disturbance's row neither leaks nor leaves the set), and that input.
/// There the value is 1.
std::vector<char> sure_safe_set(const Abstraction& abstraction, GameSupports& supports,
                                std::vector<std::uint32_t>& sure_input);

/// End components among the cells with candidate[cell] != 0: sets of cells in which the players,
/// using only allowed inputs and disturbances whose rows neither leak nor leave the set, can keep
/// the play forever, and which are strongly connected under those rows. Returns the component
/// of each cell (-1: none); a row "stays" in a component when it does not leak and its box lies
/// in it.
using InputFilter = std::function<bool(std::size_t cell, std::size_t input)>;
using RowFilter = std::function<bool(std::size_t cell, std::size_t input, std::size_t disturbance)>;
std::vector<std::int64_t> end_components(const GameSupports& supports, std::size_t cells,
                                         const std::vector<char>& candidate, const InputFilter& input_allowed,
                                         const RowFilter& row_allowed);
/// Whether the row (rank, input, disturbance) stays in the component of its cell.
bool row_stays(const GameSupports& supports, const std::vector<std::int64_t>& component, std::size_t rank,
               std::size_t input, std::size_t disturbance);

}  // namespace amytiss::detail
