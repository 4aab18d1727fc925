// The paper's a-priori error epsilon = T * H * L(A) * delta (amytiss/apriori_error.hpp): every factor
// by hand on a 1-d linear Gaussian system, the density slope against sampled gradients, the
// Jacobian bound of a nonlinear map against finite differences, the laws without a Lipschitz
// density, and the figure for the shipped robot example (vacuous).
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <Eigen/SVD>

#include <chrono>
#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "amytiss/apriori_error.hpp"
#include "amytiss/config.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

constexpr std::uint64_t kSeed = 20261201;
// The bound carries a relative slack of a few 1e-12 for rounding; hand figures agree to this.
constexpr double kHandAgreement = 1e-9;
// Central differences of step kStep: truncation error ~ kStep^2 |f'''|, rounding ~ 1e-16 / kStep.
constexpr double kStep = 1e-5;
constexpr double kFiniteDifferenceError = 1e-7;
// The per-cell interval Jacobian of van der Pol's map over cells of 0.2 exceeds the sampled norms by
// at most this factor (the Jacobian moves by about 8 % across the outermost cell).
constexpr double kJacobianLooseness = 1.1;
constexpr int kSampledCells = 300;

double normal_density_slope_by_hand_1d(double variance) {
  return std::exp(-0.5) / (variance * std::sqrt(2 * M_PI));  // sup |phi'| = 1 / (sigma^2 sqrt(2 pi e))
}

std::string linear_1d_yaml(const std::string& extra = "") {
  return R"(
name: linear_1d
states: {lb: [-2], ub: [2], eta: [0.25]}
inputs: {lb: [-1], ub: [1], eta: [0.5]}
dynamics: ["0.9*x0 + 0.2*u0"]
noise: {distribution: normal, covariance: [1.0]}
spec: {type: safety, horizon: 2, safe: {lb: [-1.5], ub: [1.5]}}
)" + extra;
}

TEST(AprioriError, LinearGaussian1dEveryFactorByHand) {
  const Abstraction abstraction = test_support::from_yaml(linear_1d_yaml());
  const AprioriError error = apriori_error(abstraction);
  // Safety in [-1.5, 1.5]: cells -1.5 .. 1.5, 13 of them, 0.25 wide.
  const double slope = normal_density_slope_by_hand_1d(1.0);
  const double lipschitz = slope * 0.9;
  const double measure = 13 * 0.25;
  const double expected = 2 * lipschitz * measure * 0.25;
  EXPECT_NEAR(error.density_slope, slope, kHandAgreement * slope);
  EXPECT_NEAR(error.jacobian_norm, 0.9, kHandAgreement);
  EXPECT_NEAR(error.lipschitz, lipschitz, kHandAgreement * lipschitz);
  EXPECT_NEAR(error.measure, measure, kHandAgreement * measure);
  EXPECT_NEAR(error.delta, 0.25, kHandAgreement);
  EXPECT_EQ(error.horizon, 2.0);
  EXPECT_NEAR(error.epsilon, expected, kHandAgreement * expected);
  EXPECT_GE(error.epsilon, expected * (1 - 1e-15));  // rounded up, never below the real figure
  EXPECT_EQ(error.vacuous(), expected >= 1);
  EXPECT_EQ(error.explanation.find("infinite"), std::string::npos) << error.explanation;
  ASSERT_LT(error.epsilon, 1);  // 0.35 here: the line says so without "vacuous"
  EXPECT_EQ(describe_apriori_error(error).find("vacuous"), std::string::npos) << describe_apriori_error(error);
}

