#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include <gtest/gtest.h>

#include "amytiss/errors.hpp"
#include "amytiss/noise.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using test_support::grid_spec;
using test_support::normal_noise;
using test_support::uniform_noise;

constexpr double kQuadratureTolerance = 1e-12;     // absolute, 1-d cell masses vs quadrature
constexpr double kTailRelativeTolerance = 1e-9;    // relative, masses far in the tails
constexpr double kRowSumSlack = 1e-6;              // rows sum to at most 1 + 1e-6 (docs/engine.md, precision)
constexpr double kRoundingSlack = 1e-12;
constexpr double kQuantileRelativeTolerance = 1e-12;

double normal_pdf(double x, double mean, double sigma) {
  const double z = (x - mean) / sigma;
  return std::exp(-0.5 * z * z) / (sigma * std::sqrt(2.0 * M_PI));
}

// Adaptive Simpson with an absolute error target; independent of the erfc formulas under test.
double adaptive_simpson(const std::function<double(double)>& f, double a, double b, double tolerance,
                        int depth = 30) {
  std::function<double(double, double, double, double, double, double, double, int)> recurse =
      [&](double lo, double hi, double f_lo, double f_mid, double f_hi, double whole, double eps, int level) {
        const double mid = 0.5 * (lo + hi);
        const double left_mid = 0.5 * (lo + mid), right_mid = 0.5 * (mid + hi);
        const double f_left = f(left_mid), f_right = f(right_mid);
        const double left = (mid - lo) / 6.0 * (f_lo + 4.0 * f_left + f_mid);
        const double right = (hi - mid) / 6.0 * (f_mid + 4.0 * f_right + f_hi);
        const double difference = left + right - whole;
        if (level <= 0 || std::fabs(difference) <= 15.0 * eps) return left + right + difference / 15.0;
        return recurse(lo, mid, f_lo, f_left, f_mid, left, 0.5 * eps, level - 1) +
               recurse(mid, hi, f_mid, f_right, f_hi, right, 0.5 * eps, level - 1);
      };
  // Split into pieces so a narrow peak inside a wide interval is not missed by the first samples.
  const int pieces = 64;
  double total = 0.0;
  for (int piece = 0; piece < pieces; ++piece) {
    const double lo = a + (b - a) * piece / pieces, hi = a + (b - a) * (piece + 1) / pieces;
    const double f_lo = f(lo), f_mid = f(0.5 * (lo + hi)), f_hi = f(hi);
    total += recurse(lo, hi, f_lo, f_mid, f_hi, (hi - lo) / 6.0 * (f_lo + 4 * f_mid + f_hi), tolerance / pieces, depth);
  }
  return total;
}

TEST(NormalQuantile, MatchesTailProbability) {
  for (double p : {0.5, 0.4, 0.1, 0.025, 0.02425, 0.01, 1e-3, 2.5e-4, 1e-6, 1e-9, 1e-12, 1e-15, 1e-100}) {
    const double z = normal_upper_quantile(p);
    const double tail = 0.5 * std::erfc(z / std::sqrt(2.0));
    EXPECT_NEAR(tail / p, 1.0, kQuantileRelativeTolerance) << "p = " << p;
  }
  EXPECT_NEAR(normal_upper_quantile(0.025), 1.959963984540054, 1e-13);
  EXPECT_NEAR(normal_upper_quantile(0.5), 0.0, 1e-15);
  EXPECT_THROW(normal_upper_quantile(0.0), std::invalid_argument);
  EXPECT_THROW(normal_upper_quantile(0.6), std::invalid_argument);
}

TEST(NormalNoise, CellMassesMatchQuadrature) {
  const Grid grid(grid_spec({-10}, {10}, {0.5}));
  const NoiseModel noise(normal_noise({0.75}), grid);
  std::mt19937_64 generator(7);
  std::uniform_real_distribution<double> mean_distribution(-12, 12), sigma_distribution(0.05, 3.0);
  std::uniform_int_distribution<int> cell_distribution(0, 40);
  for (int trial = 0; trial < 200; ++trial) {
    const double mean = mean_distribution(generator), sigma = sigma_distribution(generator);
    const int k = cell_distribution(generator);
    const double lo = -10.0 + (k - 0.5) * 0.5, hi = lo + 0.5;
    const double expected =
        adaptive_simpson([&](double x) { return normal_pdf(x, mean, sigma); }, lo, hi, 1e-14, 30);
    EXPECT_NEAR(noise.cell_mass(0, std::size_t(k), mean, sigma), expected, kQuadratureTolerance)
        << "mean " << mean << " sigma " << sigma << " cell " << k;
  }
}

