// The `refine` section (docs/refinement.md): reading it from YAML and Config::validate()'s checks.
#include <cmath>
#include <cstdint>
#include <string>

#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/grid.hpp"
#include "amytiss/grid_rules.hpp"
#include "config/messages.hpp"
#include "config/refine_section.hpp"
#include "config/yaml_read.hpp"

namespace amytiss::detail {
namespace {

const char* const kRefineExample = "refine: {at: [[-8, -8]], gap: 0.05, max_states: 200000, max_rounds: 6, max_seconds: 600}";

// The highest max_rounds accepted: each round at least one halving, far more than any budget of
// states or seconds lets run.
constexpr unsigned kMaxRefineRounds = 100;

std::vector<std::vector<double>> read_points(const YAML::Node& node) {
  const char* const example = "at: [[-8, -8], [0, 4]]";
  if (!node.IsSequence()) fail("refine.at", node_text(node), "a list of state points", example);
  std::vector<std::vector<double>> points;
  for (std::size_t i = 0; i < node.size(); ++i) points.push_back(read_number_list(node[i], indexed("refine.at", i), example));
  return points;
}

void check_point(const std::vector<double>& point, std::size_t i, const Grid& states) {
  const std::string key = indexed("refine.at", i);
  const char* const example = "at: [[-8, -8]]";
  if (point.size() != states.dims())
    fail(key, std::to_string(point.size()) + " values",
         std::to_string(states.dims()) + ", one per state dimension", example);
  check_finite_list(point, key, example);
  if (!states.cell_of(point.data()))
    fail(key, format_list(point), "a state inside the grid's covered box", example);
}

}  // namespace

RefineConfig read_refine(const YAML::Node& node) {
  check_keys(node, "refine", {"at", "gap", "max_states", "max_rounds", "max_seconds"}, kRefineExample);
  RefineConfig refine;
  if (present(node["at"])) refine.at = read_points(node["at"]);
  if (present(node["gap"])) refine.gap = read_number(node["gap"], "refine.gap", "gap: 0.05");
  // A grid's flat indices are uint32: read_count's range is the grid's.
  static_assert(kMaxGridPoints == UINT32_MAX, "max_states is read as a count");
  if (present(node["max_states"]))
    refine.max_states = read_count(node["max_states"], "refine.max_states", "a whole number of state cells",
                                   "max_states: 200000");
  if (present(node["max_rounds"]))
    refine.max_rounds = read_count(node["max_rounds"], "refine.max_rounds", "a positive integer", "max_rounds: 6");
  if (present(node["max_seconds"]))
    refine.max_seconds = read_number(node["max_seconds"], "refine.max_seconds", "max_seconds: 600");
  return refine;
}

void check_refine(const Config& config, const GridSpec& fitted) {
  if (!config.refine) return;
  const RefineConfig& refine = *config.refine;
  if (config.guarantee != Guarantee::System)
    fail("refine", "a refine section with guarantee: " + to_string(config.guarantee),
         "guarantee: system (refinement narrows the continuous-system bounds; the abstraction's values have no gap)",
         "guarantee: system");
  const Grid states(fitted);
  for (std::size_t i = 0; i < refine.at.size(); ++i) check_point(refine.at[i], i, states);
  if (!(refine.gap > 0 && refine.gap < 1)) fail("refine.gap", format_number(refine.gap), "a number in (0, 1)", "gap: 0.05");
  if (refine.max_states != 0 && refine.max_states < states.size())
    fail("refine.max_states", std::to_string(refine.max_states),
         "0 (16 times the first grid's) or at least the first grid's " + std::to_string(states.size()) + " cells",
         "max_states: " + std::to_string(states.size() * RefineConfig::kDefaultStatesFactor));
  if (refine.max_rounds < 1 || refine.max_rounds > kMaxRefineRounds)
    fail("refine.max_rounds", std::to_string(refine.max_rounds), "an integer from 1 to 100", "max_rounds: 6");
  if (!(refine.max_seconds > 0 && std::isfinite(refine.max_seconds)))
    fail("refine.max_seconds", format_number(refine.max_seconds), "a positive number of seconds", "max_seconds: 600");
}

}  // namespace amytiss::detail
