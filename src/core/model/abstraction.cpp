#include "amytiss/abstraction.hpp"

#include <chrono>
#include <string>

#include "amytiss/errors.hpp"
#include "amytiss/footprint.hpp"
#include "amytiss/grid_rules.hpp"
#include "common/require.hpp"

namespace amytiss {
namespace {

// Inputs here passed Config::validate(); a violation is a bug of the caller.
constexpr detail::Require require{"Abstraction: expected a validated configuration: "};

void require_region(const Region& region, std::size_t dims) {
  require(!region.boxes.empty(), "sets of at least one box");
  for (const Box& box : region.boxes)
    require(box.lb.size() == dims && box.ub.size() == dims, "boxes with one bound per state dimension");
}

}  // namespace

std::vector<CellRole> cell_roles(const Grid& states, const SpecConfig& spec, const SetupPoll& poll) {
  std::vector<CellRole> roles(states.size(), CellRole::Free);
  const std::size_t dims = states.dims();
  // The footprint test judges the whole cell, not only its point: no pose of the cell may touch.
  const std::vector<bool> touched = obstacle_cells(states, spec, poll);
  switch (spec.type) {
    case SpecType::Safety:
      if (spec.safe) require_region(*spec.safe, dims);
      for (std::size_t cell = 0; cell < roles.size(); ++cell)
        if (touched[cell] || (spec.safe && !states.point_in_region(cell, *spec.safe)))
          roles[cell] = CellRole::FixedZero;
      break;
    case SpecType::Reachability:
    case SpecType::ReachAvoid: {
      require(spec.target.has_value(), "a target set for reachability and reach_avoid");
      require_region(*spec.target, dims);
      const bool with_avoid = spec.type == SpecType::ReachAvoid && spec.avoid.has_value();
      if (with_avoid) require_region(*spec.avoid, dims);
      for (std::size_t cell = 0; cell < roles.size(); ++cell) {
        if (touched[cell] || (with_avoid && states.point_in_region(cell, *spec.avoid)))
          roles[cell] = CellRole::FixedZero;
        else if (states.point_in_region(cell, *spec.target))
          roles[cell] = CellRole::FixedOne;
      }
      break;
    }
  }
  return roles;
}

Abstraction Abstraction::from_config(const Config& config, const ProgressCallback& progress) {
  std::shared_ptr<const Dynamics> dynamics = make_dynamics(config);
  return from_parts(config, std::move(dynamics), progress);
}

Abstraction Abstraction::from_parts(const Config& config, std::shared_ptr<const Dynamics> dynamics,
                                    const ProgressCallback& progress) {
  Abstraction abstraction;
  abstraction.config = config;
  abstraction.states = Grid(fitted_states(config));
  require(abstraction.states.dims() > 0, "at least one state dimension");
  if (config.inputs) abstraction.inputs = Grid(*config.inputs);
  if (config.disturbances) abstraction.disturbances = Grid(*config.disturbances);
  require(dynamics != nullptr, "a dynamics");
  require(dynamics->state_dims() == abstraction.states.dims() && dynamics->input_dims() == abstraction.inputs.dims() &&
              dynamics->disturbance_dims() == abstraction.disturbances.dims(),
          "a dynamics with the grids' state, input and disturbance dimensions");
  abstraction.dynamics = std::move(dynamics);
  abstraction.noise = std::make_shared<NoiseModel>(config.noise, abstraction.states, config.constants);
  require(config.spec.unbounded || config.spec.horizon > 0, "a horizon of at least one step");
  abstraction.spec = config.spec.type;
  abstraction.unbounded = config.spec.unbounded;
  abstraction.tolerance = config.spec.tolerance_or_default();
  // An unbounded specification's stationary policy is laid out like one step of a finite one.
  abstraction.horizon = config.spec.unbounded ? 1 : config.spec.horizon;
  const auto setup_start = std::chrono::steady_clock::now();
  const unsigned total = abstraction.unbounded ? 0 : abstraction.horizon;
  const SetupPoll poll = [&] {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
    if (progress && !progress({Phase::Setup, 0, total, "", elapsed, -1})) throw Cancelled();
  };
  abstraction.roles = cell_roles(abstraction.states, config.spec, poll);
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
