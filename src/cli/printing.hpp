#pragma once
// amytiss_synth's output: the problem's sizes, the progress lines, the wall-time and profile
// tables, the value summary and the comparison with the reference engine (docs/cli.md).
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/scale_out.hpp"
#include "amytiss/synthesis_types.hpp"

namespace amytiss::cli {

/// "0.123 s" below 10 s, else "12.3 s".
std::string format_seconds(double seconds);
/// "[lo0, hi0] x [lo1, hi1]": the box the grid's cells cover (outermost faces).
std::string covered_box_text(const Grid& grid);
/// Grid sizes (with faces: also the box covered), pairs and triples, and the horizon.
void print_sizes(const Abstraction& abstraction);
/// The engine's memory estimate (docs/engine.md).
void print_memory_estimate(const Abstraction& abstraction);
/// The noise law, the truncation's cut mass and the quadrature error bound per transition.
void print_error_budget(const Abstraction& abstraction);
/// A progress line per time step (unbounded: per 100th iteration) unless quiet; always true.
bool print_progress(const Progress& progress, bool quiet);
/// Seconds of construction and synthesis, without set-up and breakdowns (the compute time).
double compute_seconds(const SynthesisReport& report);
/// The phases' wall times, the time steps summed into one line.
void print_phase_times(const SynthesisReport& report);
/// Per phase: seconds, pairs/s, multiply-adds, GMAC/s, share of the peak, GB/s; the memory; and,
/// with a peak and a measured bandwidth, the roofline of the steps and the breakdowns.
void print_profile(const SynthesisReport& report);
/// V_0 over the free cells; continuous-system bounds: min, mean and max of the lower bound, the
/// upper bound and the gap; unbounded: also the upper bound and the gap.
void print_value_summary(const Policy& policy);
/// "[0.25, 0.5, 1.47]": values as the other lines print them.
std::string format_values(const std::vector<double>& values);
/// The policy at `state`, step 0: the value of its cell (continuous-system bounds: the certified
/// lower bound and the upper bound) and the input. The state must lie in the grid.
void print_values_at(const Policy& policy, const std::vector<double>& state);
/// With refine: one line per round (cells, gap, the bounds at the `at` states, seconds), the
/// served round and why the rounds ended. Nothing for a policy of one grid.
void print_refinement(const Policy& policy);
/// The paper's a-priori error of the abstraction (apriori_error.hpp), its Jacobians bounded in number.
void print_apriori_error(const Abstraction& abstraction);
/// Runs the reference engine too and prints the speed-up and max |dV_0| (with upper bounds: the
/// largest difference of the lower and of the upper bounds).
void compare_with_reference(const Abstraction& abstraction, const Policy& policy, double engine_seconds,
                            double engine_compute_seconds, bool quiet);
/// Each rank's synthesis time and the share of it spent exchanging parts. Collective.
void print_rank_times(double synthesis_seconds, const SynthesisReport& report, Communicator* communicator);

}  // namespace amytiss::cli
