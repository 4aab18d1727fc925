#pragma once
// The product (orthogonally decoupled) bound of every (state cell, input, disturbance) of the
// interval MDP by variable elimination along the dynamics' dependency graph, in the elimination
// order and tensor layouts of the factored sweep's plan (host/factored_plan.hpp):
//   W_0 = V,   W_k[remaining post cells, U_k] = O-max over a in window(e_k | tuple) of W_{k-1}[..., a, ...],
// where the window and its interval masses are post dimension e_k's for the tuple of components
// e_k reads (the bounds of any row with those components: host/row_bounds.hpp), leave worth 0 and
// cut worth cut_value(bound), and Q = W_d holds every (cell, input, disturbance)'s bound. Each line
// of W_{k-1} is read once and every tuple applied to it by a threshold search; tuples that read
// the same window (a linear map on the grid gives many cells one mean) share one search. A line
// that feeds many searches is sorted first and searched in one batch (ThresholdSearches), one that
// feeds few is not (threshold_scan()); each search starts where the search of the window in the
// same place ended on the line before. The tensors are laid out for this (FactoredLayout::Lines): a line's results
// are written side by side.
//
// This is the product set's recursive bound in the order e_1..e_d: sound in every order (each
// stage may pick its distribution per remaining cell, a superset of the product set), and equal,
// up to rounding, to product_expectation_in_order() of each row in the same order. It pays where
// coordinates read few components (building automation: 7 dimensions, each reading 2 to 4), where
// the row-by-row product bound recomputes the same lines for every row.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "host/interval_bellman.hpp"
#include "host/product_sweep.hpp"
#include "host/row_bounds.hpp"
#include "host/factored_plan.hpp"
#include "host/threshold_expectation.hpp"

namespace amytiss::detail {

class RobustFactoredSweep {
 public:
  /// At most this many bytes for the tensors, Q and the mass tables (half of it for one tensor).
  static constexpr double kMaxBytes = 2.0 * (1 << 30);
  /// How a stage searches its lines. Auto: stages whose lines feed at least kSearchesWorthASort
  /// searches sort each line (ThresholdSearches), the others search unsorted lines
  /// (threshold_scan()); Sorted and Scan: every stage so (the same bounds up to rounding).
  enum class LineSearch { Auto, Sorted, Scan };
  static constexpr std::size_t kSearchesWorthASort = 16;
  /// The factored sweep's plan for these bounds, or nullopt with the reason: no plan (dynamics
  /// without dependencies, full covariance), or one that needs slices (an O-maximisation needs
  /// its whole line) or more than kMaxBytes.
  static std::optional<FactoredPlan> plan(const Abstraction& abstraction, std::string* reason);
  /// `rows` must hold the rows of every cell with `has_rows` true; `plan` from plan(). `buffers`
  /// (the stage tensors): shared with sweeps that never run at the same time as this one; null:
  /// its own.
  RobustFactoredSweep(const Abstraction& abstraction, const RowBounds& rows, const std::vector<bool>& has_rows,
                      FactoredPlan plan, Bound bound, unsigned threads,
                      std::shared_ptr<SweepBuffers> buffers = nullptr, LineSearch search = LineSearch::Auto);
  /// Every stage over `values` (one per state cell, flat): Q.
  void prepare(const double* values);
  /// The bound of row (cell, input, disturbance) over the values of the last prepare().
  double expectation(std::size_t cell, std::size_t input, std::size_t disturbance) const {
    return q_[cell_offset_[cell] + input_offset_[input] + disturbance_offset_[disturbance]];
  }
  /// The elimination order e_1..e_d (post dimensions).
  const std::vector<std::size_t>& order() const { return plan_.order; }
  /// Searches per line of stage k: one per distinct window that the line's tuples read.
  std::size_t searches_per_line(std::size_t k) const {
    return walks_[k].search_of.empty() ? walks_[k].free_tuples.size() : walks_[k].searched.size();
  }

 private:
  // A stage's output digits split by what they do: those the input has name the line an entry
  // reads; the others enumerate the tuples applied to that line (row-major, as the output).
  struct StageWalk {
    struct Carried {
      std::size_t radix, input_stride, output_stride, tuple_stride;
      bool jumps;  // an input or disturbance
    };
    // The lines' odometer, fastest first: by increasing input stride, inputs and disturbances last.
    std::vector<Carried> carried;
    std::vector<std::size_t> free_offsets, free_tuples;  // per combination of the other digits
    // When no line digit picks the window (every line applies the same windows), one search per
    // distinct window: the first combination that has it, and each combination's search. Empty:
    // one search per combination.
    std::vector<std::size_t> searched;
    std::vector<std::uint32_t> search_of;
  };
  struct LineCursor;
  static StageWalk walk_of(const FactoredStage& stage, const std::vector<FactorVariable>& variables);
  // Fills the walk's searched and search_of where the windows do not depend on the line.
  void share_searches(StageWalk& walk, std::size_t dimension) const;
  // Stage k from `in` (W_{k-1}, `in_size` entries) into `out` (W_k).
  void run_stage(std::size_t k, const double* in, std::size_t in_size, double* out);
  // Per post dimension, the distinct windows of the tuples of the components it reads (tuple
  // digits major to minor as plan.reads lists them), packed for the threshold search, and the
  // window of each tuple.
  void gather_windows(const Abstraction& a, const RowBounds& rows, const std::vector<bool>& has_rows);
  // Offsets of a cell, input and disturbance in Q (their variables' digits times plan.q_stride).
  void number_q(const Abstraction& a);
  FactoredPlan plan_;
  Bound bound_;
  unsigned threads_;
  LineSearch search_;
  std::vector<std::size_t> counts_;        // state cells per dimension
  std::vector<PackedWindows> packed_;      // [dimension]: the distinct windows
  std::vector<std::vector<std::uint32_t>> window_of_;  // [dimension][tuple]: its window in packed_
  VectorUnit unit_ = widest_vector_unit();  // the searches' passes
  std::vector<StageWalk> walks_;           // per stage
  std::shared_ptr<SweepBuffers> buffers_;  // the ping-pong W_k
  std::vector<double> q_;
  std::vector<std::size_t> cell_offset_, input_offset_, disturbance_offset_;
};

}  // namespace amytiss::detail
