#pragma once
// Gap-guided refinement (`refine`, docs/refinement.md): rounds of continuous-system bounds, each on
// a state grid whose cells are halved where the previous round's gap at the `at` states came from,
// until the gap is reached or a budget (cells, rounds, seconds) ends.
#include <string>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/synthesis_types.hpp"

namespace amytiss {

/// The served round of a refined synthesis.
struct RefinedSynthesis {
  Abstraction abstraction;  ///< the served round's (its config: the round's grid, no refine)
  /// The served round's bounds and controller; its refinement lists every round, its config_hash
  /// is the given configuration's (with refine), so the policy file names what was asked.
  Policy policy;
};

/// Runs the rounds of `config.refine` (config validated, refine set): each round builds the
/// abstraction of its grid and synthesize()s it with `options` (progress carries the round), the
/// next round's grid halves the intervals that add most to the gap (split_choice.hpp). Serves the
/// round with the smallest gap (the latest among equals). `report`: the served round's phases and
/// notes, and one note per round (its cells, gap, bounds at `at` and seconds) and the reason the
/// rounds ended. `first_round`: the abstraction of first_round_config(config) where the caller
/// has built it already (it is not built again); null: built here. Throws what synthesize() throws.
RefinedSynthesis synthesize_refined(const Config& config, const SynthesisOptions& options,
                                    SynthesisReport* report = nullptr, const Abstraction* first_round = nullptr);

/// The rounds `refine` may run, as one line for --dry-run: "refine: until the gap at 1 at state is
/// at most 0.05; at most 6 rounds, 160000 cells, 600 s; the plan above is the first round's".
std::string describe_refine(const RefineConfig& refine, std::size_t first_cells);

/// The configuration of one round: `config` with `states` as its state grid (faces fitted
/// already: fit_sets off) and no refine section.
Config round_config(const Config& config, const GridSpec& states);
/// The first round's configuration: round_config() of the grid fitted to the sets
/// (fitted_states()). Valid when `config` is.
Config first_round_config(const Config& config);

}  // namespace amytiss
