#include "bounds/cell_roles.hpp"

#include <algorithm>
#include <limits>

#include "amytiss/errors.hpp"
#include "amytiss/footprint.hpp"
#include "model/box_cover.hpp"

namespace amytiss::detail {
namespace {

// Whether the box [lo, hi] and `box` share interior: an overlap thinner than `slack` (per
// dimension) is contact along a face and does not count.
bool overlaps(const std::vector<double>& lo, const std::vector<double>& hi, const Box& box,
              const std::vector<double>& slack) {
  for (std::size_t d = 0; d < lo.size(); ++d)
    if (hi[d] <= box.lb[d] + slack[d] || lo[d] >= box.ub[d] - slack[d]) return false;
  return true;
}

}  // namespace

std::vector<CellRole> robust_cell_roles(const Grid& states, const SpecConfig& spec, Bound bound,
                                        const SetupPoll& poll) {
  const std::size_t dims = states.dims();
  std::vector<std::size_t> multi(dims);
  std::vector<double> cell_lo(dims), cell_hi(dims), slack(dims);
  for (std::size_t d = 0; d < dims; ++d) slack[d] = kFaceTolerance * states.eta()[d];
  // inside: the cell's interior lies in the union of the set's boxes; meets: the interior and one
  // of the boxes overlap (contact along a face, within the tolerance, does not count).
  auto inside = [&](const Region& region, const char* key) {
    const std::optional<bool> covered = box_covered(cell_lo, cell_hi, region.boxes, slack);
    if (!covered)
      throw ConfigError(key, "a union of " + std::to_string(region.boxes.size()) +
                                 " boxes too intricate to decide which cells lie inside it (more than " +
                                 std::to_string(kMaxCoverSteps) +
                                 " steps for one cell); expected fewer overlapping boxes (example: " +
                                 std::string(key).substr(5) + ": [{lb: [0, 0], ub: [2, 1]}, {lb: [0, 1], ub: [1, 2]}])");
    return *covered;
  };
  auto meets = [&](const Region& region) {
    return std::any_of(region.boxes.begin(), region.boxes.end(),
                       [&](const Box& box) { return overlaps(cell_lo, cell_hi, box, slack); });
  };
  const bool lower = bound == Bound::Lower;
  // The lower bound avoids every cell whose body may touch an obstacle at some pose; the upper
  // bound would need "touches at every pose" and, soundly, avoids no cell for obstacles.
  const std::vector<bool> touched =
      lower ? obstacle_cells(states, spec, poll) : std::vector<bool>(states.size(), false);
  std::vector<CellRole> roles(states.size(), CellRole::Free);
  for (std::size_t cell = 0; cell < states.size(); ++cell) {
    states.multi_index(cell, multi.data());
    for (std::size_t d = 0; d < dims; ++d) {
      cell_lo[d] = states.face(d, std::int64_t(multi[d]));
      cell_hi[d] = states.face(d, std::int64_t(multi[d]) + 1);
    }
    if (touched[cell]) {
      roles[cell] = CellRole::FixedZero;
      continue;
    }
    if (spec.type == SpecType::Safety) {
      if (spec.safe && !(lower ? inside(*spec.safe, "spec.safe") : meets(*spec.safe))) roles[cell] = CellRole::FixedZero;
      continue;
    }
    if (spec.avoid && (lower ? meets(*spec.avoid) : inside(*spec.avoid, "spec.avoid"))) roles[cell] = CellRole::FixedZero;
    else if (spec.target && (lower ? inside(*spec.target, "spec.target") : meets(*spec.target))) roles[cell] = CellRole::FixedOne;
  }
  return roles;
}

}  // namespace amytiss::detail
