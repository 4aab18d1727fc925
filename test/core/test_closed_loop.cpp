// The ROS-free closed loop (closed_loop.hpp): a 1-d linear system under a hand-made controller
// against its success probability by independent quadrature, the step limit of stationary
// policies, determinism by seed, and the concrete plant's draws.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "amytiss/closed_loop.hpp"
#include "amytiss/config.hpp"
#include "amytiss/grid.hpp"
#include "amytiss/plant.hpp"
#include "amytiss/policy.hpp"

namespace amytiss {
namespace {

// The line: states [-2, 2] in cells of 0.5 (covered box [-2.25, 2.25]), x+ = 0.8 x + u + N(0, 0.3^2).
constexpr double kA = 0.8, kSigma = 0.3, kCoveredLo = -2.25, kCoveredHi = 2.25, kEta = 0.5, kLb = -2.0;
constexpr double kTargetLo = 1.0, kTargetHi = 1.6, kAvoidLo = -1.3, kAvoidHi = -0.7;
constexpr double kSafeLo = -1.6, kSafeHi = 1.4;
constexpr double kAim = 1.3;          // the step-0 controller steers towards it
constexpr std::size_t kStepOneInput = 3;  // u = 0.5 at step 1, everywhere
constexpr std::size_t kEpisodes = 20000;
constexpr double kStandardErrors = 4.0;
constexpr int kSimpsonIntervals = 200;  // per smooth piece

std::string line_yaml(const std::string& spec) {
  return "name: line\n"
         "states: {lb: [-2], ub: [2], eta: [0.5]}\n"
         "inputs: {lb: [-1], ub: [1], eta: [0.5]}\n"
         "dynamics: [\"0.8*x0 + u0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.09]}\n"
         "spec: " + spec + "\n";
}
const std::string kReachAvoid =
    "{type: reach_avoid, horizon: 2, target: {lb: [1.0], ub: [1.6]}, avoid: {lb: [-1.3], ub: [-0.7]}}";
const std::string kSafety = "{type: safety, horizon: 2, safe: {lb: [-1.6], ub: [1.4]}}";

// Step 0: the input nearest to kAim - 0.8 x (clipped to the grid); step 1: kStepOneInput.
Policy hand_policy(const Config& config) {
  Policy policy;
  policy.states = Grid(config.states);
  policy.inputs = Grid(*config.inputs);
  policy.horizon = 2;
  const std::size_t n = policy.states.size();
  policy.values.assign(3 * n, 0.0);
  policy.roles.assign(n, CellRole::Free);
  policy.input_index.resize(2 * n);
  for (std::size_t cell = 0; cell < n; ++cell) {
    const double wanted = kAim - kA * policy.states.point(cell)[0];
    const auto index = std::max<std::int64_t>(0, std::min<std::int64_t>(4, std::llround((wanted + 1.0) / 0.5)));
    policy.input_index[cell] = std::uint32_t(index);
    policy.input_index[n + cell] = std::uint32_t(kStepOneInput);
  }
  return policy;
}

double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }
double normal_density(double z) { return std::exp(-0.5 * z * z) / std::sqrt(2 * M_PI); }

// Composite Simpson over [lo, hi] split at `breaks` (the integrand is smooth between them).
double integrate(const std::function<double(double)>& f, double lo, double hi, std::vector<double> breaks) {
  breaks.push_back(lo);
  breaks.push_back(hi);
  std::sort(breaks.begin(), breaks.end());
  double total = 0;
  for (std::size_t k = 0; k + 1 < breaks.size(); ++k) {
    const double a = std::max(lo, breaks[k]), b = std::min(hi, breaks[k + 1]);
    if (b <= a) continue;
    const double h = (b - a) / kSimpsonIntervals;
    double sum = f(a) + f(b);
    for (int i = 1; i < kSimpsonIntervals; ++i) sum += f(a + i * h) * (i % 2 ? 4 : 2);
    total += sum * h / 3;
  }
  return total;
}

// The continuous success probability under hand_policy, computed from the sets' definitions alone
// (no simulator code): V_2 is the terminal indicator, V_1 a normal mass, V_0 a quadrature of V_1.
class LineTruth {
 public:
  LineTruth(const Policy& policy, bool safety) : policy_(policy), safety_(safety) {}

  // The probability from a start drawn uniformly in the cell of point `centre`.
  double from_cell(double centre) const {
    const double lo = centre - kEta / 2, hi = centre + kEta / 2;
    return integrate([&](double x) { return value0(x); }, lo, hi, set_faces()) / kEta;
  }

