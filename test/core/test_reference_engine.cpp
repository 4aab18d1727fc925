#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "monte_carlo.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using namespace test_support;

constexpr double kClosedFormTolerance = 1e-9;
constexpr double kBruteForceTolerance = 1e-12;
constexpr double kMonteCarloStandardErrors = 4.0;

// Gaussian mass of [lo, hi] with erf, written independently of NoiseModel.
double erf_mass(double lo, double hi, double mean, double sigma) {
  return 0.5 * (std::erf((hi - mean) / (sigma * std::sqrt(2.0))) - std::erf((lo - mean) / (sigma * std::sqrt(2.0))));
}

// ---------------------------------------------------------------------------------------------
// Closed form: x+ = x + u + noise on X = [-2, 2] eta 1, U = {-1, 0, 1}, sigma 0.5, no truncation.

Abstraction random_walk(unsigned horizon) {
  auto dynamics = std::make_shared<LambdaDynamics>(
      1, 1, 0, [](const double* x, const double* u, const double*, double* post) { post[0] = x[0] + u[0]; },
      "post[0] = x[0] + u[0];");
  return make_abstraction(make_config(grid_spec({-2}, {2}, {1}), grid_spec({-1}, {1}, {1}), std::nullopt,
                                      normal_noise({0.25}), safety_spec(horizon), "random walk"),
                          dynamics);
}

TEST(ReferenceEngine, RandomWalkOneStepClosedForm) {
  const Policy policy = synthesize_reference(random_walk(1), nullptr);
  for (int k = 0; k < 5; ++k) {
    const double x = -2.0 + k;
    double best = -1;
    int best_u = 0;
    for (int u = -1; u <= 1; ++u) {
      const double stay = erf_mass(-2.5, 2.5, x + u, 0.5);
      if (stay > best) best = stay, best_u = u;
    }
    EXPECT_NEAR(policy.value(0, std::size_t(k)), best, kClosedFormTolerance) << "x = " << x;
    EXPECT_EQ(int(policy.input(0, std::size_t(k))) - 1, best_u) << "x = " << x;
    EXPECT_EQ(policy.value(1, std::size_t(k)), 1.0);
  }
}

TEST(ReferenceEngine, RandomWalkTwoStepsExplicitSum) {
  const Policy policy = synthesize_reference(random_walk(2), nullptr);
  auto one_step = [](double x) {
    double best = 0;
    for (int u = -1; u <= 1; ++u) best = std::max(best, erf_mass(-2.5, 2.5, x + u, 0.5));
    return best;
  };
  for (int k = 0; k < 5; ++k) {
    const double x = -2.0 + k;
    double best = -1;
    for (int u = -1; u <= 1; ++u) {
      double sum = 0;
      for (int j = 0; j < 5; ++j) {
        const double next = -2.0 + j;
        sum += erf_mass(next - 0.5, next + 0.5, x + u, 0.5) * one_step(next);
      }
      best = std::max(best, sum);
    }
    EXPECT_NEAR(policy.value(0, std::size_t(k)), best, kClosedFormTolerance) << "x = " << x;
    EXPECT_NEAR(policy.value(1, std::size_t(k)), one_step(x), kClosedFormTolerance);
  }
}

// ---------------------------------------------------------------------------------------------
// Brute force over every deterministic Markov policy.

// transitions[(x * U + u) * W + w][x'] for all cells.
using TransitionTable = std::vector<std::vector<double>>;

// Every row of the table, in (x, u, w) order: probability(target, mean, current point) per cell.
template <typename Probability>
TransitionTable transition_table(const Abstraction& abstraction, const Probability& probability) {
  const Grid& states = abstraction.states;
  TransitionTable table;
  std::vector<double> mean(states.dims());
  for (std::size_t x = 0; x < states.size(); ++x)
    for (std::size_t u = 0; u < abstraction.inputs.size(); ++u)
      for (std::size_t w = 0; w < abstraction.disturbances.size(); ++w) {
        const auto point = states.point(x), input = abstraction.inputs.point(u),
                   disturbance = abstraction.disturbances.point(w);
        abstraction.dynamics->evaluate(point.data(), input.data(), disturbance.data(), mean.data());
        std::vector<double> row(states.size());
        for (std::size_t target = 0; target < states.size(); ++target)
          row[target] = probability(target, mean, point);
        table.push_back(row);
      }
  return table;
}

