// Config::validate(): the one place that judges a configuration (docs/configuration.md). Errors
// name the key, the value received and an example of a valid value.
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "amytiss/config.hpp"
#include "amytiss/expression.hpp"
#include "amytiss/grid.hpp"
#include "amytiss/grid_rules.hpp"
#include "amytiss/model.hpp"
#include "config/messages.hpp"
#include "config/refine_section.hpp"

namespace amytiss {
namespace {

using detail::check_finite_list;
using detail::check_noise;
using detail::check_obstacles;
using detail::fail;
using detail::format_list;
using detail::indexed;
using detail::join;

using detail::kMaxGridPoints;
constexpr double kMaxPolicyBytes = 16.0 * 1024 * 1024 * 1024;   // 16 GiB
constexpr unsigned kMaxHorizon = 1000000000;  // the policy arrays' 16 GiB limit is checked apart

const char* const kGridExample = "{lb: [-10, -10], ub: [10, 10], eta: [0.5, 0.5]}";

/// Checks a grid and returns its number of points (saturated at UINT64_MAX).
double check_grid(const GridSpec& grid, const std::string& key, const std::string& omit_hint) {
  const std::string example = key.substr(key.rfind('.') + 1) + ": " + kGridExample;
  if (grid.lb.empty())
    throw ConfigError(key + ".lb", "got [], expected at least one value" + omit_hint + " (example: " + example + ")");
  check_finite_list(grid.lb, key + ".lb", example);
  check_finite_list(grid.ub, key + ".ub", example);
  check_finite_list(grid.eta, key + ".eta", example);
  if (grid.ub.size() != grid.lb.size())
    fail(key + ".ub", std::to_string(grid.ub.size()) + " values", std::to_string(grid.lb.size()) +
         " values, as many as " + key + ".lb", example);
  if (grid.eta.size() != grid.lb.size())
    fail(key + ".eta", std::to_string(grid.eta.size()) + " values", std::to_string(grid.lb.size()) +
         " values, as many as " + key + ".lb", example);
  double points = 1;
  for (std::size_t i = 0; i < grid.lb.size(); ++i) {
    if (grid.eta[i] <= 0)
      fail(indexed(key + ".eta", i), format_number(grid.eta[i]), "a number > 0", "eta: [0.5, 0.5]");
    if (grid.lb[i] > grid.ub[i])
      fail(indexed(key + ".ub", i), format_number(grid.ub[i]),
           "a number >= " + key + ".lb[" + std::to_string(i) + "] = " + format_number(grid.lb[i]), example);
    points *= grid_points(grid.lb[i], grid.ub[i], grid.eta[i]);
  }
  if (points > double(kMaxGridPoints))
    throw ConfigError(key, "grid too large: " + format_number(points) +
                               " points, at most 4294967295 (2^32 - 1) are supported; use a larger eta");
  return points;
}

// The key of box `index` of a region: the region's own key for a single box (as before unions
// existed), else key[index].
std::string box_key(const std::string& key, const Region& region, std::size_t index) {
  return region.boxes.size() == 1 ? key : indexed(key, index);
}

// A cell in both sets would silently become avoid (avoid wins in the roles): refuse every pair of
// a target box and an avoid box with a common grid point.
void check_boxes_disjoint(const Box& target, const std::string& target_key, const Box& avoid,
                          const std::string& avoid_key, const Grid& states) {
  std::vector<double> shared;
  for (std::size_t i = 0; i < states.dims(); ++i) {
    const IndexRange in_target = box_index_range(states, i, target.lb[i], target.ub[i]);
    const IndexRange in_avoid = box_index_range(states, i, avoid.lb[i], avoid.ub[i]);
    const std::int64_t first = std::max(in_target.first, in_avoid.first);
    if (first > std::min(in_target.last, in_avoid.last)) return;
    shared.push_back(states.coordinate(i, std::size_t(first)));
  }
  auto named = [](const std::string& key, const std::string& plain) {
    return key == plain ? std::string() : " " + key;
  };
  throw ConfigError(avoid_key, "the avoid box" + named(avoid_key, "spec.avoid") + " " + format_list(avoid.lb) +
                                   " .. " + format_list(avoid.ub) + " and the target box" +
                                   named(target_key, "spec.target") + " " + format_list(target.lb) + " .. " +
                                   format_list(target.ub) + " share grid points, for example " +
                                   format_list(shared) +
                                   "; expected boxes without a common grid point (shrink one of them)");
}

void check_target_avoid_disjoint(const Region& target, const Region& avoid, const Grid& states) {
  for (std::size_t j = 0; j < avoid.boxes.size(); ++j)
    for (std::size_t i = 0; i < target.boxes.size(); ++i)
      check_boxes_disjoint(target.boxes[i], box_key("spec.target", target, i), avoid.boxes[j],
                           box_key("spec.avoid", avoid, j), states);
}

void check_box(const Box& box, const std::string& key, const Grid& states) {
  std::string name = key.substr(key.rfind('.') + 1);
  name = name.substr(0, name.find('['));  // "avoid" of "spec.avoid[2]"
  const std::string example = name + ": {lb: [5, 5], ub: [7, 7]}";
  const std::size_t n = states.dims();
  if (box.lb.size() != n)
    fail(key + ".lb", std::to_string(box.lb.size()) + " values", std::to_string(n) + " values (one per state)", example);
  if (box.ub.size() != n)
    fail(key + ".ub", std::to_string(box.ub.size()) + " values", std::to_string(n) + " values (one per state)", example);
  check_finite_list(box.lb, key + ".lb", example);
  check_finite_list(box.ub, key + ".ub", example);
  for (std::size_t i = 0; i < n; ++i) {
    if (box.lb[i] > box.ub[i])
      fail(indexed(key + ".ub", i), format_number(box.ub[i]),
           "a number >= " + key + ".lb[" + std::to_string(i) + "] = " + format_number(box.lb[i]), example);
    // The membership rule of Grid::point_in_box (grid_rules.hpp).
    const std::size_t count = states.count(i);
    const IndexRange inside = box_index_range(states, i, box.lb[i], box.ub[i]);
    if (inside.first > inside.last)
      throw ConfigError(key, "the box " + format_list(box.lb) + " .. " + format_list(box.ub) +
                                 " contains no representative point of the state grid in dimension " +
                                 std::to_string(i) + " (points " + format_number(states.coordinate(i, 0)) + ", " +
                                 format_number(states.uniform(i) ? states.lb()[i] + states.eta()[i]
                                                                 : states.coordinate(i, std::min<std::size_t>(1, count - 1))) +
                                 ", ..., " + format_number(states.coordinate(i, count - 1)) +
                                 "); widen the box or refine states.eta (example: " + example + ")");
  }
}

// Each box as a single box is checked, under its own key (spec.avoid[2].lb).
void check_region(const Region& region, const std::string& key, const Grid& states) {
  if (region.boxes.empty())
    fail(key, "[]", "a box or a non-empty list of boxes",
         key.substr(key.rfind('.') + 1) + ": [{lb: [5, 5], ub: [7, 7]}, {lb: [-7, 5], ub: [-5, 7]}]");
  for (std::size_t i = 0; i < region.boxes.size(); ++i) check_box(region.boxes[i], box_key(key, region, i), states);
}

bool is_identifier(const std::string& name) {
  if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) return false;
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

bool looks_like_variable(const std::string& name) {
  if (name.size() < 2 || std::string("xuw").find(name[0]) == std::string::npos) return false;
  for (std::size_t i = 1; i < name.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(name[i]))) return false;
  return true;
}

void check_integrator(const IntegratorConfig& integrator, bool expressions, std::size_t n) {
  const char* const example = "integrator: {method: rk4, substeps: 4, tau: 0.1}";
  if (integrator.substeps < 1 || integrator.substeps > kMaxIntegratorSubsteps)
    fail("integrator.substeps", std::to_string(integrator.substeps),
         "an integer in [1, " + std::to_string(kMaxIntegratorSubsteps) + "]", example);
  if (integrator.tau && !(std::isfinite(*integrator.tau) && *integrator.tau > 0))
    fail("integrator.tau", format_number(*integrator.tau), "a time step in seconds > 0", example);
  if (expressions && !integrator.is_default() && !integrator.tau)
    throw ConfigError("integrator.tau",
                      "missing: with an integrator, `dynamics` are the vector field dx/dt and need the length of "
                      "one time step in seconds (example: " + std::string(example) + ")");
  const bool integrated = !expressions || integrator.tau;
  if (integrated && n > kMaxIntegratorStates)
    throw ConfigError("integrator", "an integrated model has at most " + std::to_string(kMaxIntegratorStates) +
                                        " state dimensions, got " + std::to_string(n) +
                                        "; give `dynamics` as the discrete map without `integrator`");
}

void check_constants(const std::map<std::string, double>& constants) {
  for (const auto& constant : constants) {
    const std::string key = "constants." + constant.first;
    // z is the variable of noise densities.
    const bool reserved = constant.first == "pi" || constant.first == "z" || looks_like_variable(constant.first) ||
                          is_function_name(constant.first);
    if (!is_identifier(constant.first) || reserved)
      throw ConfigError(key, "got the name '" + constant.first +
                                 "', expected a name of letters, digits and '_' that is not pi, a variable "
                                 "(x0, u1, ..., z) or a function (example: constants: {tau: 10.0})");
    if (!std::isfinite(constant.second)) fail(key, format_number(constant.second), "a finite number", "tau: 10.0");
  }
}

// Either expressions, one per state dimension, that parse; or a built-in model with its dimensions.
void check_dynamics(const Config& config) {
  const std::size_t n = config.states.lb.size();
  const std::size_t m = config.inputs ? config.inputs->lb.size() : 0;
  const std::size_t p = config.disturbances ? config.disturbances->lb.size() : 0;
  if (!config.model.empty() && !config.dynamics.empty())
    throw ConfigError("model", "both `model` and `dynamics` are given; use one (example: model: bmw320i)");
  if (config.model.empty()) {
    if (config.dynamics.empty())
      throw ConfigError("dynamics", "missing, expected one expression per state dimension or a built-in `model` "
                                    "(example: dynamics: [\"x0 + tau*u0*cos(u1) + w0\", \"x1 + tau*u0*sin(u1) + w0\"])");
    if (config.dynamics.size() != n)
      fail("dynamics", std::to_string(config.dynamics.size()) + " expressions",
           std::to_string(n) + ", one per state dimension (states.lb has " + std::to_string(n) + " values)",
           "dynamics: [\"x0 + tau*u0*cos(u1) + w0\", \"x1 + tau*u0*sin(u1) + w0\"]");
    parse_dynamics(config);
  } else {
    const BuiltinModelInfo* info = nullptr;
    std::vector<std::string> names;
    for (const auto& candidate : builtin_models()) {
      names.push_back(candidate.name);
      if (candidate.name == config.model) info = &candidate;
    }
    if (!info) fail("model", "'" + config.model + "'", "one of " + join(names), "model: bmw320i");
    auto check_dims = [&](const char* key, std::size_t have, std::size_t want) {
      if (have != want)
        throw ConfigError(key, "model " + config.model + " needs " + std::to_string(want) + " dimensions, got " +
                                   std::to_string(have) + " (" + info->description + ")");
    };
    check_dims("states.lb", n, info->state_dims);
    check_dims("inputs.lb", m, info->input_dims);
    check_dims("disturbances.lb", p, info->disturbance_dims);
  }
}

void check_spec(const SpecConfig& spec, const GridSpec& fitted) {
  const Grid states(fitted);
  if (spec.unbounded) {
    const double tolerance = spec.tolerance_or_default();
    if (!(tolerance > 0 && tolerance < 1))
      fail("spec.tolerance", format_number(tolerance), "a number in (0, 1)", "tolerance: 1.0e-6");
  } else {
    if (spec.tolerance)
      throw ConfigError("spec.tolerance", "given but spec.horizon is " + std::to_string(spec.horizon) +
                                              "; the tolerance is for horizon: infinite");
    if (spec.horizon < 1 || spec.horizon > kMaxHorizon)
      fail("spec.horizon", std::to_string(spec.horizon),
           "an integer >= 1 and <= 1000000000 (number of time steps; the policy arrays must also fit in 16 GiB) "
           "or infinite",
           "horizon: 16 (or horizon: infinite)");
  }
  switch (spec.type) {
    case SpecType::Safety:
      if (spec.target) throw ConfigError("spec.target", "given for spec.type safety; safety uses `safe` (or the whole grid)");
      if (spec.avoid) throw ConfigError("spec.avoid", "given for spec.type safety; use reach_avoid, or `safe` for the set to stay in");
      if (spec.safe) check_region(*spec.safe, "spec.safe", states);
      break;
    case SpecType::Reachability:
    case SpecType::ReachAvoid:
      if (spec.safe) throw ConfigError("spec.safe", "given for spec.type " + to_string(spec.type) + "; `safe` is for safety only");
      if (!spec.target)
        throw ConfigError("spec.target", "missing, expected the target box (or a list of boxes) for " +
                                             to_string(spec.type) +
                                             " (example: target: {lb: [5, 5], ub: [7, 7]})");
      check_region(*spec.target, "spec.target", states);
      if (spec.avoid) {
        if (spec.type == SpecType::Reachability)
          throw ConfigError("spec.avoid", "given for spec.type reachability; use reach_avoid to avoid a set");
        check_region(*spec.avoid, "spec.avoid", states);
        check_target_avoid_disjoint(*spec.target, *spec.avoid, states);
      }
      break;
  }
  check_obstacles(spec, fitted);
}

void check_compute(const ComputeConfig& compute) {
  if (!(compute.memory_fraction > 0 && compute.memory_fraction <= 1))
    fail("compute.memory_fraction", format_number(compute.memory_fraction), "a fraction in (0, 1]",
         "memory_fraction: 0.5");

  for (std::size_t i = 0; i < compute.devices.size(); ++i) {
    const std::string& entry = compute.devices[i];
    if (entry == "all") {
      if (compute.devices.size() > 1)
        fail(indexed("compute.devices", i), "'all' beside other devices", "`all` alone or a list of devices",
             "devices: all");
      continue;
    }
    if (!parse_device_selector(entry))
      fail(indexed("compute.devices", i), "'" + entry + "'",
           "gpu:N, cpu:N or P.D (--list-devices numbers), optionally /C to split it into sub-devices of C "
           "compute units",
           "devices: [gpu:0, gpu:1]");
  }
  if (!compute.devices.empty() && compute.device == DeviceKind::Reference)
    fail("compute.devices", join(compute.devices), "no devices with compute.device: reference (it runs on the host)",
         "device: auto");
}

// The continuous-system bounds are products of one-dimensional masses, computed on the host.
void check_guarantee(const Config& config) {
  if (config.guarantee != Guarantee::System) {
    if (config.compute.bounds_method != BoundsMethod::Auto)
      fail("compute.bounds_method", to_string(config.compute.bounds_method),
           "auto with guarantee: abstraction (the bounds' methods are those of guarantee: system)",
           "bounds_method: auto");
    return;
  }
  const std::size_t n = config.states.lb.size();
  const std::vector<double>& covariance = config.noise.covariance;
  if (covariance.size() == n * n && n > 1)
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j)
        if (i != j && covariance[i * n + j] != 0.0)
          fail("noise.covariance", "a full matrix (entry [" + std::to_string(i) + "][" + std::to_string(j) +
                                       "] = " + format_number(covariance[i * n + j]) + ")",
               "a diagonal covariance with guarantee: system (its transition bounds are products of "
               "one-dimensional masses)",
               "covariance: [0.75, 0.75]");
  if (config.compute.device == DeviceKind::Cpu || config.compute.device == DeviceKind::Gpu)
    fail("compute.device", to_string(config.compute.device),
         "auto or reference with guarantee: system (its interval bounds are computed on the host's cores)",
         "device: auto");
  if (!config.compute.devices.empty())
    fail("compute.devices", join(config.compute.devices),
         "no devices with guarantee: system (its interval bounds are computed on the host's cores)", "device: auto");
}

