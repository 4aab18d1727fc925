#include "amytiss/plant.hpp"

#include <stdexcept>

namespace amytiss {

Plant::Plant(const Config& config, DisturbanceDraw draw)
    : dynamics_(make_dynamics(config)),
      state_dims_(config.states.lb.size()),
      input_dims_(config.inputs ? config.inputs->lb.size() : 0),
      noise_(config.noise, state_dims_, config.constants),
      draw_(draw),
      disturbances_(config.disturbances),
      disturbance_grid_(config.disturbances ? Grid(*config.disturbances) : Grid()) {}

void Plant::step(const double* state, const double* input, double* next, std::mt19937_64& random) const {
  // The disturbance is drawn before the noise, so a plant with a disturbance box replays the
  // trajectories the ROS plant simulator has always drawn for a seed.
  std::vector<double> disturbance;
  if (disturbances_) {
    if (draw_ == DisturbanceDraw::Box) {
      for (std::size_t i = 0; i < disturbances_->lb.size(); ++i)
        disturbance.push_back(
            std::uniform_real_distribution<double>(disturbances_->lb[i], disturbances_->ub[i])(random));
    } else {
      const std::size_t point =
          std::uniform_int_distribution<std::size_t>(0, disturbance_grid_.size() - 1)(random);
      disturbance = disturbance_grid_.point(point);
    }
  }
  dynamics_->evaluate(state, input_dims_ ? input : nullptr, disturbance.empty() ? nullptr : disturbance.data(),
                      next);
  const std::vector<double> noise = noise_.draw(state, random);
  for (std::size_t i = 0; i < state_dims_; ++i) next[i] += noise[i];
}

std::vector<double> Plant::step(const std::vector<double>& state, const std::vector<double>& input,
                                std::mt19937_64& random) const {
  if (state.size() != state_dims_ || input.size() != input_dims_)
    throw std::invalid_argument("Plant::step: got a state of " + std::to_string(state.size()) + " and an input of " +
                                std::to_string(input.size()) + " values, expected " + std::to_string(state_dims_) +
                                " and " + std::to_string(input_dims_));
  std::vector<double> next(state_dims_);
  step(state.data(), input.data(), next.data(), random);
  return next;
}

}  // namespace amytiss