// Independent of the engine's loops: diagonal normal without truncation, erf products.
TransitionTable erf_transitions(const Abstraction& abstraction) {
  const Grid& states = abstraction.states;
  return transition_table(abstraction, [&](std::size_t target, const std::vector<double>& mean,
                                           const std::vector<double>&) {
    const auto center = states.point(target);
    double probability = 1;
    for (std::size_t d = 0; d < states.dims(); ++d) {
      const double eta = states.eta()[d];
      probability *= erf_mass(center[d] - eta / 2, center[d] + eta / 2, mean[d],
                              std::sqrt(abstraction.config.noise.covariance[d]));
    }
    return probability;
  });
}

// Through the noise model (full covariance, truncation): tests the recursion, not the masses.
TransitionTable model_transitions(const Abstraction& abstraction) {
  return transition_table(abstraction, [&](std::size_t target, const std::vector<double>& mean,
                                           const std::vector<double>& point) {
    return abstraction.noise->transition_probability(abstraction.states, target, mean.data(), point.data());
  });
}

// V^pi_0 of a Markov policy pi[step][free index] against the worst adversary per step.
std::vector<double> evaluate_policy(const Abstraction& abstraction, const TransitionTable& table,
                                    const std::vector<std::vector<std::size_t>>& pi,
                                    const std::vector<std::size_t>& free_cells) {
  const std::size_t S = abstraction.states.size(), U = abstraction.inputs.size(), W = abstraction.disturbances.size();
  std::vector<double> next(S);
  for (std::size_t x = 0; x < S; ++x) next[x] = abstraction.terminal_value(abstraction.roles[x]);
  for (unsigned step = abstraction.horizon; step-- > 0;) {
    std::vector<double> current = next;  // fixed cells keep their value
    for (std::size_t i = 0; i < free_cells.size(); ++i) {
      const std::size_t x = free_cells[i], u = pi[step][i];
      double worst = std::numeric_limits<double>::infinity();
      for (std::size_t w = 0; w < W; ++w) {
        double sum = 0;
        for (std::size_t target = 0; target < S; ++target) sum += table[(x * U + u) * W + w][target] * next[target];
        worst = std::min(worst, sum);
      }
      current[x] = worst;
    }
    next = current;
  }
  return next;
}

void expect_engine_matches_brute_force(const Abstraction& abstraction, const TransitionTable& table) {
  const Policy policy = synthesize_reference(abstraction, nullptr);
  std::vector<std::size_t> free_cells;
  for (std::size_t x = 0; x < abstraction.states.size(); ++x)
    if (abstraction.roles[x] == CellRole::Free) free_cells.push_back(x);
  const std::size_t U = abstraction.inputs.size(), T = abstraction.horizon, slots = free_cells.size() * T;
  ASSERT_LE(std::pow(double(U), double(slots)), 1e5) << "problem too large to enumerate";
  std::vector<double> best(abstraction.states.size(), -1.0);
  std::vector<std::size_t> digits(slots, 0);
  std::size_t policies = 0;
  while (true) {
    std::vector<std::vector<std::size_t>> pi(T, std::vector<std::size_t>(free_cells.size()));
    for (std::size_t slot = 0; slot < slots; ++slot) pi[slot / free_cells.size()][slot % free_cells.size()] = digits[slot];
    const auto values = evaluate_policy(abstraction, table, pi, free_cells);
    for (std::size_t x = 0; x < values.size(); ++x) best[x] = std::max(best[x], values[x]);
    ++policies;
    std::size_t slot = 0;
    while (slot < slots && ++digits[slot] == U) digits[slot++] = 0;
    if (slot == slots) break;
  }
  EXPECT_EQ(double(policies), std::pow(double(U), double(slots)));
  bool nontrivial = false;
  for (std::size_t x = 0; x < abstraction.states.size(); ++x) {
    EXPECT_NEAR(policy.value(0, x), best[x], kBruteForceTolerance) << "cell " << x;
    if (abstraction.roles[x] == CellRole::Free && best[x] > 1e-3 && best[x] < 1 - 1e-3) nontrivial = true;
  }
  EXPECT_TRUE(nontrivial) << "the test problem should have probabilities strictly inside (0, 1)";
  // The engine's own policy achieves its values.
  std::vector<std::vector<std::size_t>> engine_pi(T, std::vector<std::size_t>(free_cells.size()));
  for (std::size_t step = 0; step < T; ++step)
    for (std::size_t i = 0; i < free_cells.size(); ++i) engine_pi[step][i] = policy.input(unsigned(step), free_cells[i]);
  const auto achieved = evaluate_policy(abstraction, table, engine_pi, free_cells);
  for (std::size_t x = 0; x < achieved.size(); ++x) EXPECT_NEAR(achieved[x], policy.value(0, x), kBruteForceTolerance);
}

