// states.fit_sets: the faces of the specification's boxes become faces of the state grid, so that
// every cell lies inside or outside each box (docs/configuration.md).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "amytiss/grid.hpp"
#include "amytiss/grid_rules.hpp"

namespace amytiss {
namespace {

// The boxes' bounds along each state dimension: the sets of the specification in state
// coordinates, the obstacles (2-d, world frame) along the footprint's x and y components.
std::vector<std::vector<double>> set_faces(const SpecConfig& spec, std::size_t dims) {
  std::vector<std::vector<double>> out(dims);
  auto add_region = [&](const std::optional<Region>& region) {
    if (!region) return;
    for (const Box& box : region->boxes)
      for (std::size_t d = 0; d < dims && d < box.lb.size() && d < box.ub.size(); ++d) {
        out[d].push_back(box.lb[d]);
        out[d].push_back(box.ub[d]);
      }
  };
  add_region(spec.target);
  add_region(spec.avoid);
  add_region(spec.safe);
  if (spec.obstacles && spec.footprint && spec.footprint->pose.size() >= 2)
    for (const Box& box : spec.obstacles->boxes)
      for (std::size_t j = 0; j < 2 && j < box.lb.size() && j < box.ub.size(); ++j) {
        const std::size_t d = spec.footprint->pose[j];
        if (d >= dims) continue;
        out[d].push_back(box.lb[j]);
        out[d].push_back(box.ub[j]);
      }
  return out;
}

// Inserts each candidate lying strictly inside a cell, farther than the slack from its faces.
// Returns whether one was inserted.
bool insert_faces(std::vector<double>& faces, std::vector<double> candidates) {
  std::sort(candidates.begin(), candidates.end());
  bool inserted = false;
  for (double value : candidates) {
    if (!std::isfinite(value) || !(value > faces.front() && value < faces.back())) continue;
    const auto above = std::upper_bound(faces.begin(), faces.end(), value);
    const double hi = *above, lo = *(above - 1);
    const double slack = kFitFaceSlack * (hi - lo);
    if (value - lo <= slack || hi - value <= slack) continue;
    faces.insert(above, value);
    inserted = true;
  }
  return inserted;
}

}  // namespace

GridSpec fitted_states(const Config& config) {
  GridSpec spec = config.states;
  if (!config.fit_sets) return spec;
  const Grid grid(config.states);
  const std::vector<std::vector<double>> candidates = set_faces(config.spec, grid.dims());
  for (std::size_t d = 0; d < grid.dims(); ++d) {
    std::vector<double> faces = grid.faces(d);
    if (insert_faces(faces, candidates[d])) set_dimension_faces(spec, d, std::move(faces));
  }
  return spec;
}

void set_dimension_faces(GridSpec& spec, std::size_t dim, std::vector<double> faces) {
  spec.faces.resize(spec.lb.size());
  spec.faces[dim] = std::move(faces);
  constexpr double kNotGiven = std::numeric_limits<double>::quiet_NaN();
  spec.lb[dim] = spec.ub[dim] = spec.eta[dim] = kNotGiven;
}

}  // namespace amytiss
