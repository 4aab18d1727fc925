// Reading the values of a configuration's YAML tree: the key in every error (config/yaml_read.hpp).
#include "config/yaml_read.hpp"

#include <cmath>
#include <cstdint>
#include <map>

namespace amytiss::detail {
namespace {

// " (lines 3 and 9)", or nothing for a tree not parsed from text (no positions).
std::string lines_of(const YAML::Node& first, const YAML::Node& second) {
  if (first.Mark().is_null() || second.Mark().is_null()) return "";
  return " (lines " + std::to_string(first.Mark().line + 1) + " and " + std::to_string(second.Mark().line + 1) + ")";
}

}  // namespace

// yaml-cpp keeps both entries of a repeated key and its lookup finds the first one: a second
// `guarantee:` further down would be ignored without this check.
void add_once(std::map<std::string, YAML::Node>& seen, const YAML::Node& name, const std::string& key) {
  const auto [first, fresh] = seen.emplace(name.Scalar(), name);
  if (!fresh)
    throw ConfigError(key, "given twice" + lines_of(first->second, name) +
                               ", expected each key once (remove one of them)");
}

std::string node_text(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) return node.Scalar();
  if (node.IsSequence()) return "a list";
  return "a map";
}

std::string key_in(const std::string& key, const std::string& name) { return key.empty() ? name : key + "." + name; }

void check_keys(const YAML::Node& node, const std::string& key, const std::vector<std::string>& allowed,
                const std::string& example) {
  if (!node.IsMap()) fail(key, node_text(node), "a map", example);
  std::map<std::string, YAML::Node> seen;
  for (const auto& entry : node) {
    const std::string name = entry.first.Scalar();
    bool known = false;
    for (const auto& candidate : allowed) known = known || candidate == name;
    if (!known)
      throw ConfigError(key_in(key, name), "unknown key (valid keys" + (key.empty() ? std::string() : " of " + key) +
                                               ": " + join(allowed) + ")");
    add_once(seen, entry.first, key_in(key, name));
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

std::vector<double> read_number_list(const YAML::Node& node, const std::string& key, const std::string& example,
                                     bool nulls) {
  if (!node.IsSequence()) fail(key, node_text(node), "a list of numbers", example);
  std::vector<double> values;
  for (std::size_t i = 0; i < node.size(); ++i)
    values.push_back(nulls && !present(node[i]) ? std::nan("") : read_number(node[i], indexed(key, i), example));
  return values;
}

std::string read_string(const YAML::Node& node, const std::string& key, const std::string& example) {
  if (!node.IsScalar()) fail(key, node_text(node), "a text value", example);
  return node.Scalar();
}

unsigned read_count(const YAML::Node& node, const std::string& key, const std::string& expected,
                    const std::string& example) {
  const double value = read_number(node, key, example);
  if (!(value >= 0 && value == std::floor(value))) fail(key, node.Scalar(), expected, example);
  if (value > double(UINT32_MAX)) fail(key, node.Scalar(), expected + " <= " + std::to_string(UINT32_MAX), example);
  return static_cast<unsigned>(value);
}

std::vector<std::string> read_string_list(const YAML::Node& node, const std::string& key, const std::string& what,
                                          const std::string& example) {
  if (!node.IsSequence()) fail(key, node_text(node), what, example);
  std::vector<std::string> values;
  for (std::size_t i = 0; i < node.size(); ++i) values.push_back(read_string(node[i], indexed(key, i), example));
  return values;
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

bool read_flag(const YAML::Node& node, const std::string& key, const std::string& example) {
  const std::string text = node.IsScalar() ? node.Scalar() : node_text(node);
  if (node.IsScalar() && (text == "true" || text == "false")) return text == "true";
  fail(key, "'" + text + "'", "true or false", example);
}

}  // namespace amytiss::detail