 private:
  double input(double x, unsigned step) const {
    const auto cell = std::size_t(std::floor((x - kLb) / kEta + 0.5));
    return policy_.inputs.point(policy_.input(step, cell))[0];
  }
  // Whether x decides the episode, and its value then.
  bool decided(double x, double& value) const {
    value = 0;
    if (x < kCoveredLo || x > kCoveredHi) return true;
    if (safety_) return x < kSafeLo || x > kSafeHi;
    if (kAvoidLo <= x && x <= kAvoidHi) return true;
    value = 1;
    return kTargetLo <= x && x <= kTargetHi;
  }
  // P(the next state lies where the terminal value is 1 | mean m).
  double terminal_mass(double m) const {
    const double lo = safety_ ? kSafeLo : kTargetLo, hi = safety_ ? kSafeHi : kTargetHi;
    return normal_cdf((hi - m) / kSigma) - normal_cdf((lo - m) / kSigma);
  }
  double value1(double y) const {
    double value;
    if (decided(y, value)) return value;
    return terminal_mass(kA * y + input(y, 1));
  }
  double value0(double x) const {
    double value;
    if (decided(x, value)) return value;
    const double m = kA * x + input(x, 0);
    std::vector<double> breaks = set_faces();
    for (int k = 0; k <= 9; ++k) breaks.push_back(kLb + (k - 0.5) * kEta);
    return integrate([&](double y) { return normal_density((y - m) / kSigma) / kSigma * value1(y); }, kCoveredLo,
                     kCoveredHi, breaks);
  }
  std::vector<double> set_faces() const {
    return safety_ ? std::vector<double>{kSafeLo, kSafeHi}
                   : std::vector<double>{kTargetLo, kTargetHi, kAvoidLo, kAvoidHi};
  }

