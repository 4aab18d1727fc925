#pragma once
// Helpers shared by reading a configuration (config/yaml.cpp) and validating it
// (config/validate.cpp): error messages that name the key, the value and an example.
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/format.hpp"

namespace amytiss::detail {

/// The most points a grid may have: 2^32 - 1, its flat indices are uint32.
inline constexpr std::uint64_t kMaxGridPoints = 4294967295ull;

/// Throws ConfigError(key, "got <got>, expected <expected> (example: <example>)").
[[noreturn]] inline void fail(const std::string& key, const std::string& got, const std::string& expected,
                              const std::string& example) {
  throw ConfigError(key, "got " + got + ", expected " + expected + " (example: " + example + ")");
}

/// "key[index]".
inline std::string indexed(const std::string& key, std::size_t index) {
  return key + "[" + std::to_string(index) + "]";
}

/// The items separated by ", ".
inline std::string join(const std::vector<std::string>& items) {
  std::string text;
  for (const auto& item : items) text += (text.empty() ? "" : ", ") + item;
  return text;
}

/// "[1, 2.5]" with format_number().
inline std::string format_list(const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + format_number(values[i]);
  return text + "]";
}

/// The checks of the `noise` section for n state dimensions (config/noise_section.cpp); custom densities
/// may use `constants`.
void check_noise(const NoiseConfig& noise, std::size_t n, const std::map<std::string, double>& constants);

/// Config::validate()'s checks of `spec.obstacles` and `spec.footprint` (obstacles_section.cpp);
/// `states`: the state grid (its dimension, and the cells the footprint is tested on).
void check_obstacles(const SpecConfig& spec, const GridSpec& states);

/// Config::validate()'s checks of a state grid with `states.faces` (config/states_section.cpp):
/// the faces, lb/ub/eta null exactly where faces are given, at most max_points points. Returns the
/// number of points.
double check_faced_states(const GridSpec& states, std::uint64_t max_points);
/// Refuses `states.fit_sets: true` under guarantee abstraction (config/states_section.cpp).
void check_fit_sets(const Config& config);

/// Throws ConfigError naming key[i] for the first value that is NaN or infinite.
inline void check_finite_list(const std::vector<double>& values, const std::string& key, const std::string& example) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i])) fail(indexed(key, i), format_number(values[i]), "a finite number", example);
}

}  // namespace amytiss::detail
