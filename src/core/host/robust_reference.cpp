#include "host/robust_reference.hpp"

#include <algorithm>
#include <limits>

#include "amytiss/errors.hpp"
#include "amytiss/footprint.hpp"
#include "model/box_cover.hpp"

namespace amytiss::detail {
namespace {

double role_value(CellRole role, SpecType spec) {
  if (role == CellRole::FixedOne) return 1.0;
  if (role == CellRole::FixedZero) return 0.0;
  return spec == SpecType::Safety ? 1.0 : 0.0;
}

// The bounds of every (cell, input, disturbance) row of the Free cells, per dimension.
std::vector<std::vector<DimensionBounds>> row_bounds(const RobustProblem& p) {
  const std::size_t dims = p.states.dims();
  std::vector<MassBounds> per_dimension;
  for (std::size_t d = 0; d < dims; ++d) per_dimension.emplace_back(p.noise, d);
  const std::size_t inputs = p.inputs.size(), disturbances = p.disturbances.size();
  std::vector<std::vector<DimensionBounds>> rows(p.states.size() * inputs * disturbances);
  std::vector<double> lo(dims), hi(dims);
  std::vector<std::size_t> multi(dims);
  for (std::size_t cell = 0; cell < p.states.size(); ++cell) {
    if (p.lower_roles[cell] != CellRole::Free && p.upper_roles[cell] != CellRole::Free) continue;
    p.states.multi_index(cell, multi.data());
    for (std::size_t u = 0; u < inputs; ++u) {
      for (std::size_t w = 0; w < disturbances; ++w) {
        p.mean_box(cell, u, w, lo.data(), hi.data());
        std::vector<DimensionBounds>& row = rows[(cell * inputs + u) * disturbances + w];
        for (std::size_t d = 0; d < dims; ++d) {
          const auto k = std::int64_t(multi[d]);
          const MassInterval scale = per_dimension[d].scale_range(p.states.face(d, k), p.states.face(d, k + 1));
          row.push_back(per_dimension[d].dimension_bounds(p.states, lo[d], hi[d], scale.lo, scale.hi));
        }
      }
    }
  }
  return rows;
}

// Whether the box [lo, hi] and `box` share interior: an overlap thinner than `slack` (per
// dimension) is contact along a face and does not count.
bool overlaps(const std::vector<double>& lo, const std::vector<double>& hi, const Box& box,
              const std::vector<double>& slack) {
  for (std::size_t d = 0; d < lo.size(); ++d)
    if (hi[d] <= box.lb[d] + slack[d] || lo[d] >= box.ub[d] - slack[d]) return false;
  return true;
}

}  // namespace

RobustValues robust_values(const RobustProblem& p, AmbiguitySet set) {
  const std::size_t cells = p.states.size(), inputs = p.inputs.size(), disturbances = p.disturbances.size();
  const std::vector<std::vector<DimensionBounds>> rows = row_bounds(p);
  std::vector<IntervalRow> joint(set == AmbiguitySet::Joint ? rows.size() : 0);
  for (std::size_t r = 0; r < joint.size(); ++r)
    if (!rows[r].empty()) joint[r] = joint_row(p.states, rows[r]);
  auto expectation = [&](std::size_t row, const std::vector<double>& values, Bound bound) {
    return set == AmbiguitySet::Joint ? joint_expectation(joint[row], values.data(), bound)
                                      : product_expectation(p.states, rows[row], values.data(), bound);
  };

  RobustValues out;
  out.lower.resize(cells);
  out.upper.resize(cells);
  out.controller.assign(std::size_t(p.horizon) * cells, 0);
  for (std::size_t cell = 0; cell < cells; ++cell) {
    out.lower[cell] = role_value(p.lower_roles[cell], p.spec);
    out.upper[cell] = role_value(p.upper_roles[cell], p.spec);
  }
  for (unsigned k = p.horizon; k-- > 0;) {
    const std::vector<double> next_lower = out.lower, next_upper = out.upper;
    for (std::size_t cell = 0; cell < cells; ++cell) {
      double best_lower = -1.0, best_upper = -1.0;
      for (std::size_t u = 0; u < inputs; ++u) {
        double worst_lower = std::numeric_limits<double>::infinity(), worst_upper = worst_lower;
        for (std::size_t w = 0; w < disturbances; ++w) {
          const std::size_t row = (cell * inputs + u) * disturbances + w;
          if (p.lower_roles[cell] == CellRole::Free)
            worst_lower = std::min(worst_lower, expectation(row, next_lower, Bound::Lower));
          if (p.upper_roles[cell] == CellRole::Free)
            worst_upper = std::min(worst_upper, expectation(row, next_upper, Bound::Upper));
        }
        if (p.lower_roles[cell] == CellRole::Free && worst_lower > best_lower) {
          best_lower = worst_lower;
          out.controller[std::size_t(k) * cells + cell] = std::uint32_t(u);
        }
        best_upper = std::max(best_upper, worst_upper);
      }
      if (p.lower_roles[cell] == CellRole::Free) out.lower[cell] = best_lower;
      if (p.upper_roles[cell] == CellRole::Free) out.upper[cell] = best_upper;
    }
  }
  return out;
}

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
