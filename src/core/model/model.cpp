// The dynamics of a configuration: which model (expressions, a built-in model) and whether an
// integrator steps it.
#include "amytiss/model.hpp"

#include <string>

#include "common/require.hpp"
#include "model/builtin_fields.hpp"
#include "model/expression_models.hpp"
#include "model/integrated_dynamics.hpp"

namespace amytiss {
namespace {

// The configuration passed Config::validate(); a violation is a bug of the caller.
constexpr detail::Require require{"make_dynamics: expected a validated configuration: "};

}  // namespace

std::unique_ptr<VectorField> make_vector_field(const Config& config) {
  const std::size_t n = config.states.lb.size();
  const std::size_t m = config.inputs ? config.inputs->lb.size() : 0;
  const std::size_t p = config.disturbances ? config.disturbances->lb.size() : 0;
  if (config.model.empty()) {
    if (!config.integrator.tau) return nullptr;
    require(config.dynamics.size() == n, "one dynamics expression per state dimension");
    return detail::make_expression_field(parse_dynamics(config), m, p);
  }
  for (const auto& info : builtin_models()) {
    if (info.name != config.model) continue;
    require(info.state_dims == n && info.input_dims == m && info.disturbance_dims == p,
            "grids with the dimensions of model " + info.name);
    if (auto field = detail::make_builtin_field(info)) return field;
  }
  require(false, "a built-in model name, got '" + config.model + "'");
  return nullptr;
}

std::unique_ptr<Dynamics> make_dynamics(const Config& config) {
  require(config.states.lb.size() <= kMaxIntegratorStates || (config.model.empty() && !config.integrator.tau),
          "at most " + std::to_string(kMaxIntegratorStates) + " integrated states");
  if (auto field = make_vector_field(config)) {
    double tau = config.integrator.tau.value_or(0.0);
    for (const auto& info : builtin_models())
      if (info.name == config.model && !config.integrator.tau) tau = info.tau;
    return detail::make_integrated_dynamics(std::move(field), config.integrator, tau);
  }
  require(config.integrator.is_default(), "an integrator.tau for integrated expressions");
  require(config.dynamics.size() == config.states.lb.size(), "one dynamics expression per state dimension");
  return detail::make_expression_dynamics(parse_dynamics(config), config.inputs ? config.inputs->lb.size() : 0,
                                          config.disturbances ? config.disturbances->lb.size() : 0);
}

}  // namespace amytiss