  const Policy& policy_;
  bool safety_;
};

Config line_config(const std::string& spec) { return config_from_yaml(YAML::Load(line_yaml(spec))); }

// The cell whose point is `centre`.
std::size_t cell_at(const Grid& grid, double centre) { return *grid.cell_of(&centre); }

void expect_rate_near_truth(const std::string& spec, bool safety, double centre) {
  const Config config = line_config(spec);
  const Policy policy = hand_policy(config);
  const double truth = LineTruth(policy, safety).from_cell(centre);
  const ClosedLoop loop(config, policy);
  const SimulationResult result = simulate_cell(loop, cell_at(policy.states, centre), kEpisodes, 11);
  const double tolerance = kStandardErrors * std::sqrt(truth * (1 - truth) / kEpisodes);
  EXPECT_NEAR(result.rate(), truth, tolerance) << "cell of " << centre << ", " << spec;
  EXPECT_GT(truth, 0.02) << "a probability away from 0 and 1 tests the rate";
  EXPECT_LT(truth, 0.98);
}

TEST(ClosedLoop, ReachAvoidRateMatchesTheQuadratureOfTheContinuousSets) {
  expect_rate_near_truth(kReachAvoid, false, 0.0);
  // This cell reaches into the avoid set [-1.3, -0.7]: starts there fail at once.
  expect_rate_near_truth(kReachAvoid, false, -1.5);
}

TEST(ClosedLoop, SafetyRateMatchesTheQuadratureOfTheContinuousSets) {
  expect_rate_near_truth(kSafety, true, 0.0);
  // This cell straddles the safe set's face at 1.4.
  expect_rate_near_truth(kSafety, true, 1.5);
}

// The controller of step 1 matters: serving step 0's input at step 1 would give another rate.
TEST(ClosedLoop, ServesEachStepsOwnInput) {
  const Config config = line_config(kReachAvoid);
  Policy policy = hand_policy(config), same_steps = policy;
  const std::size_t n = policy.states.size();
  std::copy(policy.input_index.begin(), policy.input_index.begin() + n, same_steps.input_index.begin() + n);
  const double truth = LineTruth(policy, false).from_cell(0.0);
  const double other = LineTruth(same_steps, false).from_cell(0.0);
  const double tolerance = kStandardErrors * std::sqrt(truth * (1 - truth) / kEpisodes);
  ASSERT_GT(std::abs(truth - other), 3 * tolerance) << "the two controllers must be told apart";
  const SimulationResult result =
      simulate_cell(ClosedLoop(config, same_steps), cell_at(policy.states, 0.0), kEpisodes, 11);
  EXPECT_NEAR(result.rate(), other, tolerance);
}

TEST(ClosedLoop, SameSeedSameResultWhateverTheThreads) {
  const Config config = line_config(kReachAvoid);
  const Policy policy = hand_policy(config);
  const ClosedLoop loop(config, policy);
  const std::size_t cell = cell_at(policy.states, 0.0), episodes = 2000;
  const SimulationResult one = simulate_cell(loop, cell, episodes, 5, 1);
  const SimulationResult two = simulate_cell(loop, cell, episodes, 5, 2);
  const SimulationResult again = simulate_cell(loop, cell, episodes, 5, 3);
  EXPECT_EQ(one.successes, two.successes);
  EXPECT_EQ(one.ends, two.ends);
  EXPECT_EQ(one.ends, again.ends);
  const SimulationResult other = simulate_cell(loop, cell, episodes, 6, 2);
  EXPECT_NE(one.ends, other.ends) << "another seed draws other episodes";
  std::size_t total = 0;
  for (std::size_t count : one.ends) total += count;
  EXPECT_EQ(total, episodes);
}

TEST(ClosedLoop, RefusesNoEpisodesTooManyAndCellsOffTheGrid) {
  const Config config = line_config(kReachAvoid);
  const Policy policy = hand_policy(config);
  const ClosedLoop loop(config, policy);
  EXPECT_THROW(simulate_cell(loop, 0, 0, 1), std::invalid_argument);
  EXPECT_THROW(simulate_cell(loop, 0, kMaxSimulatedEpisodes + 1, 1), std::invalid_argument);
  EXPECT_THROW(simulate_cell(loop, policy.states.size(), 1, 1), std::invalid_argument);
}

// x+ = 0.5 x + U(-0.1, 0.1) never leaves [-2, 2] nor reaches [1.9, 2]: every episode of a
// stationary policy runs to the step limit, a success for safety and a failure for reachability.
TEST(ClosedLoop, StationaryEpisodesEndAtTheStepLimit) {
  constexpr unsigned kLimit = 40;
  const std::string base =
      "name: contraction\nstates: {lb: [-2], ub: [2], eta: [0.5]}\ndynamics: [\"0.5*x0\"]\n"
      "noise: {type: additive, distribution: uniform, half_width: [0.1]}\n";
  for (const bool safety : {true, false}) {
    const Config config = config_from_yaml(YAML::Load(
        base + (safety ? "spec: {type: safety, horizon: infinite}\n"
                       : "spec: {type: reachability, horizon: infinite, target: {lb: [1.9], ub: [2]}}\n")));
    Policy policy;
    policy.states = Grid(config.states);
    policy.horizon = 1;
    policy.stationary = true;
    policy.values.assign(2 * policy.states.size(), 0.0);
    policy.input_index.assign(policy.states.size(), 0);
    policy.roles.assign(policy.states.size(), CellRole::Free);
    const SimulationResult result =
        simulate_cell(ClosedLoop(config, policy, DisturbanceDraw::GridPoints, kLimit), cell_at(policy.states, 0.5),
                      50, 3);
    EXPECT_EQ(result.ended(EpisodeEnd::StepLimit), 50u);
    EXPECT_EQ(result.successes, safety ? 50u : 0u);
    std::mt19937_64 random(1);
    EXPECT_EQ(ClosedLoop(config, policy, DisturbanceDraw::GridPoints, kLimit).run({0.5}, random).steps, kLimit);
  }
}

// The grid-point draw takes only the disturbance grid's points, each of them; the box draw any value.
TEST(Plant, DrawsDisturbancesFromTheGridPointsOrTheBox) {
  const Config config = config_from_yaml(YAML::Load(
      "name: disturbed\nstates: {lb: [-5], ub: [5], eta: [1]}\ndisturbances: {lb: [-1], ub: [1], eta: [1]}\n"
      "dynamics: [\"x0 + w0\"]\nnoise: {type: additive, distribution: normal, covariance: [0.0]}\n"
      "spec: {type: safety, horizon: 3}\n"));
  std::mt19937_64 random(2);
  std::vector<int> seen(3, 0);
  const Plant grid_points(config, DisturbanceDraw::GridPoints), box(config, DisturbanceDraw::Box);
  bool off_grid = false;
  for (int k = 0; k < 300; ++k) {
    const double w = grid_points.step(std::vector<double>{0.0}, {}, random)[0];
    ASSERT_TRUE(w == -1.0 || w == 0.0 || w == 1.0) << w;
    seen[std::size_t(w + 1)] += 1;
    const double v = box.step(std::vector<double>{0.0}, {}, random)[0];
    ASSERT_TRUE(v >= -1.0 && v <= 1.0) << v;
    off_grid = off_grid || (v != -1.0 && v != 0.0 && v != 1.0);
  }
  for (int count : seen) EXPECT_GT(count, 50);
  EXPECT_TRUE(off_grid);
}

}  // namespace
}  // namespace amytiss