// sup over y of |grad N(y; 0, Sigma)|: the bound is attained (along the smallest variance's axis) and
// never below a sampled gradient.
TEST(AprioriError, DensitySlopeBoundsSampledGradients) {
  for (const std::string covariance : {"[0.04, 0.25]", "[0.09, 0.02, 0.02, 0.04]"}) {
    const Abstraction abstraction = test_support::from_yaml(R"(
name: slope
states: {lb: [-1, -1], ub: [1, 1], eta: [0.5, 0.5]}
dynamics: ["x0", "x1"]
noise: {distribution: normal, covariance: )" + covariance + R"(}
spec: {type: safety, horizon: 1}
)");
    std::string why_not;
    const double slope = noise_density_slope(abstraction, &why_not);
    ASSERT_TRUE(why_not.empty()) << why_not;
    const std::vector<double>& c = abstraction.config.noise.covariance;
    Eigen::Matrix2d sigma;
    if (c.size() == 2) sigma << c[0], 0, 0, c[1];
    else sigma << c[0], c[1], c[2], c[3];
    const Eigen::Matrix2d inverse = sigma.inverse();
    const double normalizer = 1 / (2 * M_PI * std::sqrt(sigma.determinant()));
    double largest = 0;
    for (double a = -1.5; a <= 1.5; a += 0.002)
      for (double b = -1.5; b <= 1.5; b += 0.01) {
        const Eigen::Vector2d y(a, b);
        const double density = normalizer * std::exp(-0.5 * y.dot(inverse * y));
        largest = std::max(largest, (inverse * y).norm() * density);
      }
    EXPECT_GE(slope, largest) << covariance;
    EXPECT_LE(slope, largest * 1.001) << covariance;  // the grid of y comes within 0.1 % of the peak
  }
}

// f(x) by the abstraction's own dynamics (no input, no disturbance beyond `u`).
std::vector<double> post(const Abstraction& abstraction, std::vector<double> x, const std::vector<double>& u) {
  std::vector<double> out(x.size());
  abstraction.dynamics->evaluate(x.data(), u.data(), nullptr, out.data());
  return out;
}

// The spectral norm of df/dx at x by central differences.
double finite_difference_norm(const Abstraction& abstraction, const std::vector<double>& x,
                              const std::vector<double>& u) {
  const std::size_t n = x.size();
  Eigen::MatrixXd jacobian(n, n);
  for (std::size_t j = 0; j < n; ++j) {
    std::vector<double> up = x, down = x;
    up[j] += kStep;
    down[j] -= kStep;
    const std::vector<double> f_up = post(abstraction, up, u), f_down = post(abstraction, down, u);
    for (std::size_t i = 0; i < n; ++i)
      jacobian(Eigen::Index(i), Eigen::Index(j)) = (f_up[i] - f_down[i]) / (2 * kStep);
  }
  return Eigen::JacobiSVD<Eigen::MatrixXd>(jacobian).singularValues()(0);
}

TEST(AprioriError, NonlinearJacobianBoundsFiniteDifferences) {
  const Abstraction abstraction =
      Abstraction::from_config(load_config_file(std::string(AMYTISS_SOURCE_DIR) + "/config/arch_van_der_pol.yaml"));
  const AprioriError error = apriori_error(abstraction);
  ASSERT_TRUE(std::isfinite(error.jacobian_norm)) << error.explanation;
  std::mt19937_64 random(kSeed);
  std::uniform_int_distribution<std::size_t> pick_cell(0, abstraction.states.size() - 1);
  std::uniform_int_distribution<std::size_t> pick_input(0, abstraction.inputs.size() - 1);
  std::uniform_real_distribution<double> offset(-0.5, 0.5);
  double largest = 0;
  auto sample = [&](const std::vector<double>& x) {
    const double norm = finite_difference_norm(abstraction, x, abstraction.inputs.point(pick_input(random)));
    EXPECT_GE(error.jacobian_norm, norm - kFiniteDifferenceError) << "x = " << x[0] << ", " << x[1];
    largest = std::max(largest, norm);
  };
  for (int drawn = 0; drawn < kSampledCells; ++drawn) {
    const std::size_t cell = pick_cell(random);
    if (abstraction.roles[cell] != CellRole::Free) continue;
    std::vector<double> x = abstraction.states.point(cell);
    for (std::size_t j = 0; j < x.size(); ++j) x[j] += offset(random) * abstraction.states.eta()[j];
    sample(x);
  }
  // The corners of the covered box, where |df/dx| is largest (their cells are Free).
  const double edge = 5 + 0.5 * 0.2;
  for (double a : {-edge, edge})
    for (double b : {-edge, edge}) sample({a, b});
  EXPECT_LE(error.jacobian_norm, kJacobianLooseness * largest);
  EXPECT_EQ(error.cells_per_box, 1u);
  // Fewer Jacobians over boxes of several cells: sound (never below the per-cell bound), looser.
  const std::size_t per_cell_jacobians = abstraction.states.size() * abstraction.inputs.size();
  const AprioriError coarse = apriori_error(abstraction, per_cell_jacobians / 10);
  EXPECT_GE(coarse.cells_per_box, 10u);
  EXPECT_GE(coarse.jacobian_norm, error.jacobian_norm);
  EXPECT_GE(coarse.epsilon, error.epsilon);
  EXPECT_NE(coarse.explanation.find("over boxes of"), std::string::npos) << coarse.explanation;
  std::cout << "van der Pol: |df/dx| <= " << error.jacobian_norm << " (sampled max " << largest
            << "), epsilon " << error.epsilon << "\n";
}

