#include "amytiss/config.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "amytiss/errors.hpp"
#include "amytiss/expression.hpp"
#include "amytiss/noise.hpp"
#include "amytiss/model.hpp"

namespace amytiss {

namespace {

constexpr std::uint64_t kMaxGridPoints = 4294967295ull;          // 2^32 - 1: indices are uint32
constexpr double kMaxPolicyBytes = 16.0 * 1024 * 1024 * 1024;   // 16 GiB
constexpr double kSymmetryTolerance = 1e-12;

// ---------------------------------------------------------------------------------------------
// Text helpers

std::string format_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[40];
  // The shortest of 15..17 significant digits that reads back to the same double.
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  return buffer;
}

std::string format_list(const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) text += ", ";
    text += format_number(values[i]);
  }
  return text + "]";
}

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

std::string indexed(const std::string& key, std::size_t index) {
  return key + "[" + std::to_string(index) + "]";
}

std::string join(const std::vector<std::string>& items) {
  std::string text;
  for (const auto& item : items) text += (text.empty() ? "" : ", ") + item;
  return text;
}

std::string node_text(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) return node.Scalar();
  if (node.IsSequence()) return "a list";
  return "a map";
}

// ---------------------------------------------------------------------------------------------
// Reading YAML with the key in every error

[[noreturn]] void fail(const std::string& key, const std::string& got, const std::string& expected,
                       const std::string& example) {
  throw ConfigError(key, "got " + got + ", expected " + expected + " (example: " + example + ")");
}

void check_keys(const YAML::Node& node, const std::string& key, const std::vector<std::string>& allowed,
                const std::string& example) {
  if (!node.IsMap()) fail(key, node_text(node), "a map", example);
  for (const auto& entry : node) {
    const std::string name = entry.first.Scalar();
    bool known = false;
    for (const auto& candidate : allowed) known = known || candidate == name;
    if (!known)
      throw ConfigError(key.empty() ? name : key + "." + name,
                        "unknown key (valid keys" + (key.empty() ? std::string() : " of " + key) + ": " +
                            join(allowed) + ")");
  }
}

bool present(const YAML::Node& node) { return node.IsDefined() && !node.IsNull(); }

double read_number(const YAML::Node& node, const std::string& key, const std::string& example) {
  if (!node.IsScalar()) fail(key, node_text(node), "a number", example);
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    fail(key, "'" + node.Scalar() + "'", "a number", example);
  }
}

std::vector<double> read_number_list(const YAML::Node& node, const std::string& key,
                                     const std::string& example) {
  if (!node.IsSequence()) fail(key, node_text(node), "a list of numbers", example);
  std::vector<double> values;
  for (std::size_t i = 0; i < node.size(); ++i) values.push_back(read_number(node[i], indexed(key, i), example));
  return values;
}

std::string read_string(const YAML::Node& node, const std::string& key, const std::string& example) {
  if (!node.IsScalar()) fail(key, node_text(node), "a text value", example);
  return node.Scalar();
}

template <typename Enum>
Enum read_enum(const YAML::Node& node, const std::string& key, const std::vector<std::pair<std::string, Enum>>& names,
               const std::string& example) {
  const std::string text = read_string(node, key, example);
  std::vector<std::string> valid;
  for (const auto& entry : names) {
    if (entry.first == text) return entry.second;
    valid.push_back(entry.first);
  }
  fail(key, "'" + text + "'", "one of " + join(valid), example);
}

const YAML::Node required(const YAML::Node& parent, const std::string& name, const std::string& key,
                          const std::string& example) {
  const YAML::Node node = parent[name];
  if (!present(node)) throw ConfigError(key, "missing, expected a value (example: " + example + ")");
  return node;
}

