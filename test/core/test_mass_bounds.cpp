// Interval transition bounds per dimension (bounds/mass_bounds.hpp): the 1-d extrema of each law
// against closed forms, soundness over sampled means and scales (every law, additive and
// multiplicative), the union window and the mass leaving the grid or cut by the truncation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "amytiss/errors.hpp"
#include "bounds/mass_bounds.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using namespace test_support;

// A closed-form extremum may lie this far inside the bound: the law's evaluation error widened
// the bound (mass_error()), plus rounding.
constexpr double kTightness = 1e-12;
// The beta peak by golden-section search on the closed form stops this close to the peak mean.
constexpr double kGoldenStop = 1e-10;
constexpr int kSoundnessSamples = 400;

// One dimension on [-2, 2] (cells of 0.2) with the given noise.
struct OneDimension {
  Grid grid;
  NoiseModel noise;
  MassBounds bounds;
  explicit OneDimension(const NoiseConfig& config)
      : grid(grid_spec({-1.9}, {1.9}, {0.2})), noise(config, grid), bounds(noise, 0) {}
};

NoiseConfig exponential_noise(double rate, double shift) {
  NoiseConfig noise;
  noise.distribution = Distribution::Exponential;
  noise.rate = {rate};
  noise.shift = {shift};
  return noise;
}

NoiseConfig beta_noise(double alpha, double beta, double lb, double ub) {
  NoiseConfig noise;
  noise.distribution = Distribution::Beta;
  noise.alpha = {alpha};
  noise.beta = {beta};
  noise.support = box({lb}, {ub});
  return noise;
}

NoiseConfig laplace_noise() {
  NoiseConfig noise;
  noise.distribution = Distribution::Custom;
  noise.density = {"0.5*exp(-abs(z))"};
  noise.support = box({-40}, {40});
  return noise;
}

double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

// The interval [lo, hi] holds [exact_min, exact_max] and is tight to kTightness.
void expect_tight(const MassInterval& bound, double exact_min, double exact_max) {
  EXPECT_LE(bound.lo, exact_min);
  EXPECT_GE(bound.hi, exact_max);
  EXPECT_LE(exact_min - bound.lo, kTightness);
  EXPECT_LE(bound.hi - exact_max, kTightness);
}

TEST(MassBounds, NormalExtremaAreTheClosedForms) {
  const double s = 0.3, a = 0.1, b = 0.3;
  OneDimension d(normal_noise({s * s}));
  auto g = [&](double m) { return normal_cdf((b - m) / s) - normal_cdf((a - m) / s); };
  // The cell's centre 0.2 inside [0, 0.25]: the maximum is the centred mass, the minimum at the
  // farther endpoint 0.
  expect_tight(d.bounds.bounds(a, b, 0.0, 0.25, s, s), g(0.0), std::erf((b - a) / (2 * s * std::sqrt(2.0))));
  // The centre left of [0.3, 0.5]: maximum at 0.3, minimum at 0.5.
  expect_tight(d.bounds.bounds(a, b, 0.3, 0.5, s, s), g(0.5), g(0.3));
  // Far in the tail both extrema stay tight in absolute terms.
  expect_tight(d.bounds.bounds(a, b, 2.0, 2.5, s, s), g(2.5), g(2.0));
}

TEST(MassBounds, UniformExtremaAreTheClosedForms) {
  const double h = 0.25, a = 0.0, b = 0.2;
  OneDimension d(uniform_noise({h}));
  auto g = [&](double m) { return std::max(0.0, std::min(b, m + h) - std::max(a, m - h)) / (2 * h); };
  // Means with the whole cell inside the support reach 0.2/0.5; the far end of [0.05, 0.3] drops to 0.3.
  expect_tight(d.bounds.bounds(a, b, 0.05, 0.3, h, h), g(0.3), 0.4);
  expect_tight(d.bounds.bounds(a, b, 0.3, 0.5, h, h), 0.0, g(0.3));
}

