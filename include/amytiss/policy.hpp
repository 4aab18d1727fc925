#pragma once
// The synthesized time-varying policy u*(x, k) and the values V_k(x) (docs/semantics.md).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/grid.hpp"
#include "amytiss/run_id.hpp"  // new_run_id() for Policy::run_id

namespace amytiss {

/// Outcome of a lookup; every non-Ok status comes with a message from describe().
enum class LookupStatus { Ok, WrongDimension, NotFinite, OutsideGrid, StepBeyondHorizon };

/// One round of `refine` (docs/refinement.md): the round's grid, its time and the gap it left.
struct RefinementRound {
  std::uint64_t states = 0;  ///< state cells of the round's grid
  double seconds = 0;        ///< wall time of the round: its abstraction, bounds and split choice (s)
  /// The round's gap: the largest upper - lower at step 0 over the `at` states, or without `at`
  /// the mean over the free cells.
  double gap = 0;
  std::vector<double> lower, upper;  ///< the bounds at step 0 at each `at` state (empty without `at`)
};

/// The rounds of a refined synthesis; empty `rounds` for a policy computed on one grid.
struct Refinement {
  /// The `at` states (state units, one vector per state, as the configuration lists them) whose
  /// bounds each round's lower and upper hold, in that order; empty without `at`.
  std::vector<std::vector<double>> at;
  std::vector<RefinementRound> rounds;
  std::uint64_t served_round = 0;  ///< the round whose grid and bounds the policy holds (0-based)
  std::string stop;                ///< why the rounds ended, a sentence
};

struct Policy {
  Grid states;
  Grid inputs;
  unsigned horizon = 0;
  /// V_k for k = 0..horizon, k-major: values[k * states.size() + flat]. Probabilities in [0, 1].
  std::vector<double> values;
  /// Index (flat, into `inputs`) of u*(x, k) for k = 0..horizon-1: input_index[k * states.size()
  /// + flat]. Ties: the lowest flat input index. Target cells: under the abstraction the
  /// input a Free cell would get (the best one-step expectation of the next values: a state in
  /// the cell's box may lie outside the target); other fixed cells, and every fixed cell with
  /// guarantee system, input 0.
  std::vector<std::uint32_t> input_index;
  std::vector<CellRole> roles;
  /// What `values` and `upper_values` bound (docs/semantics.md). Abstraction: `values` are the
  /// finite MDP's exact values (bounded horizon; `upper_values` empty). System: `values` are lower
  /// bounds of the continuous system's probability under this policy from every state of the cell,
  /// `upper_values` (same layout as `values`, or one row when stationary) upper bounds of what any
  /// controller choosing inputs of the input grid achieves.
  Guarantee guarantee = Guarantee::Abstraction;
  /// Unbounded specification (horizon: infinite): the policy is stationary, `horizon` is 1,
  /// values rows 0 and 1 both hold the certified lower bound (the probability the stored
  /// policy guarantees), `upper_values` the upper bound of the optimal value per cell, and
  /// lookup() ignores the step.
  bool stationary = false;
  std::vector<double> upper_values;
  /// The upper bound that matches value(step, cell): upper_values' row `step` (stationary: its
  /// only row); value(step, cell) itself when there is no upper bound (abstraction, bounded).
  double upper_value(unsigned step, std::size_t cell) const {
    if (upper_values.empty()) return value(step, cell);
    return stationary ? upper_values[cell] : upper_values[std::size_t(step) * states.size() + cell];
  }
  unsigned iterations = 0;  ///< interval iterations done (stationary only)
  double gap = 0;           ///< max over cells of upper - lower (stationary only)
  /// Stationary only: whether `gap` reached the specification's tolerance. False: the bounds
  /// are sound but further apart than asked (the synthesis also said so in a Warning note).
  bool converged = true;
  /// The rounds of `refine` that led to this grid (empty rounds without refine).
  Refinement refinement;
  /// What computed it (device name or "reference") and the configuration's hash.
  std::string computed_by;
  std::string config_hash;
  /// Identity of the synthesis run that computed it: 16 hex digits of a random 64-bit number,
  /// drawn by synthesize() (new_run_id()). Two runs of one configuration differ in run_id.
  std::string run_id;

  double value(unsigned step, std::size_t cell) const { return values[std::size_t(step) * states.size() + cell]; }
  std::uint32_t input(unsigned step, std::size_t cell) const {
    return input_index[std::size_t(step) * states.size() + cell];
  }

  /// Concrete state -> input and probability for time step `step` (0 <= step < horizon; any step
  /// for a stationary policy).
  /// Writes inputs.dims() values to input_out and V_step(cell) to probability_out on Ok, and
  /// upper_value(step, cell) to upper_out when it is not null. No allocation, O(dimension).
  LookupStatus lookup(const double* state, std::size_t state_length, unsigned step,
                      double* input_out, double* probability_out, double* upper_out = nullptr) const;
  /// A sentence that says what was wrong and what was expected, e.g. "state has 3 values,
  /// expected 2 (x0, x1)" or "state [12, 0] is outside the grid [-10.25, 10.25] x [...]".
  std::string describe(LookupStatus status, const double* state, std::size_t state_length,
                       unsigned step) const;
};

/// How every output labels a value of guarantee abstraction, beside the number.
inline constexpr const char* kAbstractionValueLabel = "abstraction's value, not a guarantee for the real system";

/// Summary of V_0 for logs: min, mean, max over Free cells, and how many cells have V_0 >= 0.5.
struct ValueSummary {
  double min = 0, mean = 0, max = 0;
  std::size_t free_cells = 0, cells_at_least_half = 0;
};
ValueSummary summarize_initial_values(const Policy& policy);

/// min, mean and max of a quantity over the Free cells (probabilities; 0 when there is none).
struct RangeSummary {
  double min = 0, mean = 0, max = 0;
};
/// Both bounds of step 0 over the Free cells: lower, value(0, cell); upper, upper_value(0, cell);
/// gap, upper - lower per cell. Without upper bounds (abstraction, bounded) upper equals lower.
struct BoundsSummary {
  RangeSummary lower, upper, gap;
  std::size_t free_cells = 0;
};
BoundsSummary summarize_bounds(const Policy& policy);

}  // namespace amytiss
