#pragma once
// ROS parameters -> amytiss::Config. The synthesizer's private namespace holds the YAML schema of
// docs/configuration.md (loaded with <rosparam command="load">) plus a few node keys (kNodeParameterKeys)
// that are not part of the configuration.
#include <string>
#include <vector>

#include <XmlRpcValue.h>
#include <yaml-cpp/yaml.h>

#include "amytiss/config.hpp"

namespace amytiss_ros {

/// Private parameters of the synthesizer that are not configuration keys.
extern const std::vector<std::string> kNodeParameterKeys;

/// The XmlRpc tree as YAML: struct -> map, array -> sequence, int/double/bool/string -> scalars
/// (doubles with full precision). Throws amytiss::ConfigError (key "<path>") for XmlRpc types
/// with no YAML counterpart (date-time, base64) and for trees nested deeper than 32 levels.
YAML::Node yaml_from_xmlrpc(XmlRpc::XmlRpcValue& value, const std::string& path = "", std::size_t depth = 0);

/// Converts the private-namespace tree (a struct) to a validated configuration: drops
/// kNodeParameterKeys, then amytiss::config_from_yaml with `device_override` as the override of
/// compute.device when it is not empty ("auto", "cpu", "gpu", "reference"). Throws ConfigError.
amytiss::Config config_from_params(XmlRpc::XmlRpcValue& private_params,
                                   const std::string& device_override = "");

/// The same from YAML text (the Synthesize action's config_yaml). Throws ConfigError, also for
/// text that is not YAML (key "config_yaml", with the line and column).
amytiss::Config config_from_yaml_text(const std::string& text, const std::string& device_override = "");

}  // namespace amytiss_ros
