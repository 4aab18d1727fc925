// The serial reference engine: the paper's Algorithms 1 + 3 written plainly, in double precision.
// It is the oracle the OpenCL engine is tested against, so clarity wins over speed here.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"

namespace amytiss {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// sum over the window cells of prod_d mass_d(k_d) * next_values(cell), one dimension at a time.
struct WindowSum {
  std::size_t dims;
  const std::int64_t* first;
  const std::int64_t* last;
  const std::vector<std::vector<double>>* masses;  // masses[d][k - first[d]]
  const std::size_t* strides;
  const double* next_values;
  double multiply_adds = 0;

  double sum(std::size_t dim, std::size_t offset, double probability) {
    const std::vector<double>& mass = (*masses)[dim];
    if (dim + 1 == dims) {
      // Innermost dimension: a plain dot product of its masses with the contiguous values.
      double dot = 0.0;
      for (std::int64_t k = first[dim]; k <= last[dim]; ++k)
        dot += mass[std::size_t(k - first[dim])] * next_values[offset + std::size_t(k)];
      multiply_adds += double(last[dim] - first[dim] + 1);
      return probability * dot;
    }
    double total = 0.0;
    for (std::int64_t k = first[dim]; k <= last[dim]; ++k) {
      const double cell_mass = mass[std::size_t(k - first[dim])];
      if (cell_mass == 0.0) continue;
      total += sum(dim + 1, offset + std::size_t(k) * strides[dim], probability * cell_mass);
    }
    return total;
  }
};

}  // namespace

