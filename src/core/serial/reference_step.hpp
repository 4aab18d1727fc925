#pragma once
// The serial engine's Bellman step (serial/reference_step.cpp): plain loops in double precision.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "solve/bellman_step.hpp"

namespace amytiss::detail {

/// The serial engine's step, in double precision: the reference engine's, and the host's
/// computations of interval iteration (a fixed policy's value, single expected values).
class ReferenceStep : public BellmanStep {
 public:
  explicit ReferenceStep(const Abstraction& abstraction);
  void apply(const double* in, double* out, std::uint32_t* chosen) override;
  double multiply_adds() const override { return multiply_adds_; }
  void evaluate(const double* in, double* out, const std::uint32_t* controller) override;
  /// sum_x' T(x'|x,u,w) in(x') for state cell x, input index u, disturbance index w.
  double expected(std::size_t cell, std::size_t input, std::size_t disturbance, const double* in);
  /// min over disturbances of expected().
  double input_value(std::size_t cell, std::size_t input, const double* in);
  /// The input of largest input_value() for `cell` (ties: the lowest index); its value in *value.
  std::uint32_t best_input(std::size_t cell, const double* in, double* value);

 private:
  const Abstraction& a_;
  std::vector<std::vector<double>> input_points_, disturbance_points_;
  std::vector<std::size_t> strides_, multi_;
  std::vector<double> x_, mean_;
  std::vector<std::int64_t> first_, last_;
  std::vector<std::vector<double>> masses_;
  double multiply_adds_ = 0;
  double counted_ = 0;  // multiply-adds of the current apply()
  double window_sum(std::size_t dim, std::size_t offset, double probability, const double* in);
};

}  // namespace amytiss::detail