TEST(MassBounds, ExponentialPeakPutsTheCellOnTheShift) {
  const double rate = 2.0, shift = 0.1, a = 0.5, b = 0.8;
  OneDimension d(exponential_noise(rate, shift));
  // Z = shift + Exp(rate): g(m) = P(a - m - shift <= E <= b - m - shift).
  auto cdf = [&](double t) { return t <= 0 ? 0.0 : 1.0 - std::exp(-rate * t); };
  auto g = [&](double m) { return cdf(b - m - shift) - cdf(a - m - shift); };
  // The peak mean a - shift = 0.4 lies in [0.2, 0.6]: the maximum 1 - exp(-rate (b - a)).
  expect_tight(d.bounds.bounds(a, b, 0.2, 0.6, 1.0, 1.0), std::min(g(0.2), g(0.6)), 1.0 - std::exp(-rate * (b - a)));
  // Right of the peak g decreases: maximum at 0.45, minimum at 0.7.
  expect_tight(d.bounds.bounds(a, b, 0.45, 0.7, 1.0, 1.0), g(0.7), g(0.45));
  // Left of it g increases.
  expect_tight(d.bounds.bounds(a, b, -0.3, 0.1, 1.0, 1.0), g(-0.3), g(0.1));
}

TEST(MassBounds, SymmetricBetaPeakIsCentred) {
  OneDimension d(beta_noise(2, 2, -0.5, 0.5));
  // Beta(2, 2) on [-0.5, 0.5]: F(z) = 3t^2 - 2t^3 with t = z + 0.5.
  auto cdf = [](double z) {
    const double t = std::clamp(z + 0.5, 0.0, 1.0);
    return 3 * t * t - 2 * t * t * t;
  };
  const double a = 0.1, b = 0.3;
  auto g = [&](double m) { return cdf(b - m) - cdf(a - m); };
  expect_tight(d.bounds.bounds(a, b, 0.1, 0.4, 1.0, 1.0), std::min(g(0.1), g(0.4)), g(0.2));
}

TEST(MassBounds, AsymmetricBetaPeakByBisection) {
  OneDimension d(beta_noise(2, 5, 0.0, 1.0));
  // Beta(2, 5): F(t) = 1 - (1 - t)^6 - 6 t (1 - t)^5 (the binomial sum of I_t(2, 5)).
  auto cdf = [](double z) {
    const double t = std::clamp(z, 0.0, 1.0);
    return 1.0 - std::pow(1 - t, 6) - 6 * t * std::pow(1 - t, 5);
  };
  const double a = 0.3, b = 0.45;
  auto g = [&](double m) { return cdf(b - m) - cdf(a - m); };
  // Golden-section search of the peak on [0, 0.4] (g is log-concave).
  double left = 0.0, right = 0.4;
  const double ratio = (std::sqrt(5.0) - 1) / 2;
  while (right - left > kGoldenStop) {
    const double x1 = right - ratio * (right - left), x2 = left + ratio * (right - left);
    if (g(x1) < g(x2)) left = x1;
    else right = x2;
  }
  const double peak = g(0.5 * (left + right));
  expect_tight(d.bounds.bounds(a, b, 0.0, 0.4, 1.0, 1.0), std::min(g(0.0), g(0.4)), peak);
  // The peak mean is near 0.2: an interval right of it has its maximum at its left end.
  expect_tight(d.bounds.bounds(a, b, 0.3, 0.5, 1.0, 1.0), g(0.5), g(0.3));
}

TEST(MassBounds, CustomDensityTakesTheCdfBoundWithSplitting) {
  OneDimension d(laplace_noise());
  auto cdf = [](double v) { return v < 0 ? 0.5 * std::exp(v) : 1.0 - 0.5 * std::exp(-v); };
  const double a = 0.0, b = 0.5, m_lo = -0.4, m_hi = 0.6;
  auto g = [&](double m) { return cdf(b - m) - cdf(a - m); };
  const MassInterval bound = d.bounds.bounds(a, b, m_lo, m_hi, 1.0, 1.0);
  // Each piece over-states by at most 2 * max density * piece width.
  const double piece_slack = 2 * 0.5 * (m_hi - m_lo) / double(MassBounds::kSplits);
  const double exact_max = g(0.25), exact_min = std::min(g(m_lo), g(m_hi));
  EXPECT_LE(bound.lo, exact_min);
  EXPECT_GE(bound.hi, exact_max);
  EXPECT_LE(exact_min - bound.lo, piece_slack);
  EXPECT_LE(bound.hi - exact_max, piece_slack);
}