Policy synthesize_reference(const Abstraction& abstraction, const ProgressCallback& progress,
                            SynthesisReport* report) {
  const auto start = Clock::now();
  const Grid& states = abstraction.states;
  const Grid& inputs = abstraction.inputs;
  const Grid& disturbances = abstraction.disturbances;
  const NoiseModel& noise = *abstraction.noise;
  const Dynamics& dynamics = *abstraction.dynamics;
  const std::size_t state_count = states.size();
  const std::size_t dims = states.dims();
  const unsigned horizon = abstraction.horizon;

  Policy policy;
  policy.states = states;
  policy.inputs = inputs;
  policy.horizon = horizon;
  policy.roles = abstraction.roles;
  policy.computed_by = "reference";
  policy.config_hash = config_hash(abstraction.config);
  policy.values.assign(std::size_t(horizon + 1) * state_count, 0.0);
  policy.input_index.assign(std::size_t(horizon) * state_count, 0);

  for (std::size_t cell = 0; cell < state_count; ++cell)
    policy.values[std::size_t(horizon) * state_count + cell] = abstraction.terminal_value(abstraction.roles[cell]);

  if (report) {
    report->device = "reference";
    report->transitions = "on_the_fly (the reference engine computes each transition when it needs it)";
    report->phases.clear();
  }
  if (progress) {
    Progress setup{Phase::Setup, 0, horizon, "reference", seconds_since(start), -1};
    if (!progress(setup)) throw Cancelled();
  }

  std::vector<std::size_t> strides(dims);
  {
    std::size_t stride = 1;
    for (std::size_t d = dims; d-- > 0;) {
      strides[d] = stride;
      stride *= states.count(d);
    }
  }
  std::vector<std::vector<double>> input_points(inputs.size()), disturbance_points(disturbances.size());
  for (std::size_t u = 0; u < inputs.size(); ++u) input_points[u] = inputs.point(u);
  for (std::size_t w = 0; w < disturbances.size(); ++w) disturbance_points[w] = disturbances.point(w);

  std::vector<double> x(dims), mean(dims);
  std::vector<std::int64_t> first(dims), last(dims);
  std::vector<std::vector<double>> masses(dims);
  std::vector<std::size_t> multi(dims);

  for (unsigned step = horizon; step-- > 0;) {
    const auto step_start = Clock::now();
    const double* next_values = &policy.values[std::size_t(step + 1) * state_count];
    double* values = &policy.values[std::size_t(step) * state_count];
    std::uint32_t* chosen = &policy.input_index[std::size_t(step) * state_count];
    WindowSum window_sum{dims, first.data(), last.data(), &masses, strides.data(), next_values};
    double multiply_adds = 0;

    for (std::size_t cell = 0; cell < state_count; ++cell) {
      const CellRole role = abstraction.roles[cell];
      if (role != CellRole::Free) {
        values[cell] = abstraction.terminal_value(role);
        chosen[cell] = 0;
        continue;
      }
      states.point(cell, x.data());
      double best_value = -1.0;
      std::uint32_t best_input = 0;
      for (std::size_t u = 0; u < inputs.size(); ++u) {
        double worst_value = std::numeric_limits<double>::infinity();
        for (std::size_t w = 0; w < disturbances.size(); ++w) {
          dynamics.evaluate(x.data(), input_points[u].data(), disturbance_points[w].data(), mean.data());
          double expected = 0.0;
          if (noise.window(states, mean.data(), first.data(), last.data())) {
            if (noise.separable()) {
              for (std::size_t d = 0; d < dims; ++d) {
                masses[d].resize(std::size_t(last[d] - first[d] + 1));
                noise.cell_masses(d, first[d], last[d], mean[d], noise.scale(d, x.data()), masses[d].data());
              }
              window_sum.multiply_adds = 0;
              expected = window_sum.sum(0, 0, 1.0);
              multiply_adds += window_sum.multiply_adds;
            } else {
              // Full covariance: the box mass of every cell of the window.
              for (std::size_t d = 0; d < dims; ++d) multi[d] = std::size_t(first[d]);
              while (true) {
                const std::size_t target = states.flat_index(multi.data());
                expected += noise.transition_probability(states, target, mean.data(), x.data()) * next_values[target];
                multiply_adds += 1;
                std::size_t d = dims;
                while (d-- > 0) {
                  if (std::int64_t(++multi[d]) <= last[d]) break;
                  multi[d] = std::size_t(first[d]);
                }
                if (d == std::size_t(-1)) break;
              }
            }
          }
          if (expected < worst_value) worst_value = expected;
        }
        // Strict '>': ties keep the lowest input index.
        if (worst_value > best_value) {
          best_value = worst_value;
          best_input = static_cast<std::uint32_t>(u);
        }
      }
      // A sum of exact masses is at most 1, but its double rounding may exceed 1 by an ulp or so;
      // the value is a probability (and the policy file holds it to [0, 1]).
      values[cell] = std::min(best_value, 1.0);
      chosen[cell] = best_input;
    }

    const double step_seconds = seconds_since(step_start);
    if (report) {
      PhaseReport phase;
      phase.name = "step " + std::to_string(step);
      phase.seconds = step_seconds;
      phase.pairs_per_second = step_seconds > 0 ? double(abstraction.pairs()) / step_seconds : 0.0;
      phase.multiply_adds = multiply_adds;
      report->phases.push_back(phase);
    }
    if (progress) {
      const unsigned done = horizon - step;
      const double elapsed = seconds_since(start);
      Progress update{Phase::Synthesis, done, horizon, "reference", elapsed,
                      elapsed / double(done) * double(horizon - done)};
      if (!progress(update)) throw Cancelled();
    }
  }

  if (report) report->host_peak_bytes = peak_resident_bytes();
  return policy;
}

std::size_t peak_resident_bytes() {
  std::FILE* status = std::fopen("/proc/self/status", "r");
  if (!status) return 0;
  char line[256];
  std::size_t bytes = 0;
  while (std::fgets(line, sizeof line, status)) {
    unsigned long long kilobytes = 0;
    if (std::sscanf(line, "VmHWM: %llu kB", &kilobytes) == 1) {
      bytes = std::size_t(kilobytes) * 1024;
      break;
    }
  }
  std::fclose(status);
  return bytes;
}

}  // namespace amytiss
