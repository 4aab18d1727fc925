#pragma once
// Agreement of a policy with the reference engine's: values, and chosen inputs up to ties (a
// differing input is fine when the reference values both choices equally, within a margin).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"

namespace amytiss {
namespace test_support {

// Expected next value of (state, input) under V_{step+1} of `policy`, min over disturbances,
// evaluated directly in double from the noise model (independent of both engines' loops).
inline double input_value(const Abstraction& a, const Policy& policy, unsigned step, std::size_t state,
                   std::size_t input) {
  const std::size_t dims = a.states.dims();
  const std::vector<double> x = a.states.point(state), u = a.inputs.point(input);
  const double* next = &policy.values[std::size_t(step + 1) * a.states.size()];
  double worst = std::numeric_limits<double>::infinity();
  for (std::size_t w = 0; w < a.disturbances.size(); ++w) {
    const std::vector<double> disturbance = a.disturbances.point(w);
    std::vector<double> mean(dims);
    a.dynamics->evaluate(x.data(), u.data(), disturbance.data(), mean.data());
    std::vector<std::int64_t> first(dims), last(dims);
    double expected = 0.0;
    if (a.noise->window(a.states, mean.data(), first.data(), last.data())) {
      std::vector<std::size_t> multi(dims);
      for (std::size_t d = 0; d < dims; ++d) multi[d] = std::size_t(first[d]);
      while (true) {
        double probability = 1.0;
        for (std::size_t d = 0; d < dims; ++d)
          probability *= a.noise->cell_mass(d, multi[d], mean[d], a.noise->scale(d, x.data()));
        expected += probability * next[a.states.flat_index(multi.data())];
        std::size_t d = dims;
        while (d-- > 0) {
          if (std::int64_t(++multi[d]) <= last[d]) break;
          multi[d] = std::size_t(first[d]);
        }
        if (d == std::size_t(-1)) break;
      }
    }
    worst = std::min(worst, expected);
  }
  return worst;
}

struct Agreement {
  double max_value_difference = 0;
  std::size_t input_mismatches = 0;       // cells whose chosen inputs differ
  double max_mismatch_margin = 0;         // largest q(reference input) - q(opencl input) there
};

inline Agreement compare(const Abstraction& a, const Policy& reference, const Policy& opencl) {
  Agreement result;
  EXPECT_EQ(reference.values.size(), opencl.values.size());
  EXPECT_EQ(reference.input_index.size(), opencl.input_index.size());
  for (std::size_t i = 0; i < reference.values.size(); ++i)
    result.max_value_difference =
        std::max(result.max_value_difference, std::fabs(reference.values[i] - opencl.values[i]));
  for (unsigned step = 0; step < a.horizon; ++step)
    for (std::size_t cell = 0; cell < a.states.size(); ++cell) {
      const auto chosen_reference = reference.input(step, cell), chosen_opencl = opencl.input(step, cell);
      if (chosen_reference == chosen_opencl) continue;
      ++result.input_mismatches;
      const double margin = input_value(a, reference, step, cell, chosen_reference) -
                            input_value(a, reference, step, cell, chosen_opencl);
      result.max_mismatch_margin = std::max(result.max_mismatch_margin, margin);
    }
  return result;
}

}  // namespace test_support
}  // namespace amytiss