GridSpec read_grid(const YAML::Node& node, const std::string& key, const std::string& example) {
  check_keys(node, key, {"lb", "ub", "eta"}, key + ": " + example);
  GridSpec grid;
  grid.lb = read_number_list(required(node, "lb", key + ".lb", example), key + ".lb", example);
  grid.ub = read_number_list(required(node, "ub", key + ".ub", example), key + ".ub", example);
  grid.eta = read_number_list(required(node, "eta", key + ".eta", example), key + ".eta", example);
  return grid;
}

Box read_box(const YAML::Node& node, const std::string& key, const std::string& example) {
  check_keys(node, key, {"lb", "ub"}, key + ": " + example);
  Box box;
  box.lb = read_number_list(required(node, "lb", key + ".lb", example), key + ".lb", example);
  box.ub = read_number_list(required(node, "ub", key + ".ub", example), key + ".ub", example);
  return box;
}

// ---------------------------------------------------------------------------------------------
// Semantic checks

const char* const kGridExample = "{lb: [-10, -10], ub: [10, 10], eta: [0.5, 0.5]}";

std::uint64_t points_of_dimension(double lb, double ub, double eta) {
  return static_cast<std::uint64_t>(std::floor((ub - lb) / eta + 0.5)) + 1;
}

void check_finite_list(const std::vector<double>& values, const std::string& key, const std::string& example) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i])) fail(indexed(key, i), format_number(values[i]), "a finite number", example);
}

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
    points *= std::floor((grid.ub[i] - grid.lb[i]) / grid.eta[i] + 0.5) + 1;
  }
  if (points > double(kMaxGridPoints))
    throw ConfigError(key, "grid too large: " + format_number(points) +
                               " points, at most 4294967295 (2^32 - 1) are supported; use a larger eta");
  return points;
}

// Grid indices first..last of dimension i that a (validated) box contains, by the membership rule
// of Grid::point_in_box (closed box, 1e-9*eta tolerance).
std::pair<double, double> box_index_range(const Box& box, const GridSpec& states, std::size_t i) {
  const double eta = states.eta[i];
  const double count = double(points_of_dimension(states.lb[i], states.ub[i], eta));
  const double first = std::max(0.0, std::ceil((box.lb[i] - states.lb[i]) / eta - 1e-9));
  const double last = std::min(count - 1, std::floor((box.ub[i] - states.lb[i]) / eta + 1e-9));
  return {first, last};
}

// A cell in both boxes would silently become avoid (avoid wins in the roles): refuse it.
void check_target_avoid_disjoint(const Box& target, const Box& avoid, const GridSpec& states) {
  std::vector<double> shared;
  for (std::size_t i = 0; i < states.lb.size(); ++i) {
    const auto target_range = box_index_range(target, states, i);
    const auto avoid_range = box_index_range(avoid, states, i);
    const double first = std::max(target_range.first, avoid_range.first);
    const double last = std::min(target_range.second, avoid_range.second);
    if (first > last) return;
    shared.push_back(states.lb[i] + first * states.eta[i]);
  }
  throw ConfigError("spec.avoid", "the avoid box " + format_list(avoid.lb) + " .. " + format_list(avoid.ub) +
                                      " and the target box " + format_list(target.lb) + " .. " +
                                      format_list(target.ub) + " share grid points, for example " +
                                      format_list(shared) +
                                      "; expected boxes without a common grid point (shrink one of them)");
}

void check_box(const Box& box, const std::string& key, const GridSpec& states) {
  const std::string name = key.substr(key.rfind('.') + 1);
  const std::string example = name + ": {lb: [5, 5], ub: [7, 7]}";
  const std::size_t n = states.lb.size();
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
    // Same membership rule as Grid::point_in_box: closed box with a 1e-9*eta tolerance.
    const double eta = states.eta[i];
    const double count = double(points_of_dimension(states.lb[i], states.ub[i], eta));
    const auto [first, last] = box_index_range(box, states, i);
    if (first > last)
      throw ConfigError(key, "the box " + format_list(box.lb) + " .. " + format_list(box.ub) +
                                 " contains no representative point of the state grid in dimension " +
                                 std::to_string(i) + " (points " + format_number(states.lb[i]) + ", " +
                                 format_number(states.lb[i] + eta) + ", ..., " +
                                 format_number(states.lb[i] + (count - 1) * eta) +
                                 "); widen the box or refine states.eta (example: " + example + ")");
  }
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