TEST(NormalNoise, TailMassesKeepRelativePrecision) {
  const Grid grid(grid_spec({0}, {1}, {1}));
  const NoiseModel noise(normal_noise({1.0}), grid);
  // Intervals 8..20 standard deviations away, on both sides of the mean.
  for (double start : {8.0, 12.0, 20.0}) {
    // Integrate pdf(x) / pdf(start) (order 1) and scale back, so the target is relative.
    const double relative = adaptive_simpson(
        [&](double x) { return std::exp(-0.5 * (x - start) * (x + start)); }, start, start + 1.0, 1e-14, 30);
    const double expected = relative * normal_pdf(start, 0.0, 1.0);
    const double right = noise.interval_mass(0, start, start + 1.0, 0.0, 1.0);
    const double left = noise.interval_mass(0, -start - 1.0, -start, 0.0, 1.0);
    ASSERT_GT(expected, 0.0);
    EXPECT_NEAR(right / expected, 1.0, kTailRelativeTolerance) << start;
    EXPECT_NEAR(left / expected, 1.0, kTailRelativeTolerance) << start;
  }
}

TEST(NormalNoise, RowSumsAtMostOneAndTelescope) {
  const Grid grid(grid_spec({-10, -10}, {10, 10}, {0.5, 0.5}));
  const NoiseModel noise(normal_noise({0.75, 0.75}, Truncation::None), grid);
  std::mt19937_64 generator(11);
  std::uniform_real_distribution<double> mean_distribution(-11, 11);
  for (int trial = 0; trial < 20; ++trial) {
    const double mean[2] = {mean_distribution(generator), mean_distribution(generator)};
    double row_sum = 0.0;
    for (std::size_t cell = 0; cell < grid.size(); ++cell)
      row_sum += noise.transition_probability(grid, cell, mean, mean);
    EXPECT_LE(row_sum, 1.0 + kRowSumSlack);
    // Without truncation the row is exactly the mass of the covered set [-10.25, 10.25]^2.
    const double covered = noise.interval_mass(0, -10.25, 10.25, mean[0], std::sqrt(0.75)) *
                           noise.interval_mass(1, -10.25, 10.25, mean[1], std::sqrt(0.75));
    EXPECT_NEAR(row_sum, covered, 1e-12);
  }
}

TEST(NormalNoise, PaperMidpointRuleExceedsOneOnBmwGridButExactMassDoesNot) {
  // BMW paper grid, x1: cells of width 4, noise standard deviation 0.5.
  const Grid grid(grid_spec({-10}, {10}, {4}));
  const NoiseModel noise(normal_noise({0.25}), grid);
  const double center = grid.coordinate(0, 2);
  const double midpoint_rule = normal_pdf(center, center, 0.5) * 4.0;
  EXPECT_NEAR(midpoint_rule, 3.19, 0.01);
  EXPECT_GT(midpoint_rule, 1.0);
  const double exact = noise.cell_mass(0, 2, center, 0.5);
  EXPECT_LE(exact, 1.0);
  EXPECT_NEAR(exact, 1.0 - std::erfc(4.0 / std::sqrt(2.0)), 1e-15);  // 1 - 2 Q(4)
}

TEST(NormalNoise, CuttingProbabilityWindowCutsAtMostGamma) {
  // A grid large enough that windows are never clipped for the means drawn.
  const Grid grid(grid_spec({-20, -20}, {20, 20}, {0.5, 0.5}));
  for (double gamma : {1e-1, 1e-3, 1e-6}) {
    const NoiseModel noise(normal_noise({0.75, 0.3}, Truncation::CuttingProbability, gamma), grid);
    EXPECT_LE(noise.cut_mass_bound(), gamma);
    std::mt19937_64 generator(3);
    std::uniform_real_distribution<double> mean_distribution(-5, 5);
    double largest_cut = 0.0;
    for (int trial = 0; trial < 200; ++trial) {
      const double mean[2] = {mean_distribution(generator), mean_distribution(generator)};
      std::int64_t first[2], last[2];
      ASSERT_TRUE(noise.window(grid, mean, first, last));
      double kept = 0.0;
      for (std::int64_t i = first[0]; i <= last[0]; ++i)
        for (std::int64_t j = first[1]; j <= last[1]; ++j) {
          const std::size_t multi[2] = {std::size_t(i), std::size_t(j)};
          kept += noise.transition_probability(grid, grid.flat_index(multi), mean, mean);
        }
      largest_cut = std::max(largest_cut, 1.0 - kept);
    }
    EXPECT_LE(largest_cut, noise.cut_mass_bound() + kRoundingSlack) << "gamma " << gamma;
    EXPECT_LE(largest_cut, gamma + kRoundingSlack);
    // Truncation actually truncates (a window as large as the grid would pass trivially).
    EXPECT_LT(noise.window_cells(), grid.size() / 10);
  }
}

