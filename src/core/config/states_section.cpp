// Config::validate()'s checks of a state grid whose dimensions may be given by their faces
// (`states.faces`), and of `states.fit_sets`.
#include <cmath>
#include <string>

#include "amytiss/config.hpp"
#include "amytiss/grid_rules.hpp"
#include "config/messages.hpp"

namespace amytiss::detail {
namespace {

const char* const kFacesExample = "faces: [~, [-1, 0, 0.5, 2]]";
const char* const kStatesExample = "states: {lb: [-10, ~], ub: [10, ~], eta: [0.5, ~], faces: [~, [-1, 0, 0.5, 2]]}";

void check_face_list(const std::vector<double>& faces, std::size_t d) {
  const std::string key = indexed("states.faces", d);
  if (faces.size() < 2)
    fail(key, format_list(faces), "at least 2 faces (one cell between each neighbouring pair)", kFacesExample);
  for (std::size_t k = 0; k < faces.size(); ++k) {
    if (!std::isfinite(faces[k]))
      fail(indexed(key, k), format_number(faces[k]), "a finite number", kFacesExample);
    if (k > 0 && !(faces[k - 1] < faces[k]))
      fail(key, format_list(faces),
           "strictly increasing faces (face " + std::to_string(k) + ", " + format_number(faces[k]) +
               ", is not above face " + std::to_string(k - 1) + ", " + format_number(faces[k - 1]) + ")",
           kFacesExample);
  }
}

// lb, ub and eta hold null exactly where a dimension has faces: a number there would be a second
// description of the same dimension, so it is refused rather than ignored or compared.
void check_entry(const std::vector<double>& values, const char* name, std::size_t d, bool faced) {
  const std::string key = indexed(std::string("states.") + name, d);
  if (faced && !std::isnan(values[d]))
    fail(key, format_number(values[d]),
         "null (~): states.faces[" + std::to_string(d) + "] gives the cells of dimension " + std::to_string(d),
         kStatesExample);
  if (!faced && !std::isfinite(values[d]))
    fail(key, std::isnan(values[d]) ? "null" : format_number(values[d]),
         "a finite number (dimension " + std::to_string(d) + " has no faces in states.faces)", kStatesExample);
}

}  // namespace

double check_faced_states(const GridSpec& states, std::uint64_t max_points) {
  const std::size_t n = states.faces.size();
  if (n == 0) fail("states.faces", "[]", "one entry per state dimension (null for a uniform one)", kFacesExample);
  for (const auto& [name, list] : {std::pair{"lb", &states.lb}, {"ub", &states.ub}, {"eta", &states.eta}})
    if (list->size() != n)
      fail(std::string("states.") + name, std::to_string(list->size()) + " values",
           std::to_string(n) + " values, as many as states.faces has entries", kStatesExample);
  double points = 1;
  for (std::size_t d = 0; d < n; ++d) {
    const bool faced = states.has_faces(d);
    check_entry(states.lb, "lb", d, faced);
    check_entry(states.ub, "ub", d, faced);
    check_entry(states.eta, "eta", d, faced);
    if (faced) {
      check_face_list(states.faces[d], d);
      points *= double(states.faces[d].size() - 1);
      continue;
    }
    if (states.eta[d] <= 0)
      fail(indexed("states.eta", d), format_number(states.eta[d]), "a number > 0", "eta: [0.5, 0.5]");
    if (states.lb[d] > states.ub[d])
      fail(indexed("states.ub", d), format_number(states.ub[d]),
           "a number >= states.lb[" + std::to_string(d) + "] = " + format_number(states.lb[d]), kStatesExample);
    points *= grid_points(states.lb[d], states.ub[d], states.eta[d]);
  }
  if (points > double(max_points))
    throw ConfigError("states", "grid too large: " + format_number(points) + " points, at most " +
                                    std::to_string(max_points) + " are supported; use fewer faces or a larger eta");
  return points;
}

void check_fit_sets(const Config& config) {
  if (config.fit_sets && config.guarantee != Guarantee::System)
    fail("states.fit_sets", "true",
         "false with guarantee: abstraction (fitted faces make the system bounds exact at the sets' "
         "boundaries; the abstraction's values are those of the cells' points)",
         "guarantee: system");
}

}  // namespace amytiss::detail
