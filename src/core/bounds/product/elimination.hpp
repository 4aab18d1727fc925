#pragma once
// The product (orthogonally decoupled) bound of every (state cell, input, disturbance) of the
// interval MDP by variable elimination along the dynamics' dependency graph, in the elimination
// order and tensor layouts of the factored sweep's plan (factored/factored_plan.hpp):
//   W_0 = V,   W_k[remaining post cells, U_k] = O-max over a in window(e_k | tuple) of W_{k-1}[..., a, ...],
// where the window and its interval masses are post dimension e_k's for the tuple of components
// e_k reads (the bounds of any row with those components: bounds/row_bounds.hpp), leave worth 0 and
// cut worth cut_value(bound), and Q = W_d holds every (cell, input, disturbance)'s bound. Each line
// of W_{k-1} is read once and every tuple applied to it by a threshold search; tuples that read
// the same window (a linear map on the grid gives many cells one mean) share one search. A line
// that feeds many searches is sorted first and searched in one batch (ThresholdSearches), one that
// feeds few is not (threshold_scan()); each search starts where the search of the window in the
// same place ended on the line before (bounds/product/stage_lines.hpp). The tensors are laid out for this
// (FactoredLayout::Lines): a line's results are written side by side. Where a stage contracts the
// post cell over which the stage before counts its lines fastest, the two run as a pair: each run
// of the first stage's lines over that cell gives whole lines of the second, searched while in
// cache, and the tensor between them is never written (traffic 3-d: 688 MB per bound and step).
//
// This is the product set's recursive bound in the order e_1..e_d: sound in every order (each
// stage may pick its distribution per remaining cell, a superset of the product set), and equal,
// up to rounding, to the tests' product_expectation_in_order() (test/core/robust_oracle.hpp) of
// each row in the same order. It pays where coordinates read few components (building
// automation: 7 dimensions, each reading 2 to 4), where the row-by-row product bound recomputes
// the same lines for every row.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "bounds/omax/robust_expectation.hpp"
#include "bounds/product/whole_tables.hpp"
#include "bounds/row_bounds.hpp"
#include "factored/factored_plan.hpp"
#include "bounds/product/stage_lines.hpp"
#include "bounds/omax/threshold_expectation.hpp"

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
  std::size_t searches_per_line(std::size_t k) const { return walks_[k].searches_per_line(); }
  /// The stages as they run: one alone, or a pair where stage first + 1 searches stage first's
  /// results as they come, a run of lines at a time (W_first is never written out), because it
  /// contracts the fastest digit of stage first's lines. With their seconds over every prepare().
  struct StageRun {
    std::size_t first, last;
    double seconds = 0.0;
  };
  const std::vector<StageRun>& runs() const { return runs_; }
  /// The runs that a sweep of `plan` takes, from the plan alone (counts: state cells per
  /// dimension): the pairs that leave the most entries of the stage tensors unwritten.
  static std::vector<StageRun> stage_runs(const FactoredPlan& plan, const std::vector<std::size_t>& counts);
  /// Whether stage k runs as a pair with stage k + 1.
  bool fused_with_next(std::size_t k) const {
    for (const StageRun& run : runs_)
      if (run.first == k) return run.last > k;
    return false;
  }

 private:
  // Stage k's lines in its input of `in_size` entries: the dimension it contracts, the lines'
  // length and stride, and their number.
  struct LineShape {
    std::size_t dimension, length, stride, lines;
  };
  LineShape lines_of(std::size_t k, std::size_t in_size) const;
  // Stage k from `in` (W_{k-1}, `in_size` entries) into `out` (W_k).
  void run_stage(std::size_t k, const double* in, std::size_t in_size, double* out);
  // Stages k and k + 1 from `in` (W_{k-1}) into `out` (W_{k+1}), where stage k + 1 contracts the
  // fastest digit of stage k's lines (a pair of runs_): each run of stage k's lines over that digit
  // gives whole lines of stage k + 1, searched at once, while they are in cache; W_k is never
  // written out.
  void run_fused(std::size_t k, const double* in, std::size_t in_size, double* out);
  // Whether stage k's lines, a run at a time, give whole lines of stage k + 1.
  static bool fuses_next(const FactoredPlan& plan, const std::vector<std::size_t>& counts, std::size_t k);
  // Whether stage k sorts its lines.
  bool sorts(std::size_t k) const;
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
  std::vector<StageRun> runs_;             // every stage once, in order
  std::shared_ptr<SweepBuffers> buffers_;  // the ping-pong W_k
  std::vector<double> q_;
  std::vector<std::size_t> cell_offset_, input_offset_, disturbance_offset_;
};

}  // namespace amytiss::detail