TEST(NormalNoise, RobotWindowSize) {
  // Robot: sigma sqrt(.75), eta .5, gamma 1e-3, n = 2: z = Q^-1(2.5e-4) = 3.4808, h = ceil(6.03) = 7.
  const Grid grid(grid_spec({-10, -10}, {10, 10}, {0.5, 0.5}));
  const NoiseModel noise(normal_noise({0.75, 0.75}, Truncation::CuttingProbability, 1e-3), grid);
  EXPECT_EQ(noise.window_half_cells(), (std::vector<std::int64_t>{7, 7}));
  EXPECT_EQ(noise.window_cells(), 225u);
}

TEST(NormalNoise, BmwFixedRegionHas675Cells) {
  const Grid grid(grid_spec({-10, -10, -0.4, -2, -0.3, -0.4, -0.04}, {10, 10, 0.4, 2, 0.3, 0.4, 0.04},
                            {4, 4, 0.2, 1, 0.1, 0.2, 0.02}));
  const NoiseModel noise(normal_noise({0.0625, 0.0625, 0.04, 0.01, 0.04, 0.04, 0.04}, Truncation::FixedRegion,
                                      1e-3, {0.5, 0.5, 0.4, 2, 0.1, 0.2, 0.02}),
                         grid);
  EXPECT_EQ(noise.window_half_cells(), (std::vector<std::int64_t>{0, 0, 2, 2, 1, 1, 1}));
  EXPECT_EQ(noise.window_cells(), 675u);
  EXPECT_GT(noise.cut_mass_bound(), 0.0);
  EXPECT_LE(noise.cut_mass_bound(), 1.0);
}

TEST(NormalNoise, FixedRegionCutWithinBound) {
  const Grid grid(grid_spec({-20}, {20}, {0.5}));
  const NoiseModel noise(normal_noise({1.0}, Truncation::FixedRegion, 1e-3, {1.2}), grid);
  EXPECT_EQ(noise.window_half_cells()[0], 2);
  std::mt19937_64 generator(5);
  std::uniform_real_distribution<double> mean_distribution(-3, 3);
  for (int trial = 0; trial < 100; ++trial) {
    const double mean = mean_distribution(generator);
    std::int64_t first, last;
    ASSERT_TRUE(noise.window(grid, &mean, &first, &last));
    double kept = 0;
    for (std::int64_t k = first; k <= last; ++k) kept += noise.transition_probability(grid, std::size_t(k), &mean, &mean);
    EXPECT_LE(1.0 - kept, noise.cut_mass_bound() + kRoundingSlack);
  }
}

TEST(NormalNoise, NoTruncationWindowIsWholeGrid) {
  const Grid grid(grid_spec({0}, {10}, {1}));
  const NoiseModel noise(normal_noise({0.01}, Truncation::None), grid);
  EXPECT_EQ(noise.cut_mass_bound(), 0.0);
  const double far_mean = -50.0;
  std::int64_t first, last;
  ASSERT_TRUE(noise.window(grid, &far_mean, &first, &last));
  EXPECT_EQ(first, 0);
  EXPECT_EQ(last, 10);
}

