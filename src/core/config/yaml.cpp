// Reading a configuration from YAML: the key in every error, unknown keys refused; the values'
// meaning is judged by Config::validate() (config/validate.cpp).
#include <cmath>
#include <fstream>
#include <sstream>

#include "amytiss/config.hpp"
#include "amytiss/enum_names.hpp"
#include "config/messages.hpp"

namespace amytiss {
namespace {

using detail::fail;
using detail::indexed;
using detail::join;

const char* const kGridExample = "{lb: [-10, -10], ub: [10, 10], eta: [0.5, 0.5]}";

std::string node_text(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) return node.Scalar();
  if (node.IsSequence()) return "a list";
  return "a map";
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
Enum read_enum(const YAML::Node& node, const std::string& key, const std::string& example) {
  const std::string text = read_string(node, key, example);
  if (const auto value = enum_from_name<Enum>(text)) return *value;
  fail(key, "'" + text + "'", "one of " + enum_name_list<Enum>(), example);
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

}  // namespace

Config config_from_yaml(const YAML::Node& root) {
  check_keys(root, "", {"name", "states", "inputs", "disturbances", "constants", "dynamics", "model", "integrator", "noise",
                        "spec", "compute"},
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
  if (present(root["integrator"])) {
    const char* const example = "integrator: {method: rk4, substeps: 4}";
    const YAML::Node integrator = root["integrator"];
    check_keys(integrator, "integrator", {"method", "substeps", "tau"}, example);
    if (present(integrator["method"]))
      config.integrator.method = read_enum<IntegrationMethod>(integrator["method"], "integrator.method", "method: rk4");
    if (present(integrator["substeps"])) {
      const double substeps = read_number(integrator["substeps"], "integrator.substeps", "substeps: 4");
      if (!(substeps >= 0 && substeps == std::floor(substeps) && substeps <= 1e9))
        fail("integrator.substeps", integrator["substeps"].Scalar(), "an integer >= 1", "substeps: 4");
      config.integrator.substeps = static_cast<unsigned>(substeps);
    }
    if (present(integrator["tau"])) config.integrator.tau = read_number(integrator["tau"], "integrator.tau", "tau: 0.1");
  }

  const YAML::Node noise = required(root, "noise", "noise", "noise: {covariance: [0.75, 0.75]}");
  check_keys(noise, "noise", {"type", "distribution", "covariance", "half_width", "rate", "shift", "alpha", "beta",
                              "density", "support", "truncation", "cutting_probability", "fixed_region"},
             "noise: {covariance: [0.75, 0.75]}");
  if (present(noise["type"]))
    config.noise.type = read_enum<NoiseType>(noise["type"], "noise.type", "type: additive");
  if (present(noise["distribution"]))
    config.noise.distribution = read_enum<Distribution>(
        noise["distribution"], "noise.distribution", "distribution: normal");
  if (present(noise["rate"])) config.noise.rate = read_number_list(noise["rate"], "noise.rate", "rate: [2.0, 2.0]");
  if (present(noise["shift"]))
    config.noise.shift = read_number_list(noise["shift"], "noise.shift", "shift: [-0.5, -0.5]");
  if (present(noise["alpha"])) config.noise.alpha = read_number_list(noise["alpha"], "noise.alpha", "alpha: [2, 2]");
  if (present(noise["beta"])) config.noise.beta = read_number_list(noise["beta"], "noise.beta", "beta: [5, 5]");
  if (present(noise["support"]))
    config.noise.support = read_box(noise["support"], "noise.support", "{lb: [-1, -1], ub: [1, 1]}");
  const char* const density_example = "density: [\"0.5*exp(-abs(z))\", \"0.5*exp(-abs(z))\"]";
  if (present(noise["density"])) {
    const YAML::Node density = noise["density"];
    if (!density.IsSequence()) fail("noise.density", node_text(density), "a list of expressions of z", density_example);
    for (std::size_t i = 0; i < density.size(); ++i)
      config.noise.density.push_back(read_string(density[i], indexed("noise.density", i), density_example));
  }
  if (present(noise["covariance"]))
    config.noise.covariance = read_number_list(noise["covariance"], "noise.covariance", "covariance: [0.75, 0.75]");
  if (present(noise["half_width"]))
    config.noise.half_width = read_number_list(noise["half_width"], "noise.half_width", "half_width: [0.5, 0.5]");
  config.noise.truncation = Truncation::None;
  if (present(noise["truncation"]))
    config.noise.truncation = read_enum<Truncation>(
        noise["truncation"], "noise.truncation", "truncation: cutting_probability");
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
  check_keys(spec, "spec", {"type", "horizon", "tolerance", "safe", "target", "avoid"},
             "spec: {type: safety, horizon: 8}");
  config.spec.type = read_enum<SpecType>(
      required(spec, "type", "spec.type", "type: reach_avoid"), "spec.type", "type: reach_avoid");
  const YAML::Node horizon_node = required(spec, "horizon", "spec.horizon", "horizon: 16");
  if (horizon_node.IsScalar() && horizon_node.Scalar() == "infinite") {
    config.spec.unbounded = true;
  } else {
    const std::string horizon_example = "horizon: 16 (or horizon: infinite)";
    const double horizon = read_number(horizon_node, "spec.horizon", horizon_example);
    constexpr double kMaxHorizon = 1e9;  // the policy arrays' 16 GiB limit is checked in validate()
    if (!(horizon >= 0 && horizon == std::floor(horizon) && horizon <= kMaxHorizon))
      fail("spec.horizon", horizon_node.Scalar(),
           "an integer >= 1 and <= 1000000000 (number of time steps; the policy arrays must also fit in 16 GiB) "
           "or infinite",
           horizon_example);
    config.spec.horizon = static_cast<unsigned>(horizon);
  }
  if (present(spec["tolerance"])) {
    if (!config.spec.unbounded)
      throw ConfigError("spec.tolerance", "given but spec.horizon is " + horizon_node.Scalar() +
                                              "; the tolerance is for horizon: infinite");
    config.spec.tolerance = read_number(spec["tolerance"], "spec.tolerance", "tolerance: 1.0e-6");
  }
  if (present(spec["safe"])) config.spec.safe = read_box(spec["safe"], "spec.safe", "{lb: [-10, -10], ub: [10, 10]}");
  if (present(spec["target"])) config.spec.target = read_box(spec["target"], "spec.target", "{lb: [5, 5], ub: [7, 7]}");
  if (present(spec["avoid"])) config.spec.avoid = read_box(spec["avoid"], "spec.avoid", "{lb: [-2, -2], ub: [2, 2]}");

  if (present(root["compute"])) {
    const YAML::Node compute = root["compute"];
    check_keys(compute, "compute", {"device", "transitions", "sweep", "platform", "device_name", "memory_fraction", "devices"},
               "compute: {device: auto}");
    if (present(compute["device"]))
      config.compute.device = read_enum<DeviceKind>(
          compute["device"], "compute.device", "device: auto");
    if (present(compute["sweep"]))
      config.compute.sweep = read_enum<SweepChoice>(compute["sweep"], "compute.sweep", "sweep: auto");
    if (present(compute["transitions"]))
      config.compute.transitions = read_enum<TransitionStorage>(
          compute["transitions"], "compute.transitions", "transitions: auto");
    if (present(compute["platform"])) config.compute.platform = read_string(compute["platform"], "compute.platform", "platform: nvidia");
    if (present(compute["device_name"]))
      config.compute.device_name = read_string(compute["device_name"], "compute.device_name", "device_name: \"0\"");
    if (present(compute["devices"])) {
      const YAML::Node devices = compute["devices"];
      if (devices.IsScalar()) {
        config.compute.devices = {read_string(devices, "compute.devices", "devices: all")};
      } else if (devices.IsSequence()) {
        for (std::size_t i = 0; i < devices.size(); ++i)
          config.compute.devices.push_back(read_string(devices[i], indexed("compute.devices", i), "devices: [gpu:0, gpu:1]"));
      } else {
        fail("compute.devices", node_text(devices), "`all` or a list of devices", "devices: [gpu:0, gpu:1]");
      }
    }
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
}  // namespace amytiss