TEST(ReferenceEngineBruteForce, SafetyOneDimensionThreeInputs) {
  auto dynamics = std::make_shared<LambdaDynamics>(1, 1, 0, [](const double* x, const double* u, const double*, double* post) {
    post[0] = 0.5 * x[0] + u[0] + 0.3 * std::sin(3 * x[0]);
  });
  const Abstraction abstraction = make_abstraction(
      make_config(grid_spec({0}, {3}, {1}), grid_spec({-0.5}, {1.5}, {1}), std::nullopt, normal_noise({0.36}),
                  safety_spec(2, box({0}, {2})), "safety 1d"),
      dynamics);
  ASSERT_EQ(abstraction.roles[3], CellRole::FixedZero);
  expect_engine_matches_brute_force(abstraction, erf_transitions(abstraction));
}

TEST(ReferenceEngineBruteForce, SafetyTwoDimensionsWithDisturbance) {
  auto dynamics = std::make_shared<LambdaDynamics>(2, 1, 1, [](const double* x, const double* u, const double* w, double* post) {
    post[0] = x[0] + u[0] + w[0];
    post[1] = 0.8 * x[1] - 0.5 * u[0] + 0.4 * x[0] * w[0];
  });
  const Abstraction abstraction = make_abstraction(
      make_config(grid_spec({0, 0}, {1, 1}, {1, 1}), grid_spec({-0.5}, {0.5}, {1}), grid_spec({-0.3}, {0.3}, {0.6}),
                  normal_noise({0.2, 0.3}), safety_spec(2), "safety 2d w"),
      dynamics);
  expect_engine_matches_brute_force(abstraction, erf_transitions(abstraction));
}

TEST(ReferenceEngineBruteForce, ReachAvoidTwoDimensionsWithDisturbance) {
  auto dynamics = std::make_shared<LambdaDynamics>(2, 1, 1, [](const double* x, const double* u, const double* w, double* post) {
    post[0] = x[0] + u[0] * std::cos(x[1]) + 0.5 * w[0];
    post[1] = 0.7 * x[1] + u[0] * w[0] + 0.2;
  });
  const Abstraction abstraction = make_abstraction(
      make_config(grid_spec({0, 0}, {2, 1}, {1, 1}), grid_spec({-1}, {1}, {2}), grid_spec({-0.4}, {0.4}, {0.8}),
                  normal_noise({0.3, 0.25}), reach_avoid_spec(3, box({2, 1}, {2, 1}), box({1, 0}, {1, 0})), "ra 2d w"),
      dynamics);
  ASSERT_EQ(std::count(abstraction.roles.begin(), abstraction.roles.end(), CellRole::Free), 4);
  expect_engine_matches_brute_force(abstraction, erf_transitions(abstraction));
}

TEST(ReferenceEngineBruteForce, ReachAvoidOneDimensionThreeInputs) {
  auto dynamics = std::make_shared<LambdaDynamics>(1, 1, 0, [](const double* x, const double* u, const double*, double* post) {
    post[0] = x[0] + u[0] - 0.1 * x[0] * x[0];
  });
  const Abstraction abstraction = make_abstraction(
      make_config(grid_spec({0}, {3}, {1}), grid_spec({-1}, {1}, {1}), std::nullopt, normal_noise({0.5}),
                  reach_avoid_spec(3, box({3}, {3}), box({0}, {0})), "ra 1d"),
      dynamics);
  expect_engine_matches_brute_force(abstraction, erf_transitions(abstraction));
}

