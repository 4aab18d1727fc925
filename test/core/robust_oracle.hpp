#pragma once
// The tests' oracle of the interval MDP: lower and upper bounds of the continuous system's
// bounded-horizon value by a plain serial recursion over unpacked rows (docs/semantics.md,
// "Interval transition bounds"), against which the bounds engine's methods are checked.
//
// For every x inside a Free cell (its interior), with the controller that plays controller[k][cell] at step k:
//   lower(cell) <= P(the specification holds from x)   and, for every controller choosing inputs
//   of the input grid, P(...) <= upper(cell),
// against every disturbance of the disturbance grid (min over it, as the engines), provided
// mean_box encloses f(x, u, w) for every x in the cell. Per (cell, input, disturbance) row and
// dimension the bounds come from MassBounds (bounds/mass_bounds.hpp); the rows are the joint
// interval MDP or the product set (bounds/omax/robust_expectation.hpp).
#include <algorithm>
#include <functional>
#include <stdexcept>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/enclosure.hpp"
#include "bounds/cell_roles.hpp"
#include "bounds/mean_box.hpp"
#include "bounds/lattice.hpp"
#include "bounds/mass_bounds.hpp"
#include "bounds/omax/robust_expectation.hpp"

namespace amytiss::detail {

/// The product bound with the dimensions eliminated in `order` (post dimensions e_1..e_d: e_1's
/// intervals applied first to the values, e_d's last), row by row: the oracle of the factored
/// product sweep (bounds/product/elimination.hpp). The order (d-1, ..., 0) is product_expectation()'s,
/// bit for bit; every order gives a sound bound (another one in general).
inline double product_expectation_in_order(const Grid& states, const DimensionView* dimensions, const double* values,
                                           Bound bound, const std::vector<std::size_t>& order) {
  const std::size_t dims = states.dims();
  if (order.size() != dims) throw std::logic_error("product_expectation_in_order: an order of every dimension");
  std::vector<std::size_t> multi(dims, 0);
  std::vector<OutcomeSlack> scratch;
  // Level k eliminates order[k - 1] with the dimensions order[k..] fixed in `multi`; level 0 reads
  // the values. As eliminate(): an outcome that can get no mass needs no value.
  std::function<double(std::size_t)> level = [&](std::size_t k) -> double {
    if (k == 0) return values[states.flat_index(multi.data())];
    const std::size_t d = order[k - 1];
    const DimensionView& window = dimensions[d];
    const std::size_t cells = window.count;
    std::vector<double> lo(cells + 2), hi(cells + 2), line(cells + 2);
    for (std::size_t j = 0; j < cells; ++j) {
      lo[j] = window.cells[j].lo;
      hi[j] = window.cells[j].hi;
      multi[d] = std::size_t(window.first) + j;
      line[j] = hi[j] > 0.0 ? level(k - 1) : 0.0;
    }
    multi[d] = 0;
    lo[cells] = window.leave.lo;
    hi[cells] = window.leave.hi;
    line[cells] = 0.0;
    lo[cells + 1] = window.cut.lo;
    hi[cells + 1] = window.cut.hi;
    line[cells + 1] = cut_value(bound);
    return robust_expectation(lo.data(), hi.data(), line.data(), cells + 2, bound, scratch);
  };
  return level(dims);
}

/// The rows' ambiguity sets: the joint interval MDP (each row's masses bounded cell by cell) or
/// the product of the per-dimension sets (the bounds engine's product methods).
enum class AmbiguitySet { Joint, Product };

struct RobustProblem {
  const Grid& states;
  const Grid& inputs;        ///< zero dimensions: autonomous
  const Grid& disturbances;  ///< zero dimensions: none
  const NoiseModel& noise;   ///< separable (MassBounds refuses a full covariance)
  MeanBox mean_box;
  SpecType spec = SpecType::Safety;
  unsigned horizon = 1;
  std::vector<CellRole> lower_roles, upper_roles;  ///< robust_cell_roles() of each bound
  /// The product set's elimination order (product_expectation_in_order()); empty: product_expectation()'s.
  std::vector<std::size_t> order = {};
};

struct RobustValues {
  std::vector<double> lower, upper;       ///< V_0 bounds per state cell
  std::vector<std::uint32_t> controller;  ///< [k * cells + cell]: the maximiser of the lower bound
  /// [k * cells + cell]: how far the maximiser's lower bound lies above the next best input's
  /// (infinite with one input): an engine whose sums round otherwise may pick another input where
  /// this is within its rounding.
  std::vector<double> margin;
};

namespace oracle_detail {

inline double role_value(CellRole role, SpecType spec) {
  if (role == CellRole::FixedOne) return 1.0;
  if (role == CellRole::FixedZero) return 0.0;
  return spec == SpecType::Safety ? 1.0 : 0.0;
}

// The bounds of every (cell, input, disturbance) row of the Free cells, per dimension; a lattice
// dimension (bounds/lattice.hpp: noise-free, every row's mean box within one cell) gets the
// point masses of lattice_bounds().
inline std::vector<std::vector<DimensionBounds>> oracle_row_bounds(const RobustProblem& p) {
  const std::size_t dims = p.states.dims();
  std::vector<MassBounds> per_dimension;
  for (std::size_t d = 0; d < dims; ++d) per_dimension.emplace_back(p.noise, d);
  const std::size_t inputs = p.inputs.size(), disturbances = p.disturbances.size();
  const std::size_t row_count = p.states.size() * inputs * disturbances;
  std::vector<std::vector<double>> lo(row_count), hi(row_count);
  std::vector<bool> free_row(row_count, false), lattice(dims);
  for (std::size_t d = 0; d < dims; ++d) lattice[d] = noise_free(p.noise, d);
  for (std::size_t cell = 0; cell < p.states.size(); ++cell) {
    if (p.lower_roles[cell] != CellRole::Free && p.upper_roles[cell] != CellRole::Free) continue;
    for (std::size_t r = cell * inputs * disturbances; r < (cell + 1) * inputs * disturbances; ++r) {
      lo[r].assign(dims, 0.0);
      hi[r].assign(dims, 0.0);
      std::vector<double> expansion(dims, 0.0);
      p.mean_box(cell, (r / disturbances) % inputs, r % disturbances, lo[r].data(), hi[r].data(), expansion.data());
      free_row[r] = true;
      for (std::size_t d = 0; d < dims; ++d)
        lattice[d] = lattice[d] && lattice_row(p.states, d, lo[r][d], hi[r][d], expansion[d]);
    }
  }
  std::vector<std::vector<DimensionBounds>> rows(row_count);
  std::vector<std::size_t> multi(dims);
  for (std::size_t r = 0; r < row_count; ++r) {
    if (!free_row[r]) continue;
    p.states.multi_index(r / (inputs * disturbances), multi.data());
    for (std::size_t d = 0; d < dims; ++d) {
      const auto k = std::int64_t(multi[d]);
      const MassInterval scale = per_dimension[d].scale_range(p.states.face(d, k), p.states.face(d, k + 1));
      rows[r].push_back(lattice[d] ? lattice_bounds(p.states, d, lo[r][d], hi[r][d])
                                   : per_dimension[d].dimension_bounds(p.states, lo[r][d], hi[r][d], scale.lo, scale.hi));
    }
  }
  return rows;
}
}  // namespace oracle_detail

/// Backward recursion over the horizon: lower = max_u min_w pessimistic expectation of the next
/// lower values, upper = max_u min_w optimistic expectation of the next upper values; fixed cells
/// hold their role's value, Free cells start at 1 (safety) or 0. Ties keep the lowest input.
inline RobustValues robust_values(const RobustProblem& p, AmbiguitySet set) {
  const std::size_t cells = p.states.size(), inputs = p.inputs.size(), disturbances = p.disturbances.size();
  const std::vector<std::vector<DimensionBounds>> rows = oracle_detail::oracle_row_bounds(p);
  std::vector<IntervalRow> joint(set == AmbiguitySet::Joint ? rows.size() : 0);
  for (std::size_t r = 0; r < joint.size(); ++r)
    if (!rows[r].empty()) joint[r] = joint_row(p.states, rows[r]);
  auto expectation = [&](std::size_t row, const std::vector<double>& values, Bound bound) {
    if (set == AmbiguitySet::Joint) return joint_expectation(joint[row], values.data(), bound);
    if (p.order.empty()) return product_expectation(p.states, rows[row], values.data(), bound);
    std::vector<DimensionView> views;
    for (const DimensionBounds& dimension : rows[row]) views.push_back(view_of(dimension));
    return product_expectation_in_order(p.states, views.data(), values.data(), bound, p.order);
  };

  RobustValues out;
  out.lower.resize(cells);
  out.upper.resize(cells);
  out.controller.assign(std::size_t(p.horizon) * cells, 0);
  out.margin.assign(std::size_t(p.horizon) * cells, std::numeric_limits<double>::infinity());
  for (std::size_t cell = 0; cell < cells; ++cell) {
    out.lower[cell] = oracle_detail::role_value(p.lower_roles[cell], p.spec);
    out.upper[cell] = oracle_detail::role_value(p.upper_roles[cell], p.spec);
  }
  for (unsigned k = p.horizon; k-- > 0;) {
    const std::vector<double> next_lower = out.lower, next_upper = out.upper;
    for (std::size_t cell = 0; cell < cells; ++cell) {
      double best_lower = -1.0, best_upper = -1.0, second_lower = -1.0;
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
          second_lower = best_lower;
          best_lower = worst_lower;
          out.controller[std::size_t(k) * cells + cell] = std::uint32_t(u);
        } else if (p.lower_roles[cell] == CellRole::Free) {
          second_lower = std::max(second_lower, worst_lower);
        }
        best_upper = std::max(best_upper, worst_upper);
      }
      if (p.lower_roles[cell] == CellRole::Free) out.lower[cell] = best_lower;
      if (p.lower_roles[cell] == CellRole::Free && inputs > 1)
        out.margin[std::size_t(k) * cells + cell] = best_lower - second_lower;
      if (p.upper_roles[cell] == CellRole::Free) out.upper[cell] = best_upper;
    }
  }
  return out;
}

/// The oracle's bounds of an abstraction's configuration: its cell roles of each bound, and its
/// mean boxes from the image enclosures of its dynamics unless `mean_box` gives others.
inline RobustValues robust_values_of(const Abstraction& a, AmbiguitySet set, std::vector<std::size_t> order = {},
                                     MeanBox mean_box = nullptr) {
  const ImageEnclosure enclosure(a.config);
  const RobustProblem problem{a.states,
                              a.inputs,
                              a.disturbances,
                              *a.noise,
                              mean_box ? mean_box : enclosure_mean_box(enclosure, a.states, a.inputs, a.disturbances),
                              a.spec,
                              a.horizon,
                              robust_cell_roles(a.states, a.config.spec, Bound::Lower),
                              robust_cell_roles(a.states, a.config.spec, Bound::Upper),
                              std::move(order)};
  return robust_values(problem, set);
}

}  // namespace amytiss::detail
