#pragma once
// Monte Carlo runs of the abstract MDP under a synthesized policy: the policy's input, the
// disturbance playing its worst case for V_{step+1}, the next cell drawn from the transition row
// (the row's missing mass, off the grid or cut, is failure). Tests compare the success rate with V_0.
#include <cstddef>
#include <limits>
#include <random>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"

namespace amytiss {
namespace test_support {

class AbstractMdpSimulator {
 public:
  AbstractMdpSimulator(const Abstraction& abstraction, const Policy& policy)
      : a_(abstraction), policy_(policy), rows_(std::size_t(policy.horizon) * abstraction.states.size()) {}

  /// Fraction of `runs` runs from `start_cell` that reach a FixedOne cell before a FixedZero cell,
  /// the sink or the horizon (for safety, that stay in Free cells up to the horizon).
  double success_rate(std::size_t start_cell, int runs, std::mt19937_64& generator) {
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const std::size_t n = a_.states.size();
    int successes = 0;
    for (int run = 0; run < runs; ++run) {
      std::size_t cell = start_cell;
      bool success = a_.spec == SpecType::Safety;
      for (unsigned step = 0; step < policy_.horizon; ++step) {
        const std::vector<double>& row = worst_row(cell, step);
        double draw = uniform(generator), cumulative = 0;
        std::size_t next = n;
        for (std::size_t target = 0; target < n && next == n; ++target) {
          cumulative += row[target];
          if (draw < cumulative) next = target;
        }
        if (next == n) {
          success = false;
          break;
        }
        cell = next;
        if (a_.roles[cell] == CellRole::FixedOne) {
          success = true;
          break;
        }
        if (a_.roles[cell] == CellRole::FixedZero) {
          success = false;
          break;
        }
      }
      successes += success;
    }
    return double(successes) / runs;
  }

 private:
  // The row of the policy's input under the disturbance that minimizes the expected V_{step+1}.
  const std::vector<double>& worst_row(std::size_t cell, unsigned step) {
    std::vector<double>& cached = rows_[std::size_t(step) * a_.states.size() + cell];
    if (!cached.empty()) return cached;
    const auto x = a_.states.point(cell), u = a_.inputs.point(policy_.input(step, cell));
    double worst = std::numeric_limits<double>::infinity();
    std::vector<double> mean(a_.states.dims()), row(a_.states.size());
    for (std::size_t w = 0; w < a_.disturbances.size(); ++w) {
      const auto disturbance = a_.disturbances.point(w);
      a_.dynamics->evaluate(x.data(), u.data(), disturbance.data(), mean.data());
      double expected = 0;
      for (std::size_t target = 0; target < a_.states.size(); ++target) {
        row[target] = a_.noise->transition_probability(a_.states, target, mean.data(), x.data());
        expected += row[target] * policy_.value(step + 1, target);
      }
      if (expected < worst) worst = expected, cached = row;
    }
    return cached;
  }

  const Abstraction& a_;
  const Policy& policy_;
  std::vector<std::vector<double>> rows_;
};

}  // namespace test_support
}  // namespace amytiss