TEST(NormalNoise, WindowOffGridAndNonFinite) {
  const Grid grid(grid_spec({0}, {10}, {1}));
  const NoiseModel noise(normal_noise({0.01}, Truncation::CuttingProbability, 1e-3), grid);
  std::int64_t first, last;
  const double far = 100.0, nan = std::nan("");
  EXPECT_FALSE(noise.window(grid, &far, &first, &last));
  EXPECT_FALSE(noise.window(grid, &nan, &first, &last));
  EXPECT_EQ(noise.transition_probability(grid, 10, &far, &far), 0.0);
  // Inside: a cell just outside the window has probability 0 (cut), inside it is the exact mass.
  const double mean = 5.0;
  ASSERT_TRUE(noise.window(grid, &mean, &first, &last));
  EXPECT_EQ(first, 5 - noise.window_half_cells()[0]);
  EXPECT_EQ(noise.transition_probability(grid, std::size_t(last + 1), &mean, &mean), 0.0);
  EXPECT_DOUBLE_EQ(noise.transition_probability(grid, 5, &mean, &mean), noise.cell_mass(0, 5, 5.0, 0.1));
}

TEST(UniformNoise, ExactMassesAndNothingCut) {
  const Grid grid(grid_spec({-5}, {5}, {0.5}));
  const NoiseModel noise(uniform_noise({0.6}, Truncation::CuttingProbability), grid);
  EXPECT_EQ(noise.cut_mass_bound(), 0.0);
  EXPECT_EQ(noise.window_half_cells()[0], 2);  // ceil(0.6 / 0.5)
  // Mean 0.1: support [-0.5, 0.7]; cell 0 ([-0.25, 0.25]) gets 0.5 / 1.2.
  const double mean = 0.1;
  EXPECT_NEAR(noise.transition_probability(grid, 10, &mean, &mean), 0.5 / 1.2, 1e-15);
  EXPECT_NEAR(noise.transition_probability(grid, 9, &mean, &mean), 0.25 / 1.2, 1e-15);
  EXPECT_NEAR(noise.transition_probability(grid, 11, &mean, &mean), 0.45 / 1.2, 1e-15);
  double row = 0;
  for (std::size_t k = 0; k < grid.size(); ++k) row += noise.transition_probability(grid, k, &mean, &mean);
  EXPECT_NEAR(row, 1.0, 1e-14);
}

TEST(MultiplicativeNoise, ScalesWithStateAndPointMassAtZero) {
  const Grid grid(grid_spec({-2}, {2}, {0.5}));
  NoiseConfig config = normal_noise({0.04}, Truncation::CuttingProbability, 1e-3);
  config.type = NoiseType::Multiplicative;
  const NoiseModel noise(config, grid);
  const double x = -1.5;
  EXPECT_NEAR(noise.scale(0, &x), 0.2 * 1.5, 1e-15);
  // The window is sized for the largest |x| = 2: scale 0.4.
  const double z = normal_upper_quantile(1e-3 / 2);
  EXPECT_EQ(noise.window_half_cells()[0], std::int64_t(std::ceil(z * 0.4 / 0.5)));
  const double zero = 0.0, mean = 0.6;
  EXPECT_EQ(noise.transition_probability(grid, 5, &mean, &zero), 1.0);  // cell of 0.5
  EXPECT_EQ(noise.transition_probability(grid, 4, &mean, &zero), 0.0);
  EXPECT_NEAR(noise.transition_probability(grid, 5, &mean, &x), noise.cell_mass(0, 5, mean, 0.3), 1e-15);
  // (A full matrix with multiplicative noise is refused: NoiseConfigErrors.)
}

// Config::validate() (the gate for every input) on a safety problem over `grid` with this noise.
void validate_noise(const NoiseConfig& noise, const Grid& grid) {
  GridSpec states;
  states.lb = grid.lb();
  states.eta = grid.eta();
  for (std::size_t i = 0; i < grid.dims(); ++i) states.ub.push_back(grid.coordinate(i, grid.count(i) - 1));
  test_support::make_config(states, std::nullopt, std::nullopt, noise, test_support::safety_spec(1)).validate();
}

TEST(NoiseConfigErrors, ConstructorAssertsAValidatedConfig) {
  const Grid grid(grid_spec({0, 0}, {1, 1}, {0.5, 0.5}));
  EXPECT_THROW(NoiseModel(normal_noise({1.0}), grid), std::logic_error);
  EXPECT_THROW(NoiseModel(normal_noise({1.0, 2.0, 2.0, 1.0}), grid), std::logic_error);
  EXPECT_THROW(NoiseModel(uniform_noise({1.0}), grid), std::logic_error);
}

