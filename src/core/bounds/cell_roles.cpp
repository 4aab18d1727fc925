#include "bounds/cell_roles.hpp"

#include <algorithm>
#include <limits>

#include "amytiss/footprint.hpp"

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

// Whether the box [lo, hi] lies in the union of boxes[first..] (within `slack`). The first box
// that overlaps it covers its middle; the slabs that stick out of that box (at most two per
// dimension, cut off one after another) must lie in the union of the later boxes, since the
// earlier ones do not overlap any part of [lo, hi]. Exact up to the slack, whatever the layout.
bool covered(std::vector<double> lo, std::vector<double> hi, const std::vector<Box>& boxes, std::size_t first,
             const std::vector<double>& slack) {
  std::size_t i = first;
  while (i < boxes.size() && !overlaps(lo, hi, boxes[i], slack)) ++i;
  if (i == boxes.size()) return false;
  const Box& box = boxes[i];
  for (std::size_t d = 0; d < lo.size(); ++d) {
    if (lo[d] < box.lb[d] - slack[d]) {
      std::vector<double> slab_hi = hi;
      slab_hi[d] = box.lb[d];
      if (!covered(lo, slab_hi, boxes, i + 1, slack)) return false;
      lo[d] = box.lb[d];
    }
    if (hi[d] > box.ub[d] + slack[d]) {
      std::vector<double> slab_lo = lo;
      slab_lo[d] = box.ub[d];
      if (!covered(slab_lo, hi, boxes, i + 1, slack)) return false;
      hi[d] = box.ub[d];
    }
  }
  return true;
}

}  // namespace

std::vector<CellRole> robust_cell_roles(const Grid& states, const SpecConfig& spec, Bound bound) {
  const std::size_t dims = states.dims();
  std::vector<std::size_t> multi(dims);
  std::vector<double> cell_lo(dims), cell_hi(dims), slack(dims);
  for (std::size_t d = 0; d < dims; ++d) slack[d] = kFaceTolerance * states.eta()[d];
  // inside: the cell's interior lies in the union of the set's boxes; meets: the interior and one
  // of the boxes overlap (contact along a face, within the tolerance, does not count).
  auto inside = [&](const Region& region) { return covered(cell_lo, cell_hi, region.boxes, 0, slack); };
  auto meets = [&](const Region& region) {
    return std::any_of(region.boxes.begin(), region.boxes.end(),
                       [&](const Box& box) { return overlaps(cell_lo, cell_hi, box, slack); });
  };
  const bool lower = bound == Bound::Lower;
  // The lower bound avoids every cell whose body may touch an obstacle at some pose; the upper
  // bound would need "touches at every pose" and, soundly, avoids no cell for obstacles.
  const std::vector<bool> touched = lower ? obstacle_cells(states, spec) : std::vector<bool>(states.size(), false);
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
      if (spec.safe && !(lower ? inside(*spec.safe) : meets(*spec.safe))) roles[cell] = CellRole::FixedZero;
      continue;
    }
    if (spec.avoid && (lower ? meets(*spec.avoid) : inside(*spec.avoid))) roles[cell] = CellRole::FixedZero;
    else if (spec.target && (lower ? inside(*spec.target) : meets(*spec.target))) roles[cell] = CellRole::FixedOne;
  }
  return roles;
}

}  // namespace amytiss::detail