TEST(AprioriError, RobotReachAvoidIsVacuous) {
  const auto start = std::chrono::steady_clock::now();
  const Abstraction abstraction =
      Abstraction::from_config(load_config_file(std::string(AMYTISS_SOURCE_DIR) + "/config/robot_reach_avoid.yaml"));
  const AprioriError error = apriori_error(abstraction);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The map is x + (a function of the input): df/dx is the identity.
  EXPECT_NEAR(error.jacobian_norm, 1.0, kHandAgreement);
  // 1,681 cells less the 81 avoid cells, 0.25 m^2 each; delta the cell's diagonal.
  EXPECT_NEAR(error.measure, 1600 * 0.25, kHandAgreement * 400);
  EXPECT_NEAR(error.delta, std::sqrt(0.5), kHandAgreement);
  const double slope = std::exp(-0.5) / (std::sqrt(0.75) * 2 * M_PI * 0.75);
  EXPECT_NEAR(error.epsilon, 16 * slope * 400 * std::sqrt(0.5), kHandAgreement * error.epsilon);
  EXPECT_TRUE(error.vacuous());
  const std::string line = describe_apriori_error(error);
  EXPECT_EQ(line.rfind("a-priori error of the abstraction (paper's bound): 6.7e+02, vacuous: T 16 x H ", 0), 0u)
      << line;
  std::cout << "robot_reach_avoid: epsilon " << error.epsilon << " (" << error.explanation << ") in " << seconds
            << " s\n";
}

TEST(AprioriError, DensitiesWithoutLipschitzBoundAreInfinite) {
  struct Case {
    std::string noise, reason;
  };
  for (const Case& c : std::vector<Case>{
           {"{distribution: uniform, half_width: [0.3]}", "uniform"},
           {"{distribution: exponential, rate: [2]}", "exponential"},
           {"{distribution: beta, alpha: [2], beta: [3], support: {lb: [-0.5], ub: [0.5]}}", "beta"},
           {"{distribution: normal, covariance: [0]}", "variance of 0"},
           {"{type: multiplicative, distribution: normal, covariance: [0.01]}", "multiplicative"}}) {
    std::string yaml = linear_1d_yaml();
    yaml.replace(yaml.find("noise: {distribution: normal, covariance: [1.0]}"),
                 std::string("noise: {distribution: normal, covariance: [1.0]}").size(), "noise: " + c.noise);
    const AprioriError error = apriori_error(test_support::from_yaml(yaml));
    EXPECT_TRUE(std::isinf(error.epsilon)) << c.noise;
    EXPECT_TRUE(error.vacuous());
    EXPECT_NE(error.explanation.find(c.reason), std::string::npos) << error.explanation;
  }
}

TEST(AprioriError, JumpsInsideACellAndUnboundedHorizonAreInfinite) {
  std::string jumps = linear_1d_yaml();
  jumps.replace(jumps.find("0.9*x0 + 0.2*u0"), std::string("0.9*x0 + 0.2*u0").size(), "0.9*floor(x0) + 0.2*u0");
  const AprioriError jump = apriori_error(test_support::from_yaml(jumps));
  EXPECT_TRUE(std::isinf(jump.jacobian_norm));
  EXPECT_TRUE(std::isinf(jump.epsilon));
  EXPECT_NE(jump.explanation.find("jump"), std::string::npos) << jump.explanation;

  std::string unbounded = linear_1d_yaml();
  unbounded.replace(unbounded.find("horizon: 2"), std::string("horizon: 2").size(), "horizon: infinite");
  const AprioriError forever = apriori_error(test_support::from_yaml(unbounded));
  EXPECT_TRUE(std::isfinite(forever.lipschitz));
  EXPECT_TRUE(std::isinf(forever.epsilon));
  EXPECT_NE(forever.explanation.find("horizon is infinite"), std::string::npos) << forever.explanation;
}

}  // namespace
}  // namespace amytiss