TEST(ReferenceEngineBruteForce, FullCovarianceAndCuttingProbability) {
  auto dynamics = std::make_shared<LambdaDynamics>(2, 1, 0, [](const double* x, const double* u, const double*, double* post) {
    post[0] = 0.9 * x[0] + u[0];
    post[1] = 0.5 * x[1] + 0.5 * x[0] - u[0];
  });
  const Abstraction full = make_abstraction(
      make_config(grid_spec({0, 0}, {1, 1}, {1, 0.5}), grid_spec({-0.5}, {0.5}, {1}), std::nullopt,
                  normal_noise({0.09, 0.05, 0.05, 0.09}), safety_spec(2), "full covariance"),
      dynamics);
  ASSERT_FALSE(full.noise->separable());
  expect_engine_matches_brute_force(full, model_transitions(full));
  const Abstraction cut = make_abstraction(
      make_config(grid_spec({0, 0}, {1.5, 1.5}, {0.5, 0.5}), grid_spec({-0.5}, {0.5}, {1}), std::nullopt,
                  normal_noise({0.01, 0.01}, Truncation::CuttingProbability, 0.1), safety_spec(1), "cut"),
      dynamics);
  ASSERT_LT(cut.noise->window_cells(), cut.states.size());
  expect_engine_matches_brute_force(cut, model_transitions(cut));
}

// ---------------------------------------------------------------------------------------------
// Monte Carlo: the abstract MDP under the computed policy, adversary playing its worst case.

TEST(ReferenceEngineMonteCarlo, SuccessRateMatchesValue) {
  auto dynamics = std::make_shared<LambdaDynamics>(2, 2, 1, [](const double* x, const double* u, const double* w, double* post) {
    post[0] = x[0] + 1.5 * u[0] * std::cos(u[1]) + 0.3 * w[0];
    post[1] = x[1] + 1.5 * u[0] * std::sin(u[1]) + 0.3 * w[0];
  });
  const Abstraction abstraction = make_abstraction(
      make_config(grid_spec({-3, -3}, {3, 3}, {0.5, 0.5}), grid_spec({0, -1.5}, {1, 1.5}, {0.5, 0.75}),
                  grid_spec({-1}, {1}, {2}), normal_noise({0.2, 0.2}, Truncation::CuttingProbability, 1e-2),
                  reach_avoid_spec(6, box({1.5, 1.5}, {2.5, 2.5}), box({-0.5, -0.5}, {0.5, 0.5})), "monte carlo"),
      dynamics);
  const Policy policy = synthesize_reference(abstraction, nullptr);
  const Grid& states = abstraction.states;
  AbstractMdpSimulator simulator(abstraction, policy);
  std::mt19937_64 generator(42);
  constexpr int kRuns = 20000;
  const std::vector<std::vector<double>> starts{{-2.5, -2.5}, {-2.5, 2.0}, {0.0, 2.0}, {2.5, -1.0}};
  int checked_nontrivial = 0;
  for (const auto& start : starts) {
    const std::size_t start_cell = *states.cell_of(start.data());
    ASSERT_EQ(abstraction.roles[start_cell], CellRole::Free);
    const double predicted = policy.value(0, start_cell);
    const double rate = simulator.success_rate(start_cell, kRuns, generator);
    const double standard_error = std::sqrt(std::max(predicted * (1 - predicted), 1e-4) / kRuns);
    EXPECT_NEAR(rate, predicted, kMonteCarloStandardErrors * standard_error)
        << "start (" << start[0] << ", " << start[1] << ")";
    std::printf("monte carlo from (%g, %g): V_0 = %.4f, success rate %.4f over %d runs (4 SE = %.4f)\n", start[0],
                start[1], predicted, rate, kRuns, kMonteCarloStandardErrors * standard_error);
    if (predicted > 0.05 && predicted < 0.95) ++checked_nontrivial;
  }
  EXPECT_GE(checked_nontrivial, 2) << "the Monte Carlo check needs starts with non-trivial probabilities";
}

