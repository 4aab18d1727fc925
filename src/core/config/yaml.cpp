// Reading a configuration from YAML, one function per section: the key in every error, unknown
// keys and wrong types refused; the values' meaning is judged by Config::validate()
// (config/validate.cpp) and nowhere here.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/enum_names.hpp"
#include "config/messages.hpp"
#include "config/refine_section.hpp"
#include "config/yaml_read.hpp"

namespace amytiss {
namespace {

using detail::fail;
using detail::indexed;
using detail::join;
using detail::add_once;
using detail::check_keys;
using detail::node_text;
using detail::present;
using detail::read_count;
using detail::read_enum;
using detail::read_flag;
using detail::read_grid;
using detail::read_number;
using detail::read_number_list;
using detail::read_string;
using detail::read_string_list;
using detail::required;

const char* const kGridExample = "{lb: [-10, -10], ub: [10, 10], eta: [0.5, 0.5]}";

// states: a grid whose dimensions may be given by their faces (lb, ub, eta null there or, when
// every dimension has faces, left out), and fit_sets.
GridSpec read_states(const YAML::Node& node, Config& config) {
  const std::string example = "{lb: [-10, ~], ub: [10, ~], eta: [0.5, ~], faces: [~, [-1, 0, 0.5, 2]]}";
  check_keys(node, "states", {"lb", "ub", "eta", "faces", "fit_sets"}, "states: " + example);
  if (present(node["fit_sets"])) config.fit_sets = read_flag(node["fit_sets"], "states.fit_sets", "fit_sets: true");
  if (!present(node["faces"])) {
    YAML::Node grid = YAML::Clone(node);
    grid.remove("fit_sets");
    return read_grid(grid, "states", kGridExample);
  }
  GridSpec grid;
  const YAML::Node faces = node["faces"];
  if (!faces.IsSequence()) fail("states.faces", node_text(faces), "a list with one entry per dimension", example);
  for (std::size_t d = 0; d < faces.size(); ++d)
    grid.faces.push_back(present(faces[d]) ? read_number_list(faces[d], indexed("states.faces", d), example)
                                           : std::vector<double>{});
  for (const auto& [name, list] : {std::pair{"lb", &grid.lb}, {"ub", &grid.ub}, {"eta", &grid.eta}})
    *list = present(node[name]) ? read_number_list(node[name], std::string("states.") + name, example, true)
                                : std::vector<double>(grid.faces.size(), std::nan(""));
  return grid;
}

Box read_box(const YAML::Node& node, const std::string& key, const std::string& example) {
  check_keys(node, key, {"lb", "ub"}, key + ": " + example);
  Box box;
  box.lb = read_number_list(required(node, "lb", key + ".lb", example), key + ".lb", example);
  box.ub = read_number_list(required(node, "ub", key + ".ub", example), key + ".ub", example);
  return box;
}

// One box {lb, ub}, or a list of boxes whose keys carry the index (spec.avoid[2].lb).
Region read_region(const YAML::Node& node, const std::string& key, const std::string& example) {
  if (node.IsMap()) return Region(read_box(node, key, example));
  if (!node.IsSequence())
    fail(key, node_text(node), "a box {lb, ub} or a list of boxes",
         key.substr(key.rfind('.') + 1) + ": " + example + " or [" + example + ", ...]");
  std::vector<Box> boxes;
  for (std::size_t i = 0; i < node.size(); ++i) boxes.push_back(read_box(node[i], indexed(key, i), example));
  return Region(std::move(boxes));
}

std::map<std::string, double> read_constants(const YAML::Node& constants) {
  const char* const example = "constants: {tau: 10.0}";
  if (!constants.IsMap()) fail("constants", node_text(constants), "a map of names to numbers", example);
  std::map<std::string, double> values;
  std::map<std::string, YAML::Node> seen;
  for (const auto& entry : constants) {
    const std::string name = entry.first.Scalar();
    add_once(seen, entry.first, "constants." + name);
    values[name] = read_number(entry.second, "constants." + name, example);
  }
  return values;
}

IntegratorConfig read_integrator(const YAML::Node& integrator) {
  check_keys(integrator, "integrator", {"method", "substeps", "tau"}, "integrator: {method: rk4, substeps: 4}");
  IntegratorConfig config;
  if (present(integrator["method"]))
    config.method = read_enum<IntegrationMethod>(integrator["method"], "integrator.method", "method: rk4");
  if (present(integrator["substeps"]))
    config.substeps = read_count(integrator["substeps"], "integrator.substeps", "a positive integer", "substeps: 4");
  if (present(integrator["tau"])) config.tau = read_number(integrator["tau"], "integrator.tau", "tau: 0.1");
  return config;
}

// The parameters of every distribution are read; validate() says which ones a distribution uses.
void read_noise_law(const YAML::Node& noise, NoiseConfig& config) {
  if (present(noise["covariance"]))
    config.covariance = read_number_list(noise["covariance"], "noise.covariance", "covariance: [0.75, 0.75]");
  if (present(noise["half_width"]))
    config.half_width = read_number_list(noise["half_width"], "noise.half_width", "half_width: [0.5, 0.5]");
  if (present(noise["rate"])) config.rate = read_number_list(noise["rate"], "noise.rate", "rate: [2.0, 2.0]");
  if (present(noise["shift"])) config.shift = read_number_list(noise["shift"], "noise.shift", "shift: [-0.5, -0.5]");
  if (present(noise["alpha"])) config.alpha = read_number_list(noise["alpha"], "noise.alpha", "alpha: [2, 2]");
  if (present(noise["beta"])) config.beta = read_number_list(noise["beta"], "noise.beta", "beta: [5, 5]");
  if (present(noise["support"]))
    config.support = read_box(noise["support"], "noise.support", "{lb: [-1, -1], ub: [1, 1]}");
  if (present(noise["density"]))
    config.density = read_string_list(noise["density"], "noise.density", "a list of expressions of z",
                                      "density: [\"0.5*exp(-abs(z))\", \"0.5*exp(-abs(z))\"]");
}

NoiseConfig read_noise(const YAML::Node& noise) {
  check_keys(noise, "noise", {"type", "distribution", "covariance", "half_width", "rate", "shift", "alpha", "beta",
                              "density", "support", "truncation", "cutting_probability", "fixed_region"},
             "noise: {covariance: [0.75, 0.75]}");
  NoiseConfig config;
  if (present(noise["type"])) config.type = read_enum<NoiseType>(noise["type"], "noise.type", "type: additive");
  if (present(noise["distribution"]))
    config.distribution = read_enum<Distribution>(noise["distribution"], "noise.distribution", "distribution: normal");
  read_noise_law(noise, config);
  if (present(noise["truncation"]))
    config.truncation = read_enum<Truncation>(noise["truncation"], "noise.truncation", "truncation: cutting_probability");
  if (present(noise["cutting_probability"]))
    config.cutting_probability =
        read_number(noise["cutting_probability"], "noise.cutting_probability", "cutting_probability: 1.0e-3");
  if (present(noise["fixed_region"]))
    config.fixed_region = read_number_list(noise["fixed_region"], "noise.fixed_region", "fixed_region: [0.5, 0.5]");
  return config;
}

Footprint read_footprint(const YAML::Node& node) {
  const char* const example = "footprint: {pose: [0, 1, 2], length: 4.9, width: 1.9, rear_overhang: 1.0}";
  check_keys(node, "spec.footprint", {"pose", "length", "width", "rear_overhang"}, example);
  Footprint footprint;
  const YAML::Node pose = required(node, "pose", "spec.footprint.pose", example);
  if (!pose.IsSequence()) fail("spec.footprint.pose", node_text(pose), "a list of state indices", example);
  for (std::size_t i = 0; i < pose.size(); ++i)
    footprint.pose.push_back(
        read_count(pose[i], indexed("spec.footprint.pose", i), "a state index (an integer >= 0)", example));
  auto length_of = [&](const char* name) {
    const std::string key = std::string("spec.footprint.") + name;
    return read_number(required(node, name, key, example), key, example);
  };
  footprint.length = length_of("length");
  footprint.width = length_of("width");
  footprint.rear_overhang = length_of("rear_overhang");
  return footprint;
}

SpecConfig read_spec(const YAML::Node& spec) {
  check_keys(spec, "spec", {"type", "horizon", "tolerance", "safe", "target", "avoid", "obstacles", "footprint"},
             "spec: {type: safety, horizon: 8}");
  SpecConfig config;
  config.type = read_enum<SpecType>(required(spec, "type", "spec.type", "type: reach_avoid"), "spec.type",
                                    "type: reach_avoid");
  const YAML::Node horizon = required(spec, "horizon", "spec.horizon", "horizon: 16");
  if (horizon.IsScalar() && horizon.Scalar() == "infinite")
    config.unbounded = true;
  else
    config.horizon =
        read_count(horizon, "spec.horizon", "a positive integer or infinite", "horizon: 16 (or horizon: infinite)");
  if (present(spec["tolerance"])) config.tolerance = read_number(spec["tolerance"], "spec.tolerance", "tolerance: 1.0e-6");
  if (present(spec["safe"])) config.safe = read_region(spec["safe"], "spec.safe", "{lb: [-10, -10], ub: [10, 10]}");
  if (present(spec["target"])) config.target = read_region(spec["target"], "spec.target", "{lb: [5, 5], ub: [7, 7]}");
  if (present(spec["avoid"])) config.avoid = read_region(spec["avoid"], "spec.avoid", "{lb: [-2, -2], ub: [2, 2]}");
  if (present(spec["obstacles"]))
    config.obstacles = read_region(spec["obstacles"], "spec.obstacles", "{lb: [3, 0], ub: [4, 2]}");
  if (present(spec["footprint"])) config.footprint = read_footprint(spec["footprint"]);
  return config;
}

std::vector<std::string> read_devices(const YAML::Node& devices) {
  if (devices.IsScalar()) return {read_string(devices, "compute.devices", "devices: all")};
  if (!devices.IsSequence())
    fail("compute.devices", node_text(devices), "`all` or a list of devices", "devices: [gpu:0, gpu:1]");
  return read_string_list(devices, "compute.devices", "a list of devices", "devices: [gpu:0, gpu:1]");
}

ComputeConfig read_compute(const YAML::Node& compute) {
  check_keys(compute, "compute",
             {"device", "transitions", "sweep", "bounds_method", "platform", "device_name", "memory_fraction",
              "devices"},
             "compute: {device: auto}");
  ComputeConfig config;
  if (present(compute["device"])) config.device = read_enum<DeviceKind>(compute["device"], "compute.device", "device: auto");
  if (present(compute["sweep"])) config.sweep = read_enum<SweepChoice>(compute["sweep"], "compute.sweep", "sweep: auto");
  if (present(compute["bounds_method"]))
    config.bounds_method =
        read_enum<BoundsMethod>(compute["bounds_method"], "compute.bounds_method", "bounds_method: auto");
  if (present(compute["transitions"]))
    config.transitions =
        read_enum<TransitionStorage>(compute["transitions"], "compute.transitions", "transitions: auto");
  if (present(compute["platform"])) config.platform = read_string(compute["platform"], "compute.platform", "platform: nvidia");
  if (present(compute["device_name"]))
    config.device_name = read_string(compute["device_name"], "compute.device_name", "device_name: \"0\"");
  if (present(compute["devices"])) config.devices = read_devices(compute["devices"]);
  if (present(compute["memory_fraction"]))
    config.memory_fraction = read_number(compute["memory_fraction"], "compute.memory_fraction", "memory_fraction: 0.5");
  return config;
}

OutputConfig read_output(const YAML::Node& output) {
  check_keys(output, "output", {"values"}, "output: {values: float32_lower}");
  OutputConfig config;
  if (present(output["values"]))
    config.values = read_enum<ValueStorage>(output["values"], "output.values", "values: float32_lower");
  return config;
}

YAML::Node parse_yaml_text(const std::string& text, const std::string& key) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& error) {
    throw ConfigError(key, "not valid YAML at line " + std::to_string(error.mark.line + 1) + ", column " +
                               std::to_string(error.mark.column + 1) + ": " + error.msg);
  }
}