void check_policy_size(double state_points, const SpecConfig& spec, bool system_bounds) {
  // An unbounded policy is stored like one step (and its upper bound); continuous-system bounds
  // store an upper bound beside every value.
  const double stored_steps = spec.unbounded ? 2.0 : double(spec.horizon);
  const double value_bytes = system_bounds && !spec.unbounded ? 16 : 8;
  const double policy_bytes = state_points * ((stored_steps + 1) * value_bytes + stored_steps * 4);
  if (policy_bytes > kMaxPolicyBytes) {
    char text[300];
    std::snprintf(text, sizeof text,
                  "grid too large: %.0f states x (%u+1 values x %.0f bytes + %u inputs x 4 bytes) = %.1f GiB of "
                  "policy arrays, more than the 16 GiB supported; use a larger states.eta or a shorter horizon",
                  state_points, spec.horizon, value_bytes, spec.horizon, policy_bytes / (1024.0 * 1024 * 1024));
    throw ConfigError("states", text);
  }
}

}  // namespace

void Config::validate() const {
  if (name.empty()) fail("name", "\"\"", "a non-empty name", "name: robot_reach_avoid");
  const double given_points =
      states.faces.empty() ? check_grid(states, "states", "") : detail::check_faced_states(states, kMaxGridPoints);
  if (inputs) check_grid(*inputs, "inputs", "; omit `inputs` for an autonomous system");
  if (disturbances) check_grid(*disturbances, "disturbances", "; omit `disturbances` when there are none");
  check_constants(constants);
  check_dynamics(*this);
  check_integrator(integrator, model.empty(), states.lb.size());
  check_noise(noise, states.lb.size(), constants);
  detail::check_fit_sets(*this);
  const GridSpec fitted = fitted_states(*this);
  double state_points = given_points;
  if (fit_sets) {
    state_points = double(Grid(fitted).size());
    if (state_points > double(kMaxGridPoints))
      throw ConfigError("states.fit_sets", "the fitted grid has " + format_number(state_points) +
                                               " points, at most 4294967295 (2^32 - 1) are supported; use a larger eta");
  }
  check_spec(spec, fitted);
  detail::check_refine(*this, fitted);
  check_compute(compute);
  check_guarantee(*this);
  check_policy_size(state_points, spec, guarantee == Guarantee::System);
}

}  // namespace amytiss