// ---------------------------------------------------------------------------------------------

TEST(ReferenceEngine, TiesKeepLowestInputAndFixedCellsKeepInputZero) {
  // The input has no effect: every input ties, so the lowest index must be chosen.
  auto dynamics = std::make_shared<LambdaDynamics>(1, 1, 0, [](const double* x, const double*, const double*, double* post) {
    post[0] = x[0];
  });
  const Abstraction abstraction = make_abstraction(
      make_config(grid_spec({0}, {4}, {1}), grid_spec({-1}, {1}, {0.5}), std::nullopt, normal_noise({0.3}),
                  reach_avoid_spec(3, box({4}, {4}), box({0}, {0})), "ties"),
      dynamics);
  const Policy policy = synthesize_reference(abstraction, nullptr);
  for (unsigned step = 0; step < 3; ++step)
    for (std::size_t cell = 0; cell < 5; ++cell) EXPECT_EQ(policy.input(step, cell), 0u);
  for (unsigned step = 0; step <= 3; ++step) {
    EXPECT_EQ(policy.value(step, 0), 0.0);
    EXPECT_EQ(policy.value(step, 4), 1.0);
  }
  // Free cells: V_3 = 0 (reach), later steps grow with the remaining horizon.
  EXPECT_EQ(policy.value(3, 2), 0.0);
  EXPECT_GT(policy.value(0, 3), policy.value(1, 3));
  EXPECT_GT(policy.value(1, 3), policy.value(2, 3));
}

TEST(ReferenceEngine, AutonomousSystemClosedForm) {
  // StocHy CSB 1-d: x+ = 0.8 x + noise (variance 0.2), X [-0.5, 0.5] eta 1: two cells.
  auto dynamics = std::make_shared<LambdaDynamics>(1, 0, 0, [](const double* x, const double*, const double*, double* post) {
    post[0] = 0.8 * x[0];
  });
  const Abstraction abstraction = make_abstraction(
      make_config(grid_spec({-0.5}, {0.5}, {1}), std::nullopt, std::nullopt, normal_noise({0.2}), safety_spec(1),
                  "autonomous"),
      dynamics);
  ASSERT_EQ(abstraction.inputs.size(), 1u);
  const Policy policy = synthesize_reference(abstraction, nullptr);
  // Cells at -0.5 and 0.5 cover [-1, 1]; from x = 0.5 the mean is 0.4.
  EXPECT_NEAR(policy.value(0, 1), erf_mass(-1, 1, 0.4, std::sqrt(0.2)), kClosedFormTolerance);
  EXPECT_NEAR(policy.value(0, 0), erf_mass(-1, 1, -0.4, std::sqrt(0.2)), kClosedFormTolerance);
  EXPECT_EQ(policy.input(0, 0), 0u);
}

TEST(ReferenceEngine, ProgressReportAndCancel) {
  const Abstraction abstraction = random_walk(4);
  std::vector<unsigned> steps_seen;
  std::vector<Phase> phases_seen;
  SynthesisReport report;
  const Policy policy = synthesize_reference(
      abstraction,
      [&](const Progress& progress) {
        phases_seen.push_back(progress.phase);
        if (progress.phase == Phase::Synthesis || progress.phase == Phase::Done) {
          steps_seen.push_back(progress.steps_done);
          EXPECT_EQ(progress.steps_total, 4u);
          EXPECT_EQ(progress.device, "reference");
          EXPECT_GE(progress.remaining_s, 0.0);
        }
        return true;
      },
      &report);
  EXPECT_EQ(steps_seen, (std::vector<unsigned>{1, 2, 3, 4}));
  // Like every engine: set-up, then a step at a time, the last one reported as done.
  EXPECT_EQ(phases_seen, (std::vector<Phase>{Phase::Setup, Phase::Synthesis, Phase::Synthesis, Phase::Synthesis,
                                             Phase::Done}));
  EXPECT_EQ(report.device, "reference");
  ASSERT_EQ(report.phases.size(), 4u);
  EXPECT_EQ(report.phases[0].name, "step 3");
  // 5 states x 3 inputs, window = whole grid (5 cells): 75 multiply-adds per step.
  EXPECT_EQ(report.phases[0].multiply_adds, 75.0);
  EXPECT_GT(report.host_peak_bytes, 0u);
  EXPECT_EQ(policy.computed_by, "reference");
  EXPECT_EQ(policy.config_hash, config_hash(abstraction.config));
  EXPECT_EQ(policy.values.size(), 5u * 5u);
  EXPECT_EQ(policy.input_index.size(), 4u * 5u);

  int calls = 0;
  EXPECT_THROW(synthesize_reference(abstraction, [&](const Progress& progress) {
                 return progress.phase != Phase::Synthesis || ++calls < 2;
               }),
               Cancelled);
  EXPECT_EQ(calls, 2);
}

