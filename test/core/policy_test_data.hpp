#pragma once
// Hand-made policies for the policy-file tests: no synthesis, values that are not round in
// binary (so an inexact write shows), any grid size.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "amytiss/config.hpp"
#include "amytiss/policy.hpp"

namespace amytiss {
namespace test_support {

/// A safety configuration of n x n state cells (points 0..n-1 per dimension), 3 inputs.
inline Config square_policy_config(std::size_t cells_per_dimension, unsigned horizon) {
  const double last = double(cells_per_dimension - 1);
  Config config;
  config.name = "policy_file_test";
  config.states = GridSpec{{0.0, 0.0}, {last, last}, {1.0, 1.0}};
  config.inputs = GridSpec{{-1.0}, {1.0}, {1.0}};
  config.dynamics = {"x0 + 0.1*u0", "x1"};
  config.noise.covariance = {0.1, 0.1};
  config.spec.type = SpecType::Safety;
  config.spec.horizon = horizon;
  return config;
}

/// 5 x 4 cells, 3 inputs, horizon 3.
inline Config tiny_config() {
  Config config = square_policy_config(2, 3);
  config.states = GridSpec{{-1.0, 0.0}, {1.0, 1.5}, {0.5, 0.5}};
  return config;
}

/// A policy of the configuration's grids and horizon with values in [0, 1] and inputs in range.
inline Policy tiny_policy(const Config& config) {
  Policy policy;
  policy.states = Grid(config.states);
  policy.inputs = config.inputs ? Grid(*config.inputs) : Grid();
  policy.horizon = config.spec.horizon;
  const std::size_t cells = policy.states.size();
  for (std::size_t step = 0; step <= policy.horizon; ++step)
    for (std::size_t cell = 0; cell < cells; ++cell)
      policy.values.push_back(std::fmod(0.1 * double(step) + std::sqrt(double(cell) / 7.0), 1.0));
  for (std::size_t step = 0; step < policy.horizon; ++step)
    for (std::size_t cell = 0; cell < cells; ++cell)
      policy.input_index.push_back(std::uint32_t((cell + step) % policy.inputs.size()));
  for (std::size_t cell = 0; cell < cells; ++cell) policy.roles.push_back(CellRole(cell % 3));
  policy.computed_by = "hand-made (test)";
  policy.config_hash = config_hash(config);
  policy.run_id = "0123456789abcdef";
  return policy;
}

}  // namespace test_support
}  // namespace amytiss
