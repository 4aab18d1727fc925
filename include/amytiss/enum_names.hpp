#pragma once
// The one table of enum names: the words a configuration, an amytiss_synth option, a policy file
// and a ROS message use for each enum value ("reach_avoid", "on_the_fly", "synthesis", ...).
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/synthesis_types.hpp"

namespace amytiss {

/// Every value of Enum with its name, in declaration order.
template <typename Enum>
const std::vector<std::pair<const char*, Enum>>& enum_names();

/// The value named `name`, or nothing when no value has that name.
template <typename Enum>
std::optional<Enum> enum_from_name(const std::string& name) {
  for (const auto& [text, value] : enum_names<Enum>())
    if (name == text) return value;
  return std::nullopt;
}

/// The names of every value joined: "auto, cpu, gpu, reference".
template <typename Enum>
std::string enum_name_list() {
  std::string text;
  for (const auto& entry : enum_names<Enum>()) text += (text.empty() ? "" : ", ") + std::string(entry.first);
  return text;
}

}  // namespace amytiss
