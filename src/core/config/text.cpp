// Canonical text of a configuration (all keys, fixed order, full precision) and its hash.
#include <cmath>

#include "amytiss/config.hpp"
#include "amytiss/format.hpp"
#include "config/messages.hpp"

namespace amytiss {
namespace {

using detail::format_list;

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

std::string grid_yaml(const GridSpec& grid) {
  return "{lb: " + format_list(grid.lb) + ", ub: " + format_list(grid.ub) + ", eta: " + format_list(grid.eta) + "}";
}

// The states' grid: as before faces existed unless a dimension has faces or fit_sets is on, so
// that uniform configurations keep their text and hash. Null (~) where a dimension has faces.
std::string states_yaml(const Config& config) {
  const GridSpec& grid = config.states;
  bool faced = false;
  for (std::size_t d = 0; d < grid.faces.size(); ++d) faced = faced || grid.has_faces(d);
  if (!faced && !config.fit_sets && !config.refine) return grid_yaml(grid);
  auto list = [](const std::vector<double>& values) {
    std::string text = "[";
    for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + (std::isnan(values[i]) ? "~" : format_number(values[i]));
    return text + "]";
  };
  std::string text = "{lb: " + list(grid.lb) + ", ub: " + list(grid.ub) + ", eta: " + list(grid.eta);
  if (faced) {
    text += ", faces: [";
    for (std::size_t d = 0; d < grid.faces.size(); ++d) text += (d ? ", " : "") + (grid.has_faces(d) ? list(grid.faces[d]) : "~");
    text += "]";
  }
  // With refine, fit_sets is on unless the file turns it off.
  if (config.fit_sets)
    text += ", fit_sets: true";
  else if (config.refine)
    text += ", fit_sets: false";
  return text + "}";
}

std::string box_yaml(const Box& box) { return "{lb: " + format_list(box.lb) + ", ub: " + format_list(box.ub) + "}"; }

// One box prints as before unions existed, so that the texts and hashes of those configurations stay.
std::string region_yaml(const Region& region) {
  if (region.boxes.size() == 1) return box_yaml(region.boxes.front());
  std::string text = "[";
  for (std::size_t i = 0; i < region.boxes.size(); ++i) text += (i ? ", " : "") + box_yaml(region.boxes[i]);
  return text + "]";
}

std::string footprint_yaml(const Footprint& footprint) {
  std::string pose = "[";
  for (std::size_t i = 0; i < footprint.pose.size(); ++i) pose += (i ? ", " : "") + std::to_string(footprint.pose[i]);
  return "{pose: " + pose + "], length: " + format_number(footprint.length) + ", width: " +
         format_number(footprint.width) + ", rear_overhang: " + format_number(footprint.rear_overhang) + "}";
}

// Every key, defaults too: where the rounds stop is part of the result.
std::string refine_yaml(const RefineConfig& refine) {
  std::string at = "[";
  for (std::size_t i = 0; i < refine.at.size(); ++i) at += (i ? ", " : "") + format_list(refine.at[i]);
  return "{at: " + at + "], gap: " + format_number(refine.gap) + ", max_states: " +
         std::to_string(refine.max_states) + ", max_rounds: " + std::to_string(refine.max_rounds) +
         ", max_seconds: " + format_number(refine.max_seconds) + "}";
}

// compute and output: how the result is computed and stored.
std::string unhashed_yaml(const Config& config) {
  std::string text;
  const ComputeConfig& compute = config.compute;
  text += "compute:\n";
  text += "  device: " + to_string(compute.device) + "\n";
  text += "  transitions: " + to_string(compute.transitions) + "\n";
  text += "  sweep: " + to_string(compute.sweep) + "\n";
  // Left out when it is the default, so files of configurations without the key keep their text.
  if (compute.bounds_method != BoundsMethod::Auto)
    text += "  bounds_method: " + to_string(compute.bounds_method) + "\n";
  text += "  platform: " + quoted(compute.platform) + "\n";
  text += "  device_name: " + quoted(compute.device_name) + "\n";
  text += "  memory_fraction: " + format_number(compute.memory_fraction) + "\n";
  if (!compute.devices.empty()) {
    text += "  devices: [";
    for (std::size_t i = 0; i < compute.devices.size(); ++i) text += (i ? ", " : "") + quoted(compute.devices[i]);
    text += "]\n";
  }
  // Left out when it is the default, so files of configurations without the key keep their text.
  if (config.output.values != ValueStorage::Exact)
    text += "output: {values: " + to_string(config.output.values) + "}\n";
  return text;
}

std::string canonical_yaml(const Config& config, bool with_unhashed_sections) {
  std::string text;
  text += "name: " + quoted(config.name) + "\n";
  text += "states: " + states_yaml(config) + "\n";
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
  // The default integrator is left out, so configurations without the key keep their text and hash.
  if (!config.integrator.is_default()) {
    text += "integrator: {method: " + to_string(config.integrator.method) +
            ", substeps: " + std::to_string(config.integrator.substeps);
    if (config.integrator.tau) text += ", tau: " + format_number(*config.integrator.tau);
    text += "}\n";
  }
  const NoiseConfig& noise = config.noise;
  text += "noise:\n";
  text += "  type: " + to_string(noise.type) + "\n";
  text += "  distribution: " + to_string(noise.distribution) + "\n";
  if (!noise.covariance.empty()) text += "  covariance: " + format_list(noise.covariance) + "\n";
  if (!noise.half_width.empty()) text += "  half_width: " + format_list(noise.half_width) + "\n";
  if (!noise.rate.empty()) text += "  rate: " + format_list(noise.rate) + "\n";
  if (!noise.shift.empty()) text += "  shift: " + format_list(noise.shift) + "\n";
  if (!noise.alpha.empty()) text += "  alpha: " + format_list(noise.alpha) + "\n";
  if (!noise.beta.empty()) text += "  beta: " + format_list(noise.beta) + "\n";
  if (!noise.density.empty()) {
    text += "  density:\n";
    for (const auto& expression : noise.density) text += "    - " + quoted(expression) + "\n";
  }
  if (noise.support) text += "  support: " + box_yaml(*noise.support) + "\n";
  text += "  truncation: " + to_string(noise.truncation) + "\n";
  if (noise.truncation == Truncation::CuttingProbability)
    text += "  cutting_probability: " + format_number(noise.cutting_probability_or_default()) + "\n";
  if (!noise.fixed_region.empty()) text += "  fixed_region: " + format_list(noise.fixed_region) + "\n";
  text += "spec:\n";
  text += "  type: " + to_string(config.spec.type) + "\n";
  if (config.spec.unbounded) {
    text += "  horizon: infinite\n";
    text += "  tolerance: " + format_number(config.spec.tolerance_or_default()) + "\n";
  } else {
    text += "  horizon: " + std::to_string(config.spec.horizon) + "\n";
  }
  if (config.spec.safe) text += "  safe: " + region_yaml(*config.spec.safe) + "\n";
  if (config.spec.target) text += "  target: " + region_yaml(*config.spec.target) + "\n";
  if (config.spec.avoid) text += "  avoid: " + region_yaml(*config.spec.avoid) + "\n";
  // Printed only when given, so configurations without obstacles keep their text and hash.
  if (config.spec.obstacles) text += "  obstacles: " + region_yaml(*config.spec.obstacles) + "\n";
  if (config.spec.footprint) text += "  footprint: " + footprint_yaml(*config.spec.footprint) + "\n";
  // Left out when it is the default, so configurations without the key keep their text and hash.
  if (config.guarantee != Guarantee::Abstraction) text += "guarantee: " + to_string(config.guarantee) + "\n";
  if (config.refine) text += "refine: " + refine_yaml(*config.refine) + "\n";
  // compute and output change how the result is computed or stored, not the result: no hash.
  if (with_unhashed_sections) text += unhashed_yaml(config);
  return text;
}

}  // namespace

std::string to_yaml(const Config& config) { return canonical_yaml(config, true); }
std::string config_hash(const Config& config) { return hex16(fnv1a64(canonical_yaml(config, false))); }

}  // namespace amytiss