TEST(NoiseConfigErrors, RejectsBadCovariance) {
  const Grid grid(grid_spec({0, 0}, {1, 1}, {0.5, 0.5}));
  EXPECT_THROW(validate_noise(normal_noise({1.0}), grid), ConfigError);                      // wrong size
  EXPECT_THROW(validate_noise(normal_noise({1.0, 0.5, 0.4, 1.0}), grid), ConfigError);       // not symmetric
  EXPECT_THROW(validate_noise(normal_noise({1.0, 2.0, 2.0, 1.0}), grid), ConfigError);       // not positive definite
  EXPECT_THROW(validate_noise(normal_noise({1.0, -1.0}), grid), ConfigError);                // negative variance
  EXPECT_THROW(validate_noise(normal_noise({1.0, 0.0, 0.0, 0.0}), grid), ConfigError);       // full: not SPD
  EXPECT_THROW(validate_noise(normal_noise({1.0, 1.0}, Truncation::CuttingProbability, 1.5), grid), ConfigError);
  EXPECT_THROW(validate_noise(normal_noise({1.0, 1.0}, Truncation::FixedRegion, 1e-3, {1.0}), grid), ConfigError);
  EXPECT_THROW(validate_noise(uniform_noise({1.0}), grid), ConfigError);
  NoiseConfig multiplicative_full = normal_noise({1.0, 0.5, 0.5, 1.0});
  multiplicative_full.type = NoiseType::Multiplicative;
  EXPECT_THROW(validate_noise(multiplicative_full, grid), ConfigError);
  try {
    validate_noise(normal_noise({1.0, 2.0, 2.0, 1.0}), grid);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), "noise.covariance");
    EXPECT_NE(std::string(error.what()).find("positive definite"), std::string::npos);
  }
}

TEST(FullCovariance, DiagonalMatrixUsesSeparablePath) {
  const Grid grid(grid_spec({0, 0}, {1, 1}, {0.5, 0.5}));
  EXPECT_TRUE(NoiseModel(normal_noise({0.5, 0.0, 0.0, 0.25}), grid).separable());
  EXPECT_FALSE(NoiseModel(normal_noise({0.5, 0.1, 0.1, 0.25}), grid).separable());
}

// Reference for 2-d: integrate over x0 the exact conditional interval mass of x1 (adaptive Simpson).
double box_mass_2d_reference(const double* lo, const double* hi, const double* mean, const double* covariance) {
  const double s0 = std::sqrt(covariance[0]);
  const double slope = covariance[1] / covariance[0];
  const double conditional_sigma = std::sqrt(covariance[3] - covariance[1] * covariance[1] / covariance[0]);
  auto conditional = [&](double x0) {
    const double m = mean[1] + slope * (x0 - mean[0]);
    return 0.5 * (std::erfc((lo[1] - m) / (conditional_sigma * std::sqrt(2.0))) -
                  std::erfc((hi[1] - m) / (conditional_sigma * std::sqrt(2.0))));
  };
  const double a = std::max(lo[0], mean[0] - 12 * s0), b = std::min(hi[0], mean[0] + 12 * s0);
  if (a >= b) return 0.0;
  return adaptive_simpson([&](double x0) { return normal_pdf(x0, mean[0], s0) * conditional(x0); }, a, b, 1e-14);
}

TEST(FullCovariance, BoxMassesMatchFineQuadratureWithinStatedTolerance) {
  const Grid grid(grid_spec({-3, -3}, {3, 3}, {0.5, 0.5}));
  for (const std::vector<double>& covariance :
       {std::vector<double>{0.75, 0.3, 0.3, 0.5}, std::vector<double>{0.2, -0.18, -0.18, 0.2},
        std::vector<double>{1.0, 0.99, 0.99, 1.0}, std::vector<double>{4.0, 0.5, 0.5, 0.1}}) {
    const NoiseModel noise(normal_noise(covariance), grid);
    ASSERT_FALSE(noise.separable());
    const double tolerance = noise.box_mass_tolerance();
    EXPECT_LT(tolerance, 1e-8) << "stated tolerance too loose to be useful";
    std::mt19937_64 generator(13);
    std::uniform_real_distribution<double> mean_distribution(-3, 3);
    std::uniform_int_distribution<int> cell_distribution(0, 12);
    double largest_error = 0.0;
    for (int trial = 0; trial < 60; ++trial) {
      const double mean[2] = {mean_distribution(generator), mean_distribution(generator)};
      const double center[2] = {-3 + 0.5 * cell_distribution(generator), -3 + 0.5 * cell_distribution(generator)};
      const double lo[2] = {center[0] - 0.25, center[1] - 0.25}, hi[2] = {center[0] + 0.25, center[1] + 0.25};
      const double expected = box_mass_2d_reference(lo, hi, mean, covariance.data());
      const double computed = noise.box_mass(lo, hi, mean);
      largest_error = std::max(largest_error, std::fabs(computed - expected));
      EXPECT_NEAR(computed, expected, tolerance + 1e-13) << "covariance[1] " << covariance[1];
    }
    std::printf("full covariance %g %g %g: stated tolerance %.3g, largest observed error %.3g\n", covariance[0],
                covariance[1], covariance[3], tolerance, largest_error);
  }
}

