// The compute keys, the guarantee and the refine section given beside a configuration (CLI
// options, the ROS ~device parameter) replace the configuration's before Config::validate()
// judges the whole.
#include "amytiss/config.hpp"
#include "amytiss/enum_names.hpp"
#include "config/messages.hpp"

namespace amytiss {
namespace {

template <typename Enum>
void override_enum(Enum& value, const std::string& text, const std::string& key) {
  if (text.empty()) return;
  const auto parsed = enum_from_name<Enum>(text);
  if (!parsed) throw ConfigError(key, "got '" + text + "', expected one of " + enum_name_list<Enum>());
  value = *parsed;
}

bool default_prefix_of(const ComputeOverrides& overrides) {
  return overrides.key_prefix == ComputeOverrides{}.key_prefix;
}

}  // namespace

void apply_overrides(Config& config, const ComputeOverrides& overrides) {
  ComputeConfig& compute = config.compute;
  override_enum(compute.device, overrides.device, overrides.key_prefix + "device");
  override_enum(compute.transitions, overrides.transitions, overrides.key_prefix + "transitions");
  override_enum(compute.sweep, overrides.sweep, overrides.key_prefix + "sweep");
  override_enum(compute.bounds_method, overrides.bounds_method,
                overrides.key_prefix + (default_prefix_of(overrides) ? "bounds_method" : "bounds-method"));
  if (!overrides.platform.empty()) compute.platform = overrides.platform;
  if (!overrides.devices.empty()) compute.devices = overrides.devices;
  override_enum(config.guarantee, overrides.guarantee,
                default_prefix_of(overrides) ? "guarantee" : overrides.key_prefix + "guarantee");
  if (overrides.refine) {
    // A configuration without refine had fit_sets at its default, which refine turns on.
    if (!config.refine) config.fit_sets = true;
    config.refine = overrides.refine;
  }
}

}  // namespace amytiss
