#pragma once
// A small serial "robust reference": lower and upper bounds of the continuous system's bounded-
// horizon value through the interval MDP (docs/semantics.md, "Interval transition bounds"), for
// tiny problems and tests. Separate from the engines: it changes no result of theirs.
//
// For every x inside a Free cell (its interior), with the controller that plays controller[k][cell] at step k:
//   lower(cell) <= P(the specification holds from x)   and, for every controller choosing inputs
//   of the input grid, P(...) <= upper(cell),
// against every disturbance of the disturbance grid (min over it, as the engines), provided
// mean_box encloses f(x, u, w) for every x in the cell. Per (cell, input, disturbance) row and
// dimension the bounds come from MassBounds (model/mass_bounds.hpp); the rows are the joint
// interval MDP or the product set (host/interval_bellman.hpp).
#include <cstdint>
#include <functional>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "host/interval_bellman.hpp"

namespace amytiss::detail {

enum class AmbiguitySet { Joint, Product };

/// Writes lo[i] <= f(x, u, w)_i <= hi[i] (state units) for every x in state cell `cell` (flat
/// index), input index `input` and disturbance index `disturbance`.
using MeanBox = std::function<void(std::size_t cell, std::size_t input, std::size_t disturbance, double* lo,
                                   double* hi)>;

struct RobustProblem {
  const Grid& states;
  const Grid& inputs;        ///< zero dimensions: autonomous
  const Grid& disturbances;  ///< zero dimensions: none
  const NoiseModel& noise;   ///< separable (MassBounds refuses a full covariance)
  MeanBox mean_box;
  SpecType spec = SpecType::Safety;
  unsigned horizon = 1;
  std::vector<CellRole> lower_roles, upper_roles;  ///< robust_cell_roles() of each bound
};

struct RobustValues {
  std::vector<double> lower, upper;       ///< V_0 bounds per state cell
  std::vector<std::uint32_t> controller;  ///< [k * cells + cell]: the maximiser of the lower bound
};

/// Backward recursion over the horizon: lower = max_u min_w pessimistic expectation of the next
/// lower values, upper = max_u min_w optimistic expectation of the next upper values; fixed cells
/// hold their role's value, Free cells start at 1 (safety) or 0. Ties keep the lowest input.
RobustValues robust_values(const RobustProblem& problem, AmbiguitySet set);

/// Cell roles for one bound, from the cells' interiors (c - eta/2, c + eta/2): the bounds hold for
/// every x inside a cell; contact with a set along a face (within kFaceTolerance * eta) does not
/// count. Lower: target only when the cell lies inside the target, avoid (safety: unsafe) as soon
/// as it meets the avoid set (leaves the safe set). Upper: target as soon as it meets the target,
/// avoid only inside the avoid set (unsafe only when it misses the safe set). Avoid wins.
/// Sets that are unions of boxes: "meets" is meeting one of the boxes, "inside" is lying inside
/// their union (exactly, by box_covered(): a cell covered by several boxes together is inside);
/// ConfigError naming the set for a union too intricate to decide. `poll`: as obstacle_cells().
constexpr double kFaceTolerance = 1e-9;
std::vector<CellRole> robust_cell_roles(const Grid& states, const SpecConfig& spec, Bound bound,
                                        const SetupPoll& poll = {});

}  // namespace amytiss::detail