TEST(FullCovariance, RowsSumToCoveredMassAndAtMostOne) {
  const Grid grid(grid_spec({-6, -6}, {6, 6}, {0.5, 0.5}));
  const NoiseModel noise(normal_noise({0.75, 0.4, 0.4, 0.75}, Truncation::None), grid);
  std::mt19937_64 generator(17);
  std::uniform_real_distribution<double> mean_distribution(-3, 3);
  for (int trial = 0; trial < 5; ++trial) {
    const double mean[2] = {mean_distribution(generator), mean_distribution(generator)};
    double row = 0.0;
    for (std::size_t cell = 0; cell < grid.size(); ++cell) row += noise.transition_probability(grid, cell, mean, mean);
    EXPECT_LE(row, 1.0 + kRowSumSlack);
    const double lo[2] = {-6.25, -6.25}, hi[2] = {6.25, 6.25};
    EXPECT_NEAR(row, box_mass_2d_reference(lo, hi, mean, std::vector<double>{0.75, 0.4, 0.4, 0.75}.data()),
                double(grid.size()) * noise.box_mass_tolerance() + 1e-12);
  }
}

TEST(FullCovariance, ThreeDimensionsAgreeUnderReorderedConditioning) {
  // The same law with its dimensions reversed is integrated along a different Cholesky factor.
  const std::vector<double> covariance{1.0, 0.5, 0.2, 0.5, 0.8, -0.3, 0.2, -0.3, 0.6};
  std::vector<double> reversed(9);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) reversed[i * 3 + j] = covariance[(2 - i) * 3 + (2 - j)];
  const Grid grid(grid_spec({-2, -2, -2}, {2, 2, 2}, {0.5, 0.5, 0.5}));
  const NoiseModel noise(normal_noise(covariance), grid), noise_reversed(normal_noise(reversed), grid);
  std::mt19937_64 generator(19);
  std::uniform_real_distribution<double> position(-1.5, 1.5);
  for (int trial = 0; trial < 20; ++trial) {
    double mean[3], lo[3], hi[3], mean_r[3], lo_r[3], hi_r[3];
    for (int i = 0; i < 3; ++i) {
      mean[i] = position(generator);
      lo[i] = std::round(position(generator) * 2) / 2 - 0.25;
      hi[i] = lo[i] + 0.5;
    }
    for (int i = 0; i < 3; ++i) {
      mean_r[i] = mean[2 - i];
      lo_r[i] = lo[2 - i];
      hi_r[i] = hi[2 - i];
    }
    EXPECT_NEAR(noise.box_mass(lo, hi, mean), noise_reversed.box_mass(lo_r, hi_r, mean_r),
                noise.box_mass_tolerance() + noise_reversed.box_mass_tolerance());
  }
  EXPECT_LT(noise.box_mass_tolerance(), 1e-8);
}

TEST(NormalNoise, CellMassesAreBitIdenticalToCellMass) {
  const Grid grid(grid_spec({-3}, {3}, {0.1}));
  std::mt19937_64 generator(7);
  std::uniform_real_distribution<double> mean_draw(-4.0, 4.0), log_scale_draw(-4.0, 1.0);
  std::vector<double> masses(grid.count(0));
  for (const NoiseConfig& config : {normal_noise({1.0}), uniform_noise({0.35})}) {
    const NoiseModel noise(config, grid);
    for (int sample = 0; sample < 200; ++sample) {
      const double mean = mean_draw(generator);
      // Every tenth sample has scale 0 (a point mass); the others span tails and narrow peaks.
      const double scale = sample % 10 == 0 ? 0.0 : std::pow(10.0, log_scale_draw(generator));
      const std::int64_t first = sample % 7, last = std::int64_t(grid.count(0)) - 1 - sample % 5;
      noise.cell_masses(0, first, last, mean, scale, masses.data());
      for (std::int64_t k = first; k <= last; ++k)
        ASSERT_EQ(masses[std::size_t(k - first)], noise.cell_mass(0, std::size_t(k), mean, scale))
            << "k " << k << " mean " << mean << " scale " << scale;
    }
  }
}