const std::vector<std::string> kFunctionNames = {"sin", "cos",  "tan", "asin", "acos", "atan",  "atan2", "exp", "log",
                                                 "sqrt", "pow", "abs", "min", "max",  "floor", "ceil",  "if"};

void check_noise(const NoiseConfig& noise, std::size_t n) {
  const std::string n_text = std::to_string(n);
  if (noise.distribution == Distribution::Normal) {
    const std::string example = n == 2 ? "covariance: [0.75, 0.75]" : "covariance: [" + n_text + " variances]";
    if (!noise.half_width.empty())
      throw ConfigError("noise.half_width", "given for distribution normal; it is only used by distribution uniform");
    const auto& c = noise.covariance;
    if (c.size() != n && c.size() != n * n)
      fail("noise.covariance", std::to_string(c.size()) + " values",
           n_text + " values (diagonal) or " + std::to_string(n * n) + " values (full matrix, row-major)", example);
    check_finite_list(c, "noise.covariance", example);
    if (c.size() == n) {
      for (std::size_t i = 0; i < n; ++i)
        if (c[i] < 0)
          fail(indexed("noise.covariance", i), format_number(c[i]),
               "a variance >= 0 (0: no noise in that dimension)", example);
    } else {
      if (noise.type == NoiseType::Multiplicative)
        throw ConfigError("noise.covariance",
                          "a full covariance matrix with multiplicative noise is not supported; give the " + n_text +
                              " diagonal variances (example: " + example + ")");
      bool diagonal = true;
      for (std::size_t r = 0; r < n; ++r)
        for (std::size_t k = 0; k < n; ++k)
          if (r != k && c[r * n + k] != 0.0) diagonal = false;
      if (!diagonal && n > NoiseModel::kMaxFullCovarianceDims)
        throw ConfigError("noise.covariance",
                          "a full (non-diagonal) covariance is supported up to " +
                              std::to_string(NoiseModel::kMaxFullCovarianceDims) + " state dimensions, got " + n_text +
                              " (the quadrature cost grows like points^(n-1)); give the " + n_text +
                              " diagonal variances (example: " + example + ")");
      Eigen::MatrixXd matrix(n, n);
      for (std::size_t r = 0; r < n; ++r)
        for (std::size_t k = 0; k < n; ++k) matrix(r, k) = c[r * n + k];
      for (std::size_t r = 0; r < n; ++r)
        for (std::size_t k = r + 1; k < n; ++k)
          if (std::fabs(matrix(r, k) - matrix(k, r)) >
              kSymmetryTolerance * std::max(1.0, std::max(std::fabs(matrix(r, k)), std::fabs(matrix(k, r)))))
            throw ConfigError("noise.covariance",
                              "got a matrix that is not symmetric: entry (" + std::to_string(r) + "," +
                                  std::to_string(k) + ") = " + format_number(matrix(r, k)) + " but (" +
                                  std::to_string(k) + "," + std::to_string(r) + ") = " + format_number(matrix(k, r)) +
                                  "; expected a symmetric positive definite " + n_text + "x" + n_text +
                                  " matrix, row-major");
      Eigen::LLT<Eigen::MatrixXd> cholesky(matrix);
      if (cholesky.info() != Eigen::Success)
        throw ConfigError("noise.covariance", "got " + format_list(c) +
                                                  ", which is not positive definite (Cholesky failed); expected a "
                                                  "symmetric positive definite " + n_text + "x" + n_text +
                                                  " matrix, row-major, or " + n_text + " positive variances");
    }
  } else {
    const std::string example = "half_width: [" + n_text + " positive numbers]";
    if (!noise.covariance.empty())
      throw ConfigError("noise.covariance",
                        "given for distribution uniform; use noise.half_width (example: " + example + ")");
    if (noise.half_width.size() != n)
      fail("noise.half_width", std::to_string(noise.half_width.size()) + " values", n_text + " values (one per state)",
           example);
    check_finite_list(noise.half_width, "noise.half_width", example);
    for (std::size_t i = 0; i < n; ++i)
      if (noise.half_width[i] <= 0)
        fail(indexed("noise.half_width", i), format_number(noise.half_width[i]), "a number > 0", example);
  }
  if (!(noise.cutting_probability > 0 && noise.cutting_probability < 1))
    fail("noise.cutting_probability", format_number(noise.cutting_probability), "a probability in (0, 1)",
         "cutting_probability: 1.0e-3");
  if (noise.truncation == Truncation::FixedRegion) {
    const std::string example = "fixed_region: [" + n_text + " half-widths in state units]";
    if (noise.fixed_region.size() != n)
      fail("noise.fixed_region", std::to_string(noise.fixed_region.size()) + " values",
           n_text + " values (one per state)", example);
    check_finite_list(noise.fixed_region, "noise.fixed_region", example);
    for (std::size_t i = 0; i < n; ++i)
      if (noise.fixed_region[i] <= 0)
        fail(indexed("noise.fixed_region", i), format_number(noise.fixed_region[i]), "a number > 0", example);
  } else if (!noise.fixed_region.empty()) {
    throw ConfigError("noise.fixed_region", "given but noise.truncation is " + to_string(noise.truncation) +
                                                "; set truncation: fixed_region to use it");
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------

void Config::validate() const {
  if (name.empty()) fail("name", "\"\"", "a non-empty name", "name: robot_reach_avoid");

  const double state_points = check_grid(states, "states", "");
  const std::size_t n = states.lb.size();
  const std::size_t m = inputs ? inputs->lb.size() : 0;
  const std::size_t p = disturbances ? disturbances->lb.size() : 0;
  if (inputs) check_grid(*inputs, "inputs", "; omit `inputs` for an autonomous system");
  if (disturbances) check_grid(*disturbances, "disturbances", "; omit `disturbances` when there are none");

  for (const auto& constant : constants) {
    const std::string key = "constants." + constant.first;
    bool reserved = constant.first == "pi" || looks_like_variable(constant.first);
    for (const auto& function : kFunctionNames) reserved = reserved || function == constant.first;
    if (!is_identifier(constant.first) || reserved)
      throw ConfigError(key, "got the name '" + constant.first +
                                 "', expected a name of letters, digits and '_' that is not pi, a variable "
                                 "(x0, u1, ...) or a function (example: constants: {tau: 10.0})");
    if (!std::isfinite(constant.second)) fail(key, format_number(constant.second), "a finite number", "tau: 10.0");
  }

  if (!model.empty() && !dynamics.empty())
    throw ConfigError("model", "both `model` and `dynamics` are given; use one (example: model: bmw320i)");
  if (model.empty()) {
    if (dynamics.empty())
      throw ConfigError("dynamics", "missing, expected one expression per state dimension or a built-in `model` "
                                    "(example: dynamics: [\"x0 + tau*u0*cos(u1) + w0\", \"x1 + tau*u0*sin(u1) + w0\"])");
    if (dynamics.size() != n)
      fail("dynamics", std::to_string(dynamics.size()) + " expressions",
           std::to_string(n) + ", one per state dimension (states.lb has " + std::to_string(n) + " values)",
           "dynamics: [\"x0 + tau*u0*cos(u1) + w0\", \"x1 + tau*u0*sin(u1) + w0\"]");
    for (std::size_t i = 0; i < dynamics.size(); ++i) {
      try {
        Expression::parse(dynamics[i], constants, n, m, p);
      } catch (const ParseError& error) {
        throw ConfigError(indexed("dynamics", i), std::string(error.what()) + " in \"" + expression_excerpt(dynamics[i]) + "\"");
      }
    }
  } else {
    const BuiltinModelInfo* info = nullptr;
    std::vector<std::string> names;
    for (const auto& candidate : builtin_models()) {
      names.push_back(candidate.name);
      if (candidate.name == model) info = &candidate;
    }
    if (!info) fail("model", "'" + model + "'", "one of " + join(names), "model: bmw320i");
    auto check_dims = [&](const char* key, std::size_t have, std::size_t want) {
      if (have != want)
        throw ConfigError(key, "model " + model + " needs " + std::to_string(want) + " dimensions, got " +
                                   std::to_string(have) + " (" + info->description + ")");
    };
    check_dims("states.lb", n, info->state_dims);
    check_dims("inputs.lb", m, info->input_dims);
    check_dims("disturbances.lb", p, info->disturbance_dims);
  }

  check_noise(noise, n);

  if (spec.horizon == 0) fail("spec.horizon", "0", "an integer >= 1 (number of time steps)", "horizon: 16");
  switch (spec.type) {
    case SpecType::Safety:
      if (spec.target) throw ConfigError("spec.target", "given for spec.type safety; safety uses `safe` (or the whole grid)");
      if (spec.avoid) throw ConfigError("spec.avoid", "given for spec.type safety; use reach_avoid, or `safe` for the set to stay in");
      if (spec.safe) check_box(*spec.safe, "spec.safe", states);
      break;
    case SpecType::Reachability:
    case SpecType::ReachAvoid:
      if (spec.safe) throw ConfigError("spec.safe", "given for spec.type " + to_string(spec.type) + "; `safe` is for safety only");
      if (!spec.target)
        throw ConfigError("spec.target", "missing, expected the target box for " + to_string(spec.type) +
                                             " (example: target: {lb: [5, 5], ub: [7, 7]})");
      check_box(*spec.target, "spec.target", states);
      if (spec.avoid) {
        if (spec.type == SpecType::Reachability)
          throw ConfigError("spec.avoid", "given for spec.type reachability; use reach_avoid to avoid a set");
        check_box(*spec.avoid, "spec.avoid", states);
        check_target_avoid_disjoint(*spec.target, *spec.avoid, states);
      }
      break;
  }

  if (!(compute.memory_fraction > 0 && compute.memory_fraction <= 1))
    fail("compute.memory_fraction", format_number(compute.memory_fraction), "a fraction in (0, 1]",
         "memory_fraction: 0.5");

  const double policy_bytes = state_points * ((double(spec.horizon) + 1) * 8 + double(spec.horizon) * 4);
  if (policy_bytes > kMaxPolicyBytes) {
    char text[300];
    std::snprintf(text, sizeof text,
                  "grid too large: %.0f states x (%u+1 values x 8 bytes + %u inputs x 4 bytes) = %.1f GiB of "
                  "policy arrays, more than the 16 GiB supported; use a larger states.eta or a shorter horizon",
                  state_points, spec.horizon, spec.horizon, policy_bytes / (1024.0 * 1024 * 1024));
    throw ConfigError("states", text);
  }
}

Config config_from_yaml(const YAML::Node& root) {
  check_keys(root, "", {"name", "states", "inputs", "disturbances", "constants", "dynamics", "model", "noise", "spec",
                        "compute"},
             "name: robot_reach_avoid");
  Config config;
  config.name = read_string(required(root, "name", "name", "name: robot_reach_avoid"), "name", "name: robot_reach_avoid");
  config.states = read_grid(required(root, "states", "states", std::string("states: ") + kGridExample), "states", kGridExample);
  if (present(root["inputs"])) config.inputs = read_grid(root["inputs"], "inputs", "{lb: [-1, -1], ub: [1, 1], eta: [0.1, 0.1]}");
  if (present(root["disturbances"]))
    config.disturbances = read_grid(root["disturbances"], "disturbances", "{lb: [-1], ub: [1], eta: [0.2]}");
  if (present(root["constants"])) {
    const YAML::Node constants = root["constants"];
    if (!constants.IsMap()) fail("constants", node_text(constants), "a map of names to numbers", "constants: {tau: 10.0}");
    for (const auto& entry : constants) {
      const std::string name = entry.first.Scalar();
      config.constants[name] = read_number(entry.second, "constants." + name, "constants: {tau: 10.0}");
    }
  }
  const char* const dynamics_example = "dynamics: [\"x0 + tau*u0*cos(u1) + w0\", \"x1 + tau*u0*sin(u1) + w0\"]";
  if (present(root["dynamics"])) {
    const YAML::Node dynamics = root["dynamics"];
    if (!dynamics.IsSequence()) fail("dynamics", node_text(dynamics), "a list of expressions", dynamics_example);
    for (std::size_t i = 0; i < dynamics.size(); ++i)
      config.dynamics.push_back(read_string(dynamics[i], indexed("dynamics", i), dynamics_example));
  }
  if (present(root["model"])) config.model = read_string(root["model"], "model", "model: bmw320i");

  const YAML::Node noise = required(root, "noise", "noise", "noise: {covariance: [0.75, 0.75]}");
  check_keys(noise, "noise", {"type", "distribution", "covariance", "half_width", "truncation", "cutting_probability",
                              "fixed_region"},
             "noise: {covariance: [0.75, 0.75]}");
  if (present(noise["type"]))
    config.noise.type = read_enum<NoiseType>(noise["type"], "noise.type",
                                             {{"additive", NoiseType::Additive}, {"multiplicative", NoiseType::Multiplicative}},
                                             "type: additive");
  if (present(noise["distribution"])) {
    const std::string distribution = read_string(noise["distribution"], "noise.distribution", "distribution: normal");
    if (distribution == "exponential" || distribution == "beta" || distribution == "custom")
      throw ConfigError("noise.distribution", "got '" + distribution +
                                                  "', which is not supported yet (supported: normal, uniform; "
                                                  "example: distribution: normal)");
    config.noise.distribution = read_enum<Distribution>(
        noise["distribution"], "noise.distribution",
        {{"normal", Distribution::Normal}, {"uniform", Distribution::Uniform}}, "distribution: normal");
  }
  if (present(noise["covariance"]))
    config.noise.covariance = read_number_list(noise["covariance"], "noise.covariance", "covariance: [0.75, 0.75]");
  if (present(noise["half_width"]))
    config.noise.half_width = read_number_list(noise["half_width"], "noise.half_width", "half_width: [0.5, 0.5]");
  config.noise.truncation = Truncation::None;
  if (present(noise["truncation"]))
    config.noise.truncation = read_enum<Truncation>(
        noise["truncation"], "noise.truncation",
        {{"none", Truncation::None}, {"fixed_region", Truncation::FixedRegion},
         {"cutting_probability", Truncation::CuttingProbability}},
        "truncation: cutting_probability");
  if (present(noise["cutting_probability"])) {
    if (config.noise.truncation != Truncation::CuttingProbability)
      throw ConfigError("noise.cutting_probability", "given but noise.truncation is " +
                                                         to_string(config.noise.truncation) +
                                                         "; set truncation: cutting_probability to use it");
    config.noise.cutting_probability =
        read_number(noise["cutting_probability"], "noise.cutting_probability", "cutting_probability: 1.0e-3");
  }
  if (present(noise["fixed_region"]))
    config.noise.fixed_region = read_number_list(noise["fixed_region"], "noise.fixed_region", "fixed_region: [0.5, 0.5]");

  const YAML::Node spec = required(root, "spec", "spec", "spec: {type: safety, horizon: 8}");
  check_keys(spec, "spec", {"type", "horizon", "safe", "target", "avoid"}, "spec: {type: safety, horizon: 8}");
  config.spec.type = read_enum<SpecType>(
      required(spec, "type", "spec.type", "type: reach_avoid"), "spec.type",
      {{"safety", SpecType::Safety}, {"reachability", SpecType::Reachability}, {"reach_avoid", SpecType::ReachAvoid}},
      "type: reach_avoid");
  const double horizon = read_number(required(spec, "horizon", "spec.horizon", "horizon: 16"), "spec.horizon", "horizon: 16");
  constexpr double kMaxHorizon = 1e9;  // the policy arrays' 16 GiB limit is checked in validate()
  if (!(horizon >= 0 && horizon == std::floor(horizon) && horizon <= kMaxHorizon))
    fail("spec.horizon", spec["horizon"].Scalar(),
         "an integer >= 1 and <= 1000000000 (number of time steps; the policy arrays must also fit in 16 GiB)",
         "horizon: 16");
  config.spec.horizon = static_cast<unsigned>(horizon);
  if (present(spec["safe"])) config.spec.safe = read_box(spec["safe"], "spec.safe", "{lb: [-10, -10], ub: [10, 10]}");
  if (present(spec["target"])) config.spec.target = read_box(spec["target"], "spec.target", "{lb: [5, 5], ub: [7, 7]}");
  if (present(spec["avoid"])) config.spec.avoid = read_box(spec["avoid"], "spec.avoid", "{lb: [-2, -2], ub: [2, 2]}");

  if (present(root["compute"])) {
    const YAML::Node compute = root["compute"];
    check_keys(compute, "compute", {"device", "transitions", "platform", "device_name", "memory_fraction"},
               "compute: {device: auto}");
    if (present(compute["device"]))
      config.compute.device = read_enum<DeviceKind>(
          compute["device"], "compute.device",
          {{"auto", DeviceKind::Auto}, {"cpu", DeviceKind::Cpu}, {"gpu", DeviceKind::Gpu}, {"reference", DeviceKind::Reference}},
          "device: auto");
    if (present(compute["transitions"]))
      config.compute.transitions = read_enum<TransitionStorage>(
          compute["transitions"], "compute.transitions",
          {{"auto", TransitionStorage::Auto}, {"stored", TransitionStorage::Stored}, {"on_the_fly", TransitionStorage::OnTheFly}},
          "transitions: auto");
    if (present(compute["platform"])) config.compute.platform = read_string(compute["platform"], "compute.platform", "platform: nvidia");
    if (present(compute["device_name"]))
      config.compute.device_name = read_string(compute["device_name"], "compute.device_name", "device_name: \"0\"");
    if (present(compute["memory_fraction"]))
      config.compute.memory_fraction =
          read_number(compute["memory_fraction"], "compute.memory_fraction", "memory_fraction: 0.5");
  }

  config.validate();
  return config;
}

Config load_config_file(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw ConfigError(path, "cannot read the configuration file");
  std::stringstream text;
  text << file.rdbuf();
  YAML::Node root;
  try {
    root = YAML::Load(text.str());
  } catch (const YAML::Exception& error) {
    throw ConfigError(path, "not valid YAML at line " + std::to_string(error.mark.line + 1) + ", column " +
                                std::to_string(error.mark.column + 1) + ": " + error.msg);
  }
  return config_from_yaml(root);
}

namespace {

std::string grid_yaml(const GridSpec& grid) {
  return "{lb: " + format_list(grid.lb) + ", ub: " + format_list(grid.ub) + ", eta: " + format_list(grid.eta) + "}";
}

std::string box_yaml(const Box& box) { return "{lb: " + format_list(box.lb) + ", ub: " + format_list(box.ub) + "}"; }

std::string canonical_yaml(const Config& config, bool with_compute) {
  std::string text;
  text += "name: " + quoted(config.name) + "\n";
  text += "states: " + grid_yaml(config.states) + "\n";
  if (config.inputs) text += "inputs: " + grid_yaml(*config.inputs) + "\n";
  if (config.disturbances) text += "disturbances: " + grid_yaml(*config.disturbances) + "\n";
  if (!config.constants.empty()) {
    text += "constants:\n";
    for (const auto& constant : config.constants) text += "  " + constant.first + ": " + format_number(constant.second) + "\n";
  }
  if (!config.model.empty()) text += "model: " + quoted(config.model) + "\n";
  if (!config.dynamics.empty()) {
    text += "dynamics:\n";
    for (const auto& expression : config.dynamics) text += "  - " + quoted(expression) + "\n";
  }
  const NoiseConfig& noise = config.noise;
  text += "noise:\n";
  text += "  type: " + to_string(noise.type) + "\n";
  text += "  distribution: " + to_string(noise.distribution) + "\n";
  if (!noise.covariance.empty()) text += "  covariance: " + format_list(noise.covariance) + "\n";
  if (!noise.half_width.empty()) text += "  half_width: " + format_list(noise.half_width) + "\n";
  text += "  truncation: " + to_string(noise.truncation) + "\n";
  if (noise.truncation == Truncation::CuttingProbability)
    text += "  cutting_probability: " + format_number(noise.cutting_probability) + "\n";
  if (!noise.fixed_region.empty()) text += "  fixed_region: " + format_list(noise.fixed_region) + "\n";
  text += "spec:\n";
  text += "  type: " + to_string(config.spec.type) + "\n";
  text += "  horizon: " + std::to_string(config.spec.horizon) + "\n";
  if (config.spec.safe) text += "  safe: " + box_yaml(*config.spec.safe) + "\n";
  if (config.spec.target) text += "  target: " + box_yaml(*config.spec.target) + "\n";
  if (config.spec.avoid) text += "  avoid: " + box_yaml(*config.spec.avoid) + "\n";
  if (with_compute) {
    const ComputeConfig& compute = config.compute;
    text += "compute:\n";
    text += "  device: " + to_string(compute.device) + "\n";
    text += "  transitions: " + to_string(compute.transitions) + "\n";
    text += "  platform: " + quoted(compute.platform) + "\n";
    text += "  device_name: " + quoted(compute.device_name) + "\n";
    text += "  memory_fraction: " + format_number(compute.memory_fraction) + "\n";
  }
  return text;
}

}  // namespace

std::string to_yaml(const Config& config) { return canonical_yaml(config, true); }

std::string config_hash(const Config& config) {
  const std::string text = canonical_yaml(config, false);
  std::uint64_t hash = 14695981039346656037ull;  // FNV-1a 64-bit offset basis
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 1099511628211ull;  // FNV prime
  }
  char buffer[17];
  std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(hash));
  return buffer;
}

std::string to_string(SpecType value) {
  switch (value) {
    case SpecType::Safety: return "safety";
    case SpecType::Reachability: return "reachability";
    case SpecType::ReachAvoid: return "reach_avoid";
  }
  return "?";
}
std::string to_string(DeviceKind value) {
  switch (value) {
    case DeviceKind::Auto: return "auto";
    case DeviceKind::Cpu: return "cpu";
    case DeviceKind::Gpu: return "gpu";
    case DeviceKind::Reference: return "reference";
  }
  return "?";
}
std::string to_string(TransitionStorage value) {
  switch (value) {
    case TransitionStorage::Auto: return "auto";
    case TransitionStorage::Stored: return "stored";
    case TransitionStorage::OnTheFly: return "on_the_fly";
  }
  return "?";
}
std::string to_string(NoiseType value) {
  return value == NoiseType::Additive ? "additive" : "multiplicative";
}
std::string to_string(Distribution value) { return value == Distribution::Normal ? "normal" : "uniform"; }
std::string to_string(Truncation value) {
  switch (value) {
    case Truncation::None: return "none";
    case Truncation::FixedRegion: return "fixed_region";
    case Truncation::CuttingProbability: return "cutting_probability";
  }
  return "?";
}

}  // namespace amytiss
