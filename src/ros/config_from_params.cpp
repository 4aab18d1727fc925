#include "config_from_params.hpp"

#include <sstream>

#include "amytiss/errors.hpp"

namespace amytiss_ros {

const std::vector<std::string> kNodeParameterKeys = {"policy_file", "device", "synthesize_on_start",
                                                     "heartbeat_period_s", "diagnostic_period"};

YAML::Node yaml_from_xmlrpc(XmlRpc::XmlRpcValue& value, const std::string& path, std::size_t depth) {
  // The schema nests three levels; a deeper tree is refused before it can exhaust the stack.
  constexpr std::size_t kMaxDepth = 32;
  if (depth > kMaxDepth)
    throw amytiss::ConfigError(path, "got parameters nested deeper than " + std::to_string(kMaxDepth) +
                                         " levels, expected the configuration schema (example: "
                                         "states: {lb: [-10, -10], ub: [10, 10], eta: [0.5, 0.5]})");
  switch (value.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return YAML::Node(static_cast<bool>(value));
    case XmlRpc::XmlRpcValue::TypeInt:
      return YAML::Node(static_cast<int>(value));
    case XmlRpc::XmlRpcValue::TypeDouble:
      return YAML::Node(static_cast<double>(value));
    case XmlRpc::XmlRpcValue::TypeString:
      return YAML::Node(static_cast<std::string>(value));
    case XmlRpc::XmlRpcValue::TypeArray: {
      YAML::Node sequence(YAML::NodeType::Sequence);
      for (int i = 0; i < value.size(); ++i)
        sequence.push_back(yaml_from_xmlrpc(value[i], path + "[" + std::to_string(i) + "]", depth + 1));
      return sequence;
    }
    case XmlRpc::XmlRpcValue::TypeStruct: {
      YAML::Node map(YAML::NodeType::Map);
      for (auto& member : value)
        map[member.first] =
            yaml_from_xmlrpc(member.second, path.empty() ? member.first : path + "." + member.first, depth + 1);
      return map;
    }
    case XmlRpc::XmlRpcValue::TypeInvalid:
      return YAML::Node(YAML::NodeType::Null);
    default:
      throw amytiss::ConfigError(path.empty() ? "<parameters>" : path,
                                 "got a date-time or binary parameter, expected a number, string, "
                                 "list or map (example: eta: [0.5, 0.5])");
  }
}

namespace {

amytiss::Config config_from_tree(YAML::Node tree, const std::string& device_override) {
  if (!tree.IsMap())
    throw amytiss::ConfigError("<parameters>",
                               "got no configuration map, expected the YAML schema loaded into the "
                               "node's private namespace (example: <rosparam command=\"load\" "
                               "file=\"$(find amytiss)/config/robot_reach_avoid.yaml\"/>)");
  for (const auto& key : kNodeParameterKeys) tree.remove(key);
  amytiss::ComputeOverrides overrides;
  overrides.device = device_override;
  return amytiss::config_from_yaml(tree, overrides);
}

}  // namespace

amytiss::Config config_from_params(XmlRpc::XmlRpcValue& private_params, const std::string& device_override) {
  if (private_params.getType() != XmlRpc::XmlRpcValue::TypeStruct)
    return config_from_tree(YAML::Node(), device_override);
  return config_from_tree(yaml_from_xmlrpc(private_params), device_override);
}

amytiss::Config config_from_yaml_text(const std::string& text, const std::string& device_override) {
  YAML::Node tree;
  try {
    tree = YAML::Load(text);
  } catch (const YAML::Exception& error) {
    std::ostringstream message;
    message << "got text that is not YAML (line " << error.mark.line + 1 << ", column "
            << error.mark.column + 1 << ": " << error.msg
            << "), expected the configuration schema (example: name: robot\\nstates: {lb: [-10], ...})";
    throw amytiss::ConfigError("config_yaml", message.str());
  }
  return config_from_tree(tree, device_override);
}

}  // namespace amytiss_ros