TEST(ReferenceEngine, ValuesAreProbabilities) {
  const Abstraction abstraction = random_affine_abstraction(
      99, 2, 1, true, reach_avoid_spec(4, box({0.5, 0.5}, {1, 1}), box({-1, -1}, {-0.5, -0.5})), 5);
  const Policy policy = synthesize_reference(abstraction, nullptr);
  for (double value : policy.values) {
    EXPECT_GE(value, 0.0);
    EXPECT_LE(value, 1.0 + 1e-12);
  }
  const ValueSummary summary = summarize_initial_values(policy);
  EXPECT_GT(summary.max, 0.0);
}

TEST(AbstractionRoles, SafeBoxTargetAvoidAndErrors) {
  const Grid grid(grid_spec({0, 0}, {3, 3}, {1, 1}));
  const auto safety = cell_roles(grid, safety_spec(1, box({0, 0}, {2, 3})));
  EXPECT_EQ(std::count(safety.begin(), safety.end(), CellRole::FixedZero), 4);  // x0 = 3
  const auto everything_safe = cell_roles(grid, safety_spec(1));
  EXPECT_EQ(std::count(everything_safe.begin(), everything_safe.end(), CellRole::Free), 16);
  // A cell in both target and avoid: avoid is applied first and wins.
  const auto reach_avoid = cell_roles(grid, reach_avoid_spec(1, box({2, 2}, {3, 3}), box({0, 0}, {2, 2})));
  EXPECT_EQ(reach_avoid[grid.flat_index(std::vector<std::size_t>{2, 2}.data())], CellRole::FixedZero);
  EXPECT_EQ(reach_avoid[grid.flat_index(std::vector<std::size_t>{3, 3}.data())], CellRole::FixedOne);
  EXPECT_EQ(std::count(reach_avoid.begin(), reach_avoid.end(), CellRole::FixedOne), 3);
  EXPECT_EQ(std::count(reach_avoid.begin(), reach_avoid.end(), CellRole::FixedZero), 9);
  SpecConfig missing_target = reach_avoid_spec(1, box({0, 0}, {1, 1}));
  missing_target.target.reset();
  // Config::validate() refuses these; downstream code asserts that it did.
  EXPECT_THROW(cell_roles(grid, missing_target), std::logic_error);
  EXPECT_THROW(cell_roles(grid, safety_spec(1, box({0}, {1}))), std::logic_error);

  auto dynamics = std::make_shared<LambdaDynamics>(1, 1, 0, [](const double* x, const double*, const double*, double* post) {
    post[0] = x[0];
  });
  Config config = make_config(grid_spec({0}, {1}, {1}), grid_spec({0}, {1}, {1}), std::nullopt, normal_noise({0.1}),
                              safety_spec(0));
  EXPECT_THROW(make_abstraction(config, dynamics), std::logic_error);  // horizon 0
  config.spec.horizon = 1;
  EXPECT_NO_THROW(make_abstraction(config, dynamics));
  config.inputs.reset();
  EXPECT_THROW(make_abstraction(config, dynamics), std::logic_error);  // dynamics expects one input
}

}  // namespace
}  // namespace amytiss
