#pragma once
// Reading the values of a configuration's YAML tree (config/yaml.cpp and the sections beside it):
// each function names the key in its error, with what it got and an example; unknown keys, keys
// given twice and wrong types are refused here, the values' meaning is judged by Config::validate().
#include <map>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "amytiss/config.hpp"
#include "amytiss/enum_names.hpp"
#include "config/messages.hpp"

namespace amytiss::detail {

/// What a node holds, for messages: its scalar, "a list", "a map" or "nothing".
std::string node_text(const YAML::Node& node);
/// Records the key `name` in `seen`; ConfigError(key, "given twice (lines a and b)") when it is
/// there already.
void add_once(std::map<std::string, YAML::Node>& seen, const YAML::Node& name, const std::string& key);
/// "key.name", or "name" at the top level (key empty).
std::string key_in(const std::string& key, const std::string& name);
/// Refuses a node that is not a map, a key not in `allowed` and a key given twice.
void check_keys(const YAML::Node& node, const std::string& key, const std::vector<std::string>& allowed,
                const std::string& example);
/// Whether the node is given and not null.
bool present(const YAML::Node& node);
/// The node under `name`, or ConfigError(key, "missing ...").
const YAML::Node required(const YAML::Node& parent, const std::string& name, const std::string& key,
                          const std::string& example);

double read_number(const YAML::Node& node, const std::string& key, const std::string& example);
/// With `nulls`, null (~) stands for a dimension given by states.faces and reads as NaN.
std::vector<double> read_number_list(const YAML::Node& node, const std::string& key, const std::string& example,
                                     bool nulls = false);
std::string read_string(const YAML::Node& node, const std::string& key, const std::string& example);
/// A count or an index: an integer that fits an unsigned 32-bit field. Whether it is in range is
/// validate()'s to judge; `expected` says what the key holds ("a positive integer").
unsigned read_count(const YAML::Node& node, const std::string& key, const std::string& expected,
                    const std::string& example);
std::vector<std::string> read_string_list(const YAML::Node& node, const std::string& key, const std::string& what,
                                          const std::string& example);
GridSpec read_grid(const YAML::Node& node, const std::string& key, const std::string& example);
bool read_flag(const YAML::Node& node, const std::string& key, const std::string& example);

template <typename Enum>
Enum read_enum(const YAML::Node& node, const std::string& key, const std::string& example) {
  const std::string text = read_string(node, key, example);
  if (const auto value = enum_from_name<Enum>(text)) return *value;
  fail(key, "'" + text + "'", "one of " + enum_name_list<Enum>(), example);
}

}  // namespace amytiss::detail
