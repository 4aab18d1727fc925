#pragma once
// The product (orthogonally decoupled) bound of every row of an interval MDP, one dimension per
// stage over whole tables, like the factored sweep of the abstraction (docs/engine.md): stage d
// (from the last dimension down to 1) applies dimension d's intervals of every suffix class
// (bounds/row_bounds.hpp) to every line of stage d + 1's table; stage 0 is done per row. Each line
// of values is sorted once for all the intervals applied to it, so that an O-maximisation is a
// scan in sorted order instead of a sort. Same results, bit for bit, as product_expectation()
// with the stage caches of bounds/robust_step.hpp.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "amytiss/grid.hpp"
#include "common/host_memory.hpp"
#include "bounds/omax/robust_expectation.hpp"
#include "bounds/omax/ordered_expectation.hpp"
#include "bounds/row_bounds.hpp"

namespace amytiss::detail {

/// What one ProductSweep::prepare() builds and its expectations read: the stage tables, the lines'
/// sort orders and stage 0's running maxima; or the stage tensors of a RobustFactoredSweep
/// (bounds/product/elimination.hpp). Every prepare() rebuilds all of it, so sweeps that never run at the
/// same time (a step's lower and upper bound) can share one and touch half the memory.
struct SweepBuffers {
  HostDoubles stage_tensors[2];             // the variable elimination's W_k, ping-pong
  std::vector<std::vector<double>> tables;  // per dimension d >= 1: [suffix class][prefix]
  LineOrder source_order;                   // the current stage's source lines' order
  LineOrder stage0_order;                   // stage 0's lines' order
  std::vector<double> rising_max, falling_max;  // per stage-0 line: largest up to / from each cell
};

class ProductSweep {
 public:
  /// At most this many table entries (a double and a 32-bit position each).
  static constexpr std::size_t kMaxTableEntries = std::size_t(1) << 24;
  /// It pays only where no stage computes more lines than this per row, and no dimension's line is
  /// longer than this many times its average window (a scan, cheaper than robust_expectation()'s
  /// sort while the line is not much longer, reads the whole line).
  static constexpr std::size_t kLinesPerRow = 64;
  static constexpr std::size_t kScanLengthPerOutcome = 4;
  /// Whether the sweep pays for these rows (`row_count` of them): its tables fit
  /// kMaxTableEntries, no stage computes more lines than 64 per row, and every dimension's line
  /// is at most 4 times as long as its average window (a scan reads the whole line). Otherwise
  /// product_expectation() row by row is the cheaper way to the same results.
  static bool pays(const Grid& states, const RowBounds& rows, std::size_t row_count);
  /// Whether its tables fit kMaxTableEntries (it can run, paying or not).
  static bool fits(const Grid& states, const RowBounds& rows);
  /// `buffers`: shared with sweeps of the same rows that never run at the same time as this
  /// one; null: its own.
  ProductSweep(const Grid& states, const RowBounds& rows, Bound bound, unsigned threads,
               std::shared_ptr<SweepBuffers> buffers = nullptr);
  /// Stages dims-1..1 over `values` (one per state cell, flat) and the sort order of stage 0's
  /// lines.
  void prepare(const double* values);
  /// Stage 0 of `row` over the values of the last prepare(): the row's product bound.
  double expectation(std::size_t row) const;
  /// At least expectation(row), from the largest value the row's stage 0 can take (two reads):
  /// an input whose estimate is not above the best value so far cannot be the maximiser.
  double upper_estimate(std::size_t row) const;
  /// What upper_estimate() adds for the outward rounding of expectation() (at most
  /// robust_expectation_rounding() of a few hundred outcomes, about 1e-13).
  static constexpr double kEstimateMargin = 1e-9;

 private:
  // Stage d's table, [suffix class][prefix], from its source's lines.
  void run_stage(std::size_t d, const double* source);
  const Grid& states_;
  const RowBounds& rows_;
  Bound bound_;
  unsigned threads_;
  std::vector<std::size_t> prefixes_;        // cells of dimensions 0..d-1
  std::vector<std::vector<WindowSums>> sums_;  // per dimension and distinct bounds
  // What upper_estimate() reads of stage 0's distinct bounds, packed to stay in cache: the window's
  // cells first..last (none when last < first) and the cut's largest mass.
  struct EstimateWindow {
    std::int32_t first, last;
    double cut_hi;
  };
  std::vector<EstimateWindow> estimate_windows_;
  std::shared_ptr<SweepBuffers> buffers_;
  const double* stage0_lines_ = nullptr;
};

}  // namespace amytiss::detail
