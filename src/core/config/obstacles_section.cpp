// Config::validate()'s checks of `spec.obstacles` and `spec.footprint` (docs/configuration.md,
// "Obstacles and the car's footprint").
#include <algorithm>
#include <cmath>
#include <string>

#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/footprint.hpp"
#include "config/messages.hpp"

namespace amytiss::detail {
namespace {

const char* const kFootprintExample = "footprint: {pose: [0, 1, 2], length: 4.9, width: 1.9, rear_overhang: 1.0}";
const char* const kObstacleExample = "obstacles: [{lb: [3, 0], ub: [4, 2]}, {lb: [-4, 0], ub: [-3, 2]}]";

void check_footprint(const Footprint& footprint, std::size_t n) {
  if (footprint.pose.size() != 3)
    fail("spec.footprint.pose", std::to_string(footprint.pose.size()) + " indices",
         "3 state indices [x, y, heading]", kFootprintExample);
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string key = indexed("spec.footprint.pose", i);
    if (footprint.pose[i] >= n)
      fail(key, std::to_string(footprint.pose[i]), "a state index < " + std::to_string(n) + " (the state dimension)",
           kFootprintExample);
    for (std::size_t j = 0; j < i; ++j)
      if (footprint.pose[j] == footprint.pose[i])
        fail(key, std::to_string(footprint.pose[i]),
             "an index other than spec.footprint.pose[" + std::to_string(j) + "] (x, y and heading are distinct)",
             kFootprintExample);
  }
  if (!(std::isfinite(footprint.rear_overhang) && footprint.rear_overhang >= 0))
    fail("spec.footprint.rear_overhang", format_number(footprint.rear_overhang), "a finite number >= 0 (m)",
         kFootprintExample);
  if (!(std::isfinite(footprint.length) && footprint.length > footprint.rear_overhang))
    fail("spec.footprint.length", format_number(footprint.length),
         "a finite number > spec.footprint.rear_overhang = " + format_number(footprint.rear_overhang) + " (m)",
         kFootprintExample);
  if (!(std::isfinite(footprint.width) && footprint.width > 0))
    fail("spec.footprint.width", format_number(footprint.width), "a finite number > 0 (m)", kFootprintExample);
}

void check_obstacle_box(const Box& box, const std::string& key) {
  if (box.lb.size() != 2)
    fail(key + ".lb", std::to_string(box.lb.size()) + " values", "2 values [x, y] (obstacles are world-frame boxes)",
         kObstacleExample);
  if (box.ub.size() != 2)
    fail(key + ".ub", std::to_string(box.ub.size()) + " values", "2 values [x, y] (obstacles are world-frame boxes)",
         kObstacleExample);
  check_finite_list(box.lb, key + ".lb", kObstacleExample);
  check_finite_list(box.ub, key + ".ub", kObstacleExample);
  for (std::size_t i = 0; i < 2; ++i)
    if (box.lb[i] > box.ub[i])
      fail(indexed(key + ".ub", i), format_number(box.ub[i]),
           "a number >= " + key + ".lb[" + std::to_string(i) + "] = " + format_number(box.lb[i]), kObstacleExample);
}

// The body's test over every cell must end in reasonable time: refused past its budget, naming the
// dimension of the body that sets the pieces' length (the width, unless the cells are coarser).
void check_footprint_work(const SpecConfig& spec, const GridSpec& states) {
  const double tests = footprint_box_tests(states, spec);
  if (tests <= kMaxFootprintBoxTests) return;
  const Footprint& footprint = *spec.footprint;
  const bool by_width = 0.5 * footprint.width >= grid_body_cut(states, spec).min_side;
  const std::string estimate = footprint_work_text(states, spec);
  fail(by_width ? "spec.footprint.width" : "spec.footprint.length",
       format_number(by_width ? footprint.width : footprint.length) + ": its test of the cells needs " + estimate,
       "a body tested in at most " + format_number(kMaxFootprintBoxTests) +
           " box tests (pieces of side max(width/2, half the finer cell side in x and y) along its length; a " +
           (by_width ? "wider" : "shorter") + " body, fewer cells or fewer obstacles)",
       kFootprintExample);
}

}  // namespace

void check_obstacles(const SpecConfig& spec, const GridSpec& states) {
  const std::size_t n = states.lb.size();
  if (!spec.obstacles && !spec.footprint) return;
  if (!spec.footprint)
    throw ConfigError("spec.footprint",
                      std::string("missing, expected it with spec.obstacles (example: ") + kFootprintExample + ")");
  if (!spec.obstacles)
    throw ConfigError("spec.obstacles",
                      std::string("missing, expected it with spec.footprint (example: ") + kObstacleExample + ")");
  if (spec.type == SpecType::Reachability)
    throw ConfigError("spec.obstacles",
                      "given for spec.type reachability; use reach_avoid (or safety) to avoid obstacles");
  check_footprint(*spec.footprint, n);
  const Region& obstacles = *spec.obstacles;
  if (obstacles.boxes.empty()) fail("spec.obstacles", "[]", "a box or a non-empty list of boxes", kObstacleExample);
  for (std::size_t i = 0; i < obstacles.boxes.size(); ++i)
    check_obstacle_box(obstacles.boxes[i],
                       obstacles.boxes.size() == 1 ? "spec.obstacles" : indexed("spec.obstacles", i));
  check_footprint_work(spec, states);
}

}  // namespace amytiss::detail
