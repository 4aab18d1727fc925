#include "opencl/factored/tables.hpp"

#include <algorithm>
#include <cassert>

namespace amytiss::detail {

std::vector<MassTable> factored_mass_tables(const Abstraction& a, const FactoredPlan& plan) {
  const std::size_t dims = a.states.dims();
  std::vector<double> x(dims), u(std::max<std::size_t>(1, a.inputs.dims())),
      w(std::max<std::size_t>(1, a.disturbances.dims())), post(dims);
  auto component = [&](const FactorVariable& variable) -> double& {
    switch (variable.space) {
      case FactorVariable::Space::State: return x[variable.index];
      case FactorVariable::Space::Input: return u[variable.index];
      default: return w[variable.index];
    }
  };
  auto coordinate = [&](const FactorVariable& variable, std::size_t k) {
    switch (variable.space) {
      case FactorVariable::Space::State: return a.states.coordinate(variable.index, k);
      case FactorVariable::Space::Input: return a.inputs.coordinate(variable.index, k);
      default: return a.disturbances.coordinate(variable.index, k);
    }
  };
  std::vector<MassTable> tables(dims);
  for (std::size_t dim = 0; dim < dims; ++dim) {
    MassTable& table = tables[dim];
    table.variables = plan.reads[dim];
    table.width = plan.stages[std::size_t(std::find(plan.order.begin(), plan.order.end(), dim) - plan.order.begin())].width;
    // Components f_dim does not read keep their first grid value: the post coordinate is the same.
    for (const FactorVariable& variable : plan.variables) component(variable) = coordinate(variable, 0);
    std::size_t tuples = 1;
    for (std::size_t v : table.variables) tuples *= plan.variables[v].count;
    table.first.assign(tuples, 0);
    table.count.assign(tuples, 0);
    table.masses.assign(tuples * table.width, 0.0);
    std::vector<std::size_t> digit(table.variables.size(), 0);
    for (std::size_t tuple = 0; tuple < tuples; ++tuple) {
      for (std::size_t j = 0; j < digit.size(); ++j)
        component(plan.variables[table.variables[j]]) = coordinate(plan.variables[table.variables[j]], digit[j]);
      a.dynamics->evaluate(x.data(), u.data(), w.data(), post.data());
      std::int64_t first = 0, last = -1;
      if (a.noise->dimension_window(a.states, dim, post[dim], &first, &last)) {
        assert(std::size_t(last - first + 1) <= table.width);
        table.first[tuple] = std::uint32_t(first);
        table.count[tuple] = std::uint32_t(last - first + 1);
        a.noise->cell_masses(dim, first, last, post[dim], a.noise->scale(dim, x.data()),
                             &table.masses[tuple * table.width]);
      }
      for (std::size_t j = digit.size(); j-- > 0;) {  // next tuple, the last digit fastest
        if (++digit[j] < plan.variables[table.variables[j]].count) break;
        digit[j] = 0;
      }
    }
  }
  return tables;
}

}  // namespace amytiss::detail
