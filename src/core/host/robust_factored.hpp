#pragma once
// The product (orthogonally decoupled) bound of every (state cell, input, disturbance) of the
// interval MDP by variable elimination along the dynamics' dependency graph, in the elimination
// order and tensor layouts of the factored sweep's plan (host/factored_plan.hpp):
//   W_0 = V,   W_k[remaining post cells, U_k] = O-max over a in window(e_k | tuple) of W_{k-1}[..., a, ...],
// where the window and its interval masses are post dimension e_k's for the tuple of components
// e_k reads (the bounds of any row with those components: host/row_bounds.hpp), leave worth 0 and
// cut worth cut_value(bound), and Q = W_d holds every (cell, input, disturbance)'s bound. Each line
// of W_{k-1} is read once: sorted, then every tuple applied to it by the threshold search
// (threshold_expectation()), each search starting where the search of the window in the same place
// ended on the line before, so the stage keeps no sorted copy of its input.
//
// This is the product set's recursive bound in the order e_1..e_d: sound in every order (each
// stage may pick its distribution per remaining cell, a superset of the product set), and equal,
// up to rounding, to product_expectation_in_order() of each row in the same order. It pays where
// coordinates read few components (building automation: 7 dimensions, each reading 2 to 4), where
// the row-by-row product bound recomputes the same lines for every row.
#include <cstddef>
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
  /// The factored sweep's plan for these bounds, or nullopt with the reason: no plan (dynamics
  /// without dependencies, full covariance), or one that needs slices (an O-maximisation needs
  /// its whole line) or more than kMaxBytes.
  static std::optional<FactoredPlan> plan(const Abstraction& abstraction, std::string* reason);
  /// `rows` must hold the rows of every cell with `has_rows` true; `plan` from plan(). `buffers`
  /// (the stage tensors): shared with sweeps that never run at the same time as this one; null:
  /// its own.
  RobustFactoredSweep(const Abstraction& abstraction, const RowBounds& rows, const std::vector<bool>& has_rows,
                      FactoredPlan plan, Bound bound, unsigned threads,
                      std::shared_ptr<SweepBuffers> buffers = nullptr);
  /// Every stage over `values` (one per state cell, flat): Q.
  void prepare(const double* values);
  /// The bound of row (cell, input, disturbance) over the values of the last prepare().
  double expectation(std::size_t cell, std::size_t input, std::size_t disturbance) const {
    return q_[cell_offset_[cell] + input_offset_[input] + disturbance_offset_[disturbance]];
  }
  /// The elimination order e_1..e_d (post dimensions).
  const std::vector<std::size_t>& order() const { return plan_.order; }

 private:
  // A stage's output digits split by what they do: those the input has name the line an entry
  // reads; the others enumerate the tuples applied to that line (row-major, as the output).
  struct StageWalk {
    struct Carried {
      std::size_t radix, input_stride, output_stride, tuple_stride;
    };
    std::vector<Carried> carried;  // by increasing input stride: the lines' odometer, fastest first
    std::vector<std::size_t> free_offsets, free_tuples;  // per combination of the other digits
  };
  static StageWalk walk_of(const FactoredStage& stage);
  // Stage k from `in` (W_{k-1}, `in_size` entries) into `out` (W_k).
  void run_stage(std::size_t k, const double* in, std::size_t in_size, double* out);
  // Per post dimension, the window of each tuple of the components it reads (tuple digits major
  // to minor as plan.reads lists them), packed for the threshold search.
  void gather_windows(const Abstraction& a, const RowBounds& rows, const std::vector<bool>& has_rows);
  // Offsets of a cell, input and disturbance in Q (their variables' digits times plan.q_stride).
  void number_q(const Abstraction& a);
  FactoredPlan plan_;
  Bound bound_;
  unsigned threads_;
  std::vector<std::size_t> counts_;        // state cells per dimension
  std::vector<PackedWindows> packed_;      // [dimension]: the window of each tuple
  VectorUnit unit_ = widest_vector_unit();  // the searches' passes
  std::vector<StageWalk> walks_;           // per stage
  std::shared_ptr<SweepBuffers> buffers_;  // the ping-pong W_k
  std::vector<double> q_;
  std::vector<std::size_t> cell_offset_, input_offset_, disturbance_offset_;
};

}  // namespace amytiss::detail