// At most kMaxConfigFileBytes + 1 bytes are read, so a file that never ends (/dev/zero) or a huge
// sparse one is refused without being held in memory.
std::string read_config_text(const std::string& path) {
  const char* const example = "config/robot_reach_avoid.yaml";
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw ConfigError(path, "got a directory, expected a configuration file (example: " + std::string(example) + ")");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw ConfigError(path, "cannot read the configuration file");
  std::string text;
  std::vector<char> chunk(64 * 1024);
  while (text.size() <= kMaxConfigFileBytes) {
    const std::size_t wanted = std::min(chunk.size(), kMaxConfigFileBytes + 1 - text.size());
    if (file.read(chunk.data(), std::streamsize(wanted)).gcount() == 0) break;
    text.append(chunk.data(), std::size_t(file.gcount()));
  }
  if (file.bad()) throw ConfigError(path, "cannot read the configuration file");
  if (text.size() > kMaxConfigFileBytes)
    throw ConfigError(path, "got a file of more than " + std::to_string(kMaxConfigFileBytes >> 20) +
                                " MiB, expected a configuration of at most that size (example: " + example +
                                ", a few KiB)");
  return text;
}

}  // namespace

Config read_config(const YAML::Node& root) {
  const char* const name_example = "name: robot_reach_avoid";
  check_keys(root, "", {"name", "states", "inputs", "disturbances", "constants", "dynamics", "model", "integrator",
                        "noise", "spec", "guarantee", "refine", "compute", "output"},
             name_example);
  Config config;
  config.name = read_string(required(root, "name", "name", name_example), "name", name_example);
  config.states = read_states(required(root, "states", "states", std::string("states: ") + kGridExample), config);
  if (present(root["inputs"]))
    config.inputs = read_grid(root["inputs"], "inputs", "{lb: [-1, -1], ub: [1, 1], eta: [0.1, 0.1]}");
  if (present(root["disturbances"]))
    config.disturbances = read_grid(root["disturbances"], "disturbances", "{lb: [-1], ub: [1], eta: [0.2]}");
  if (present(root["constants"])) config.constants = read_constants(root["constants"]);
  if (present(root["dynamics"]))
    config.dynamics = read_string_list(root["dynamics"], "dynamics", "a list of expressions",
                                       "dynamics: [\"x0 + tau*u0*cos(u1) + w0\", \"x1 + tau*u0*sin(u1) + w0\"]");
  if (present(root["model"])) config.model = read_string(root["model"], "model", "model: bmw320i");
  if (present(root["integrator"])) config.integrator = read_integrator(root["integrator"]);
  config.noise = read_noise(required(root, "noise", "noise", "noise: {covariance: [0.75, 0.75]}"));
  config.spec = read_spec(required(root, "spec", "spec", "spec: {type: safety, horizon: 8}"));
  if (present(root["guarantee"]))
    config.guarantee = read_enum<Guarantee>(root["guarantee"], "guarantee", "guarantee: system");
  if (present(root["refine"])) {
    config.refine = detail::read_refine(root["refine"]);
    // Refinement splits cells where the gap is; a cell straddling a set's face keeps a gap no split removes.
    if (!present(root["states"]["fit_sets"])) config.fit_sets = true;
  }
  if (present(root["compute"])) config.compute = read_compute(root["compute"]);
  if (present(root["output"])) config.output = read_output(root["output"]);
  return config;
}

Config config_from_yaml(const YAML::Node& root, const ComputeOverrides& overrides) {
  Config config = read_config(root);
  apply_overrides(config, overrides);
  config.validate();
  return config;
}

Config load_config_file(const std::string& path, const ComputeOverrides& overrides) {
  return config_from_yaml(parse_yaml_text(read_config_text(path), path), overrides);
}

Config read_stored_config(const std::string& yaml_text) {
  return read_config(parse_yaml_text(yaml_text, "config_yaml"));
}

}  // namespace amytiss