// lo <= g(m, s) <= hi on sampled means and scales, for random cells and mean intervals.
void expect_sound(const NoiseModel& noise, const MassBounds& bounds, double x_lo, double x_hi, std::uint64_t seed) {
  std::mt19937_64 generator(seed);
  std::uniform_real_distribution<double> position(-1.5, 1.5), width(0.0, 0.6), unit(0.0, 1.0);
  const MassInterval scales = bounds.scale_range(x_lo, x_hi);
  for (int trial = 0; trial < 40; ++trial) {
    const double a = position(generator), b = a + 0.05 + width(generator);
    const double m_lo = position(generator), m_hi = m_lo + width(generator);
    const MassInterval bound = bounds.bounds(a, b, m_lo, m_hi, scales.lo, scales.hi);
    ASSERT_LE(0.0, bound.lo);
    ASSERT_LE(bound.lo, bound.hi);
    ASSERT_LE(bound.hi, 1.0);
    for (int sample = 0; sample < kSoundnessSamples / 40; ++sample) {
      const double m = sample == 0 ? m_lo : sample == 1 ? m_hi : m_lo + (m_hi - m_lo) * unit(generator);
      const double x = x_lo + (x_hi - x_lo) * unit(generator);
      const double s = noise.scale(0, &x);
      // Standardized, as the law is defined (the uniform's mass in state units loses digits to
      // cancellation at small scales).
      const double mass = s == 0.0 ? noise.interval_mass(0, a, b, m, s)
                                   : noise.interval_mass(0, (a - m) / s, (b - m) / s, 0.0, 1.0);
      EXPECT_LE(bound.lo, mass) << "a " << a << " b " << b << " m " << m << " s " << s;
      EXPECT_GE(bound.hi, mass) << "a " << a << " b " << b << " m " << m << " s " << s;
    }
  }
}

TEST(MassBounds, SoundForEveryLawAdditiveAndMultiplicative) {
  const std::vector<NoiseConfig> laws = {normal_noise({0.09}),          uniform_noise({0.3}),
                                         exponential_noise(3.0, -0.2), beta_noise(2, 5, -0.4, 0.6),
                                         beta_noise(0.5, 0.5, -0.3, 0.3), laplace_noise()};
  std::uint64_t seed = 20261201;
  for (NoiseConfig config : laws) {
    for (NoiseType type : {NoiseType::Additive, NoiseType::Multiplicative}) {
      SCOPED_TRACE(to_string(config.distribution) + " " + to_string(type));
      config.type = type;
      OneDimension d(config);
      // Source cells away from 0 and across it (multiplicative: scales down to 0, a point mass).
      expect_sound(d.noise, d.bounds, 0.5, 0.7, seed++);
      expect_sound(d.noise, d.bounds, -0.1, 0.1, seed++);
    }
  }
}

TEST(MassBounds, ZeroScaleIsAPointMass) {
  OneDimension d(normal_noise({0.0}));
  const MassInterval inside = d.bounds.bounds(0.0, 0.2, 0.05, 0.1, 0.0, 0.0);
  EXPECT_EQ(inside.lo, 1.0);
  EXPECT_EQ(inside.hi, 1.0);
  const MassInterval across = d.bounds.bounds(0.0, 0.2, 0.15, 0.25, 0.0, 0.0);
  EXPECT_EQ(across.lo, 0.0);
  EXPECT_EQ(across.hi, 1.0);
  // A closed image as wide as the cell (a deterministic step of exactly one cell) reaches the next
  // cell's lower face: from the box alone the point may lie in either cell (a lattice dimension's
  // rows argue on margins instead: bounds/lattice.hpp, test_lattice_bounds).
  const MassInterval whole = d.bounds.bounds(0.0, 0.2, 0.0, 0.2, 0.0, 0.0);
  EXPECT_EQ(whole.lo, 0.0);
  EXPECT_EQ(whole.hi, 1.0);
  const MassInterval next = d.bounds.bounds(0.2, 0.4, 0.0, 0.2, 0.0, 0.0);
  EXPECT_EQ(next.lo, 0.0);
  EXPECT_EQ(next.hi, 1.0);
}

TEST(MassBounds, FullCovarianceIsAConfigError) {
  const Grid grid(grid_spec({-1, -1}, {1, 1}, {0.5, 0.5}));
  const NoiseModel noise(normal_noise({0.04, 0.01, 0.01, 0.04}), grid);
  try {
    MassBounds bounds(noise, 0);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), "noise.covariance");
  }
}

