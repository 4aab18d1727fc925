#pragma once
// Helpers of the enclosure tests: random boxes and points (fixed seeds), and configurations of
// bare dynamics for ImageEnclosure.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/enclosure.hpp"
#include "amytiss/interval.hpp"

namespace amytiss {
namespace enclosure_test {

/// A configuration with only what ImageEnclosure reads: dimensions and dynamics.
inline Config dynamics_config(std::vector<std::string> dynamics, std::size_t inputs = 0, std::size_t disturbances = 0) {
  Config config;
  config.states.lb.assign(dynamics.size(), -1.0);
  config.states.ub.assign(dynamics.size(), 1.0);
  config.states.eta.assign(dynamics.size(), 0.5);
  if (inputs) config.inputs = GridSpec{std::vector<double>(inputs, -1.0), std::vector<double>(inputs, 1.0),
                                       std::vector<double>(inputs, 0.5)};
  if (disturbances)
    config.disturbances = GridSpec{std::vector<double>(disturbances, -1.0), std::vector<double>(disturbances, 1.0),
                                   std::vector<double>(disturbances, 0.5)};
  config.dynamics = std::move(dynamics);
  return config;
}

/// A uniformly random point of `box` (finite bounds).
inline std::vector<double> random_point(const IntervalBox& box, std::mt19937_64& random) {
  std::vector<double> point;
  for (const Interval& component : box) {
    std::uniform_real_distribution<double> uniform(component.lo, component.hi);
    point.push_back(std::min(std::max(uniform(random), component.lo), component.hi));
  }
  return point;
}

/// Corner `index` of `box` (bit j picks the upper bound of component j).
inline std::vector<double> corner(const IntervalBox& box, unsigned index) {
  std::vector<double> point;
  for (std::size_t j = 0; j < box.size(); ++j) point.push_back((index >> j) & 1u ? box[j].hi : box[j].lo);
  return point;
}

/// A box of width `widths` (per component) centred at `centre`.
inline IntervalBox box_around(const std::vector<double>& centre, const std::vector<double>& widths) {
  IntervalBox box;
  for (std::size_t j = 0; j < centre.size(); ++j)
    box.push_back(Interval(centre[j] - 0.5 * widths[j], centre[j] + 0.5 * widths[j]));
  return box;
}

inline bool box_contains(const IntervalBox& box, const std::vector<double>& point) {
  for (std::size_t i = 0; i < box.size(); ++i)
    if (!box[i].contains(point[i])) return false;
  return true;
}

}  // namespace enclosure_test
}  // namespace amytiss