TEST(ZeroVariance, DiagonalZeroIsAPointMassWithAOneCellWindow) {
  const Grid grid(grid_spec({0, 0}, {4, 4}, {1, 1}));
  for (Truncation truncation : {Truncation::None, Truncation::CuttingProbability, Truncation::FixedRegion}) {
    const std::vector<double> region = truncation == Truncation::FixedRegion ? std::vector<double>{2.0, 2.0}
                                                                             : std::vector<double>{};
    const NoiseModel noise(normal_noise({0.25, 0.0}, truncation, 1e-3, region), grid);
    EXPECT_TRUE(noise.separable());
    EXPECT_EQ(noise.base_scale()[1], 0.0);
    EXPECT_EQ(noise.window_half_cells()[1], 0) << "truncation " << int(truncation);
    EXPECT_GT(noise.window_half_cells()[0], 0);
    // Post mean (2.2, 2.4): dimension 1 puts everything in the cell [1.5, 2.5) of point 2.
    const double mean[2] = {2.2, 2.4}, x[2] = {2.0, 2.0};
    std::int64_t first[2], last[2];
    ASSERT_TRUE(noise.window(grid, mean, first, last));
    EXPECT_EQ(first[1], 2);
    EXPECT_EQ(last[1], 2);
    double row = 0.0;
    for (std::size_t target = 0; target < grid.size(); ++target) {
      const double probability = noise.transition_probability(grid, target, mean, x);
      std::size_t multi[2];
      grid.multi_index(target, multi);
      if (multi[1] != 2) {
        EXPECT_EQ(probability, 0.0);
      }
      row += probability;
    }
    EXPECT_EQ(noise.transition_probability(grid, grid.size() / 2, mean, x), noise.cell_mass(0, 2, 2.2, 0.5));
    EXPECT_LE(row, 1.0 + kRoundingSlack);
    // Dimension 0 (standard deviation 0.5) loses its truncation cut and the tails beyond the grid
    // edges, which are at least 4.6 standard deviations from the mean.
    constexpr double kEdgeTails = 1e-5;
    EXPECT_GE(row, 1.0 - noise.cut_mass_bound() - kEdgeTails);
  }
  // The face between two cells belongs to the upper one (half-open [lo, hi)).
  const NoiseModel noise(normal_noise({0.25, 0.0}, Truncation::CuttingProbability), grid);
  EXPECT_EQ(noise.cell_mass(1, 3, 2.5, 0.0), 1.0);
  EXPECT_EQ(noise.cell_mass(1, 2, 2.5, 0.0), 0.0);
}

TEST(ZeroVariance, NegativeVarianceAndSingularFullMatrixRefused) {
  const Grid grid(grid_spec({0, 0}, {1, 1}, {0.5, 0.5}));
  try {
    validate_noise(normal_noise({0.0, -1e-9}), grid);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), "noise.covariance[1]");
    EXPECT_NE(std::string(error.what()).find(">= 0"), std::string::npos) << error.what();
  }
  EXPECT_THROW(validate_noise(normal_noise({0.25, 0.0, 0.0, 0.0}), grid), ConfigError);
  EXPECT_NO_THROW(NoiseModel(normal_noise({0.0, 0.0}), grid));
}

TEST(FullCovariance, TooManyDimensionsRefused) {
  const Grid grid(grid_spec(std::vector<double>(5, 0), std::vector<double>(5, 1), std::vector<double>(5, 1)));
  std::vector<double> covariance(25, 0.1);
  for (int i = 0; i < 5; ++i) covariance[i * 6] = 1.0;
  EXPECT_THROW(validate_noise(normal_noise(covariance), grid), ConfigError);
}

}  // namespace
}  // namespace amytiss
