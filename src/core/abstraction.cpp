#include "amytiss/abstraction.hpp"

#include <string>

#include "amytiss/errors.hpp"

namespace amytiss {
namespace {

void check_box(const Box& box, std::size_t dims, const std::string& key) {
  if (box.lb.size() != dims || box.ub.size() != dims)
    throw ConfigError(key, "lb and ub have " + std::to_string(box.lb.size()) + " and " +
                               std::to_string(box.ub.size()) + " values, expected " +
                               std::to_string(dims) + " each (one per state dimension)");
}

}  // namespace

std::vector<CellRole> cell_roles(const Grid& states, const SpecConfig& spec) {
  std::vector<CellRole> roles(states.size(), CellRole::Free);
  const std::size_t dims = states.dims();
  switch (spec.type) {
    case SpecType::Safety:
      if (spec.safe) {
        check_box(*spec.safe, dims, "spec.safe");
        for (std::size_t cell = 0; cell < roles.size(); ++cell)
          if (!states.point_in_box(cell, *spec.safe)) roles[cell] = CellRole::FixedZero;
      }
      break;
    case SpecType::Reachability:
    case SpecType::ReachAvoid: {
      if (!spec.target)
        throw ConfigError("spec.target", "missing, expected a box for " + to_string(spec.type) +
                                             " (example: target: {lb: [5, 5], ub: [7, 7]})");
      check_box(*spec.target, dims, "spec.target");
      const bool with_avoid = spec.type == SpecType::ReachAvoid && spec.avoid.has_value();
      if (with_avoid) check_box(*spec.avoid, dims, "spec.avoid");
      for (std::size_t cell = 0; cell < roles.size(); ++cell) {
        if (with_avoid && states.point_in_box(cell, *spec.avoid))
          roles[cell] = CellRole::FixedZero;
        else if (states.point_in_box(cell, *spec.target))
          roles[cell] = CellRole::FixedOne;
      }
      break;
    }
  }
  return roles;
}

Abstraction Abstraction::from_config(const Config& config) {
  config.validate();
  std::shared_ptr<const Dynamics> dynamics = make_dynamics(config);
  return from_parts(config, std::move(dynamics));
}

Abstraction Abstraction::from_parts(const Config& config, std::shared_ptr<const Dynamics> dynamics) {
  Abstraction abstraction;
  abstraction.config = config;
  abstraction.states = Grid(config.states);
  if (abstraction.states.dims() == 0)
    throw ConfigError("states", "no dimensions, expected at least one (example: lb: [-10], ub: [10], eta: [0.5])");
  if (config.inputs) abstraction.inputs = Grid(*config.inputs);
  if (config.disturbances) abstraction.disturbances = Grid(*config.disturbances);
  if (!dynamics) throw ConfigError("dynamics", "no dynamics given");
  if (dynamics->state_dims() != abstraction.states.dims() ||
      dynamics->input_dims() != abstraction.inputs.dims() ||
      dynamics->disturbance_dims() != abstraction.disturbances.dims())
    throw ConfigError("dynamics", "the dynamics has " + std::to_string(dynamics->state_dims()) + "/" +
                                      std::to_string(dynamics->input_dims()) + "/" +
                                      std::to_string(dynamics->disturbance_dims()) +
                                      " state/input/disturbance dimensions, the grids have " +
                                      std::to_string(abstraction.states.dims()) + "/" +
                                      std::to_string(abstraction.inputs.dims()) + "/" +
                                      std::to_string(abstraction.disturbances.dims()));
  abstraction.dynamics = std::move(dynamics);
  abstraction.noise = std::make_shared<NoiseModel>(config.noise, abstraction.states);
  if (config.spec.horizon == 0)
    throw ConfigError("spec.horizon", "got 0, expected a positive number of steps (example: horizon: 16)");
  abstraction.spec = config.spec.type;
  abstraction.horizon = config.spec.horizon;
  abstraction.roles = cell_roles(abstraction.states, config.spec);
  return abstraction;
}

double Abstraction::terminal_value(CellRole role) const {
  switch (role) {
    case CellRole::FixedOne: return 1.0;
    case CellRole::FixedZero: return 0.0;
    case CellRole::Free: return spec == SpecType::Safety ? 1.0 : 0.0;
  }
  return 0.0;
}

}  // namespace amytiss