TEST(MassBounds, WindowIsTheUnionOverTheMeans) {
  OneDimension d(normal_noise({0.04}, Truncation::FixedRegion, 1e-3, {0.45}));
  std::int64_t first = 0, last = 0, k_first = 0, k_last = 0;
  const double m_lo = -0.33, m_hi = 0.41;
  ASSERT_TRUE(d.bounds.window(d.grid, m_lo, m_hi, &first, &last));
  for (int i = 0; i <= 100; ++i) {
    const double m = m_lo + (m_hi - m_lo) * i / 100.0;
    ASSERT_TRUE(d.noise.dimension_window(d.grid, 0, m, &k_first, &k_last));
    EXPECT_LE(first, k_first);
    EXPECT_GE(last, k_last);
  }
  // Both ends' windows are reached.
  d.noise.dimension_window(d.grid, 0, m_lo, &k_first, &k_last);
  EXPECT_EQ(first, k_first);
  d.noise.dimension_window(d.grid, 0, m_hi, &k_first, &k_last);
  EXPECT_EQ(last, k_last);
}

TEST(MassBounds, LeaveAndCutMassHoldWhatTheWindowMisses) {
  // Normal noise with a fixed region: the tails reach cells outside the window.
  OneDimension truncated(normal_noise({0.04}, Truncation::FixedRegion, 1e-3, {0.45}));
  const DimensionBounds normal = truncated.bounds.dimension_bounds(truncated.grid, 1.2, 1.4, 0.2, 0.2);
  EXPECT_GT(normal.cut.hi, 0.0);
  for (int i = 0; i <= 20; ++i) {
    const double m = 1.2 + 0.2 * i / 20.0;
    double on_grid = 0, in_window = 0;
    for (std::size_t k = 0; k < truncated.grid.count(0); ++k) {
      const double mass = truncated.noise.cell_mass(0, k, m, 0.2);
      on_grid += mass;
      if (std::int64_t(k) >= normal.first && std::int64_t(k) <= normal.last) in_window += mass;
    }
    EXPECT_LE(normal.leave.lo, 1.0 - on_grid);
    EXPECT_GE(normal.leave.hi, 1.0 - on_grid);
    EXPECT_LE(normal.cut.lo, on_grid - in_window);
    EXPECT_GE(normal.cut.hi, on_grid - in_window);
  }
  // Uniform noise: the window covers the support, so nothing is cut, exactly.
  OneDimension uniform(uniform_noise({0.25}, Truncation::CuttingProbability));
  const DimensionBounds middle = uniform.bounds.dimension_bounds(uniform.grid, 0.0, 0.1, 0.25, 0.25);
  EXPECT_EQ(middle.cut.hi, 0.0);
  EXPECT_EQ(middle.leave.lo, 0.0);
  // Near the edge some mass leaves the grid; still nothing is cut.
  const DimensionBounds edge = uniform.bounds.dimension_bounds(uniform.grid, 1.9, 2.0, 0.25, 0.25);
  EXPECT_EQ(edge.cut.hi, 0.0);
  EXPECT_GT(edge.leave.lo, 0.0);
}

TEST(MassBounds, UnboundedBoxOfMeansSaysNothing) {
  OneDimension d(normal_noise({0.04}));
  const DimensionBounds row = d.bounds.dimension_bounds(d.grid, -std::numeric_limits<double>::infinity(), 0.0, 0.2, 0.2);
  EXPECT_TRUE(row.cells.empty());
  EXPECT_EQ(row.leave.lo, 0.0);
  EXPECT_EQ(row.leave.hi, 1.0);
  EXPECT_EQ(row.cut.lo, 0.0);
  EXPECT_EQ(row.cut.hi, 1.0);
}

TEST(MassBounds, OutwardRounding) {
  EXPECT_LT(round_down(0.3), 0.3);
  EXPECT_GT(round_up(0.3), 0.3);
  EXPECT_EQ(round_down(round_up(0.3)), 0.3);
  const MassInterval none[1] = {};
  const MassInterval empty = remainder(none, 0);
  EXPECT_EQ(empty.lo, 1.0);
  EXPECT_EQ(empty.hi, 1.0);
}

}  // namespace
}  // namespace amytiss
