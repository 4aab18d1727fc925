#pragma once
// Where the next round of `refine` halves cells (docs/refinement.md, "Where the cells are
// halved"): the gap of the round's bounds attributed to the cells that create it, per dimension
// and interval, weighed by the interval's width against the noise, and the intervals that carry
// most of it halved within the round's budget of cells.
#include <cstdint>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/policy.hpp"

namespace amytiss::detail {

/// Episodes of the closed loop the attribution runs from the `at` states, all together.
constexpr std::size_t kAttributionEpisodes = 4000;
/// A round's grid has at most this many times the previous round's cells.
constexpr double kRoundGrowth = 2.0;
/// The halvings of a round cover at least this share of the weighed gap (those that carry most first).
constexpr double kCoveredShare = 0.9;

/// The gap each interval of each state dimension creates: gap[d][k] for cell interval k of
/// dimension d (probability units, summed over the cells of the interval).
/// With `at`: the mean over episodes of the closed loop under `policy` (from uniform points of the
/// `at` states' cells, `episodes` in all, seed `seed`) of the gap each visited cell adds, its
/// upper - lower at that step less the next visited cell's at the next step (the last state's
/// whole gap; outside the grid 0), so that the gaps of one episode add up to its start cell's.
/// Without `at`: every free cell's step-0 gap over the free cells' count.
std::vector<std::vector<double>> attribute_gap(const Abstraction& abstraction, const Policy& policy,
                                               const std::vector<std::vector<double>>& at, std::size_t episodes,
                                               std::uint64_t seed);

/// The next round's state grid, or why there is none.
struct SplitChoice {
  GridSpec states;          ///< `current` with the chosen intervals halved (valid when `splits` > 0)
  std::uint64_t cells = 0;  ///< its state cells
  std::size_t splits = 0;   ///< intervals halved
  std::string why_none;     ///< with no split: why (the budget of cells, or nothing to split)
};

/// Halves the intervals of the most weighed gap, gap[d][k] times the interval's width over the
/// noise's scale along d (noise-free dimensions are not split: their cells follow the lattice),
/// until kCoveredShare of the weighed gap is covered or the next halving would take the grid
/// beyond min(max_cells, kRoundGrowth times its cells).
SplitChoice choose_splits(const GridSpec& current, const NoiseModel& noise, const std::vector<std::vector<double>>& gap,
                          std::uint64_t max_cells);

}  // namespace amytiss::detail
