#pragma once
// The concrete stochastic plant of a configuration, for closed-loop simulation (docs/cli.md,
// "Simulating the closed loop"; docs/semantics.md, "Drawing concrete noise"): x+ = f(x, u, w) +
// noise (additive) or f(x, u, w) + |x| * noise (multiplicative, per component), in state units. f
// is the configuration's map as the abstraction evaluates it (expressions, or a built-in model
// stepped by its integrator); the noise is drawn by NoiseSampler from the configuration's noise
// description, untruncated; the disturbance w, when the configuration has one, is drawn each step
// as the DisturbanceDraw says.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/grid.hpp"
#include "amytiss/model.hpp"
#include "amytiss/noise_sampler.hpp"

namespace amytiss {

/// How a plant draws the disturbance of a step (configurations with `disturbances` only).
enum class DisturbanceDraw {
  /// Uniform in the box [disturbances.lb, disturbances.ub].
  Box,
  /// Uniform among the points of the disturbance grid: the disturbances the continuous-system
  /// bounds cover (guarantee: system holds for every strategy on the grid, a random one included).
  GridPoints,
};

class Plant {
 public:
  /// `config` passed Config::validate(). Throws ConfigError from make_dynamics().
  explicit Plant(const Config& config, DisturbanceDraw draw = DisturbanceDraw::Box);

  std::size_t state_dims() const { return state_dims_; }
  std::size_t input_dims() const { return input_dims_; }
  DisturbanceDraw disturbance_draw() const { return draw_; }
  /// One step from state[0..state_dims()) under input[0..input_dims()) (null when there is no
  /// input): writes the next state to next[0..state_dims()). Draws, in this order, the
  /// disturbance (when there is one) and the noise from `random`: the same generator state gives
  /// the same step. Const and free of shared scratch: one plant may step on several threads, each
  /// with its own generator.
  void step(const double* state, const double* input, double* next, std::mt19937_64& random) const;
  std::vector<double> step(const std::vector<double>& state, const std::vector<double>& input,
                           std::mt19937_64& random) const;

 private:
  std::unique_ptr<Dynamics> dynamics_;
  std::size_t state_dims_ = 0, input_dims_ = 0;
  NoiseSampler noise_;
  DisturbanceDraw draw_;
  std::optional<GridSpec> disturbances_;  // the configuration's box and grid
  Grid disturbance_grid_;
};

}  // namespace amytiss
