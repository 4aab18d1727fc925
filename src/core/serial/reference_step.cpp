// The serial Bellman step: plain loops in double precision, written for clarity (it is the
// oracle the OpenCL engine is tested against).
#include "serial/reference_step.hpp"

#include <algorithm>
#include <limits>

namespace amytiss::detail {

ReferenceStep::ReferenceStep(const Abstraction& a)
    : a_(a),
      input_points_(a.inputs.size()),
      disturbance_points_(a.disturbances.size()),
      strides_(a.states.dims()),
      multi_(a.states.dims()),
      x_(a.states.dims()),
      mean_(a.states.dims()),
      first_(a.states.dims()),
      last_(a.states.dims()),
      masses_(a.states.dims()) {
  std::size_t stride = 1;
  for (std::size_t d = a.states.dims(); d-- > 0;) {
    strides_[d] = stride;
    stride *= a.states.count(d);
  }
  for (std::size_t u = 0; u < a.inputs.size(); ++u) input_points_[u] = a.inputs.point(u);
  for (std::size_t w = 0; w < a.disturbances.size(); ++w) disturbance_points_[w] = a.disturbances.point(w);
}

// sum over the window cells of prod_d mass_d(k_d) * in(cell), one dimension at a time.
double ReferenceStep::window_sum(std::size_t dim, std::size_t offset, double probability, const double* in) {
  const std::vector<double>& mass = masses_[dim];
  if (dim + 1 == masses_.size()) {
    // Innermost dimension: a plain dot product of its masses with the contiguous values.
    double dot = 0.0;
    for (std::int64_t k = first_[dim]; k <= last_[dim]; ++k)
      dot += mass[std::size_t(k - first_[dim])] * in[offset + std::size_t(k)];
    counted_ += double(last_[dim] - first_[dim] + 1);
    return probability * dot;
  }
  double total = 0.0;
  for (std::int64_t k = first_[dim]; k <= last_[dim]; ++k) {
    const double cell_mass = mass[std::size_t(k - first_[dim])];
    if (cell_mass == 0.0) continue;
    total += window_sum(dim + 1, offset + std::size_t(k) * strides_[dim], probability * cell_mass, in);
  }
  return total;
}

double ReferenceStep::expected(std::size_t cell, std::size_t input, std::size_t disturbance, const double* in) {
  const NoiseModel& noise = *a_.noise;
  const std::size_t dims = a_.states.dims();
  a_.states.point(cell, x_.data());
  a_.dynamics->evaluate(x_.data(), input_points_[input].data(), disturbance_points_[disturbance].data(), mean_.data());
  if (!noise.window(a_.states, mean_.data(), first_.data(), last_.data())) return 0.0;
  if (noise.separable()) {
    for (std::size_t d = 0; d < dims; ++d) {
      masses_[d].resize(std::size_t(last_[d] - first_[d] + 1));
      noise.cell_masses(d, first_[d], last_[d], mean_[d], noise.scale(d, x_.data()), masses_[d].data());
    }
    return window_sum(0, 0, 1.0, in);
  }
  // Full covariance: the box mass of every cell of the window.
  double sum = 0.0;
  for (std::size_t d = 0; d < dims; ++d) multi_[d] = std::size_t(first_[d]);
  while (true) {
    const std::size_t target = a_.states.flat_index(multi_.data());
    sum += noise.transition_probability(a_.states, target, mean_.data(), x_.data()) * in[target];
    counted_ += 1;
    std::size_t d = dims;
    while (d-- > 0) {
      if (std::int64_t(++multi_[d]) <= last_[d]) break;
      multi_[d] = std::size_t(first_[d]);
    }
    if (d == std::size_t(-1)) break;
  }
  return sum;
}

double ReferenceStep::input_value(std::size_t cell, std::size_t input, const double* in) {
  double worst = std::numeric_limits<double>::infinity();
  for (std::size_t w = 0; w < disturbance_points_.size(); ++w) worst = std::min(worst, expected(cell, input, w, in));
  return worst;
}

std::uint32_t ReferenceStep::best_input(std::size_t cell, const double* in, double* value) {
  std::uint32_t best = 0;
  *value = -1.0;
  for (std::size_t u = 0; u < input_points_.size(); ++u) {
    const double candidate = input_value(cell, u, in);
    // Strict '>': ties keep the lowest input index.
    if (candidate > *value) {
      *value = candidate;
      best = static_cast<std::uint32_t>(u);
    }
  }
  return best;
}

void ReferenceStep::apply(const double* in, double* out, std::uint32_t* chosen) {
  counted_ = 0;
  for (std::size_t cell = 0; cell < a_.states.size(); ++cell) {
    const CellRole role = a_.roles[cell];
    chosen[cell] = 0;
    if (role != CellRole::Free) {
      out[cell] = a_.terminal_value(role);
      continue;
    }
    double best_value = -1.0;
    chosen[cell] = best_input(cell, in, &best_value);
    // A sum of exact masses is at most 1, but its double rounding may exceed 1 by an ulp or so;
    // the value is a probability (and the policy file holds it to [0, 1]).
    out[cell] = std::min(best_value, 1.0);
  }
  multiply_adds_ = counted_;
}

void ReferenceStep::evaluate(const double* in, double* out, const std::uint32_t* controller) {
  for (std::size_t cell = 0; cell < a_.states.size(); ++cell) {
    const CellRole role = a_.roles[cell];
    out[cell] = role == CellRole::Free ? std::min(input_value(cell, controller[cell], in), 1.0) : a_.terminal_value(role);
  }
}

}  // namespace amytiss::detail
