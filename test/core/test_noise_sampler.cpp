// NoiseSampler: every law draws with the mean and (co)variance of its definition, a custom density
// with its CDF, multiplicative noise scaled by |x_i|, and a fixed seed repeats its draws.
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "amytiss/config.hpp"
#include "amytiss/noise_sampler.hpp"

namespace amytiss {
namespace {

constexpr std::uint64_t kSeed = 20240611;
constexpr int kDraws = 200000;
constexpr int kCustomDraws = 20000;
// A sample mean of iid quantities lies within this many standard errors of the expectation
// (probability of a false failure below 1e-6 per check).
constexpr double kStandardErrors = 5.0;

// The noise section of a validated two-dimensional configuration.
NoiseConfig validated_noise(const std::string& noise) {
  return config_from_yaml(YAML::Load(
                              "name: sampler\n"
                              "states: {lb: [-5, -5], ub: [5, 5], eta: [1, 1]}\n"
                              "dynamics: [\"x0\", \"x1\"]\n"
                              "noise: " + noise + "\n"
                              "spec: {type: safety, horizon: 1}\n"))
      .noise;
}

std::vector<std::vector<double>> draws(const NoiseConfig& noise, const std::vector<double>& state, int count) {
  const NoiseSampler sampler(noise, 2);
  std::mt19937_64 random(kSeed);
  std::vector<std::vector<double>> out;
  for (int i = 0; i < count; ++i) out.push_back(sampler.draw(state.data(), random));
  return out;
}

// The sample mean of quantity(draw) against its expectation, within kStandardErrors standard
// errors (the standard deviation estimated from the same sample).
void expect_mean(const std::vector<std::vector<double>>& sample, const std::function<double(const std::vector<double>&)>& quantity,
                 double expected, const std::string& what) {
  double sum = 0, sum_squares = 0;
  for (const auto& draw : sample) {
    const double value = quantity(draw);
    sum += value;
    sum_squares += value * value;
  }
  const double n = double(sample.size());
  const double mean = sum / n;
  const double deviation = std::sqrt(std::max(0.0, sum_squares / n - mean * mean));
  EXPECT_NEAR(mean, expected, kStandardErrors * deviation / std::sqrt(n) + 1e-12) << what;
}

// Mean, variance of both components and their covariance against the law's.
void expect_moments(const std::vector<std::vector<double>>& sample, const std::vector<double>& mean,
                    const std::vector<double>& covariance) {
  for (std::size_t i = 0; i < 2; ++i) {
    expect_mean(sample, [i](const std::vector<double>& d) { return d[i]; }, mean[i], "mean " + std::to_string(i));
    expect_mean(sample, [&, i](const std::vector<double>& d) { return (d[i] - mean[i]) * (d[i] - mean[i]); },
                covariance[i * 2 + i], "variance " + std::to_string(i));
  }
  expect_mean(sample, [&](const std::vector<double>& d) { return (d[0] - mean[0]) * (d[1] - mean[1]); },
              covariance[1], "covariance");
}

const std::vector<double> kOrigin = {0.0, 0.0};

TEST(NoiseSampler, NormalDiagonalAndFullCovariance) {
  expect_moments(draws(validated_noise("{covariance: [0.75, 0.2]}"), kOrigin, kDraws), {0, 0}, {0.75, 0, 0, 0.2});
  expect_moments(draws(validated_noise("{covariance: [1.0, 0.6, 0.6, 0.5]}"), kOrigin, kDraws), {0, 0},
                 {1.0, 0.6, 0.6, 0.5});
}

TEST(NoiseSampler, Uniform) {
  const auto sample = draws(validated_noise("{distribution: uniform, half_width: [0.5, 2]}"), kOrigin, kDraws);
  expect_moments(sample, {0, 0}, {0.25 / 3, 0, 0, 4.0 / 3});
  for (const auto& draw : sample) ASSERT_TRUE(std::fabs(draw[0]) <= 0.5 && std::fabs(draw[1]) <= 2);
}

TEST(NoiseSampler, Exponential) {
  const auto sample =
      draws(validated_noise("{distribution: exponential, rate: [2, 4], shift: [-0.5, 0.1]}"), kOrigin, kDraws);
  expect_moments(sample, {-0.5 + 0.5, 0.1 + 0.25}, {0.25, 0, 0, 1.0 / 16});
  for (const auto& draw : sample) ASSERT_TRUE(draw[0] >= -0.5 && draw[1] >= 0.1);
}

TEST(NoiseSampler, Beta) {
  const auto sample = draws(
      validated_noise("{distribution: beta, alpha: [2, 0.5], beta: [5, 0.5], support: {lb: [-1, 0], ub: [1, 3]}}"),
      kOrigin, kDraws);
  auto beta_variance = [](double a, double b, double width) {
    return width * width * a * b / ((a + b) * (a + b) * (a + b + 1));
  };
  expect_moments(sample, {-1 + 2 * 2.0 / 7, 3 * 0.5}, {beta_variance(2, 5, 2), 0, 0, beta_variance(0.5, 0.5, 3)});
  for (const auto& draw : sample) ASSERT_TRUE(draw[0] >= -1 && draw[0] <= 1 && draw[1] >= 0 && draw[1] <= 3);
}

// Laplace(0, 1) truncated far out (mean 0, variance 2 up to e^-40) and the triangle 2z on [0, 1],
// whose CDF is z^2: the empirical CDF at a few points against it.
TEST(NoiseSampler, CustomDensityFollowsItsCdf) {
  const auto sample = draws(validated_noise("{distribution: custom, density: [\"0.5*exp(-abs(z))\", \"2*z\"], "
                                            "support: {lb: [-40, 0], ub: [40, 1]}}"),
                            kOrigin, kCustomDraws);
  expect_mean(sample, [](const std::vector<double>& d) { return d[0]; }, 0.0, "Laplace mean");
  expect_mean(sample, [](const std::vector<double>& d) { return d[0] * d[0]; }, 2.0, "Laplace variance");
  for (const double z : {0.2, 0.5, 0.8, 0.95}) {
    const double cdf = z * z;
    int below = 0;
    for (const auto& draw : sample) below += draw[1] <= z;
    const double n = double(sample.size());
    EXPECT_NEAR(below / n, cdf, kStandardErrors * std::sqrt(cdf * (1 - cdf) / n)) << "CDF at z = " << z;
  }
  for (const auto& draw : sample) ASSERT_TRUE(draw[1] >= 0 && draw[1] <= 1);
}

// Multiplicative noise is |x_i| * Z_i: the mean and the variance scale with |x_i| and x_i^2.
TEST(NoiseSampler, MultiplicativeScalesWithTheState) {
  const std::vector<double> state = {2.0, -3.0};
  const auto exponential = draws(
      validated_noise("{type: multiplicative, distribution: exponential, rate: [2, 4]}"), state, kDraws);
  expect_moments(exponential, {2 * 0.5, 3 * 0.25}, {4 * 0.25, 0, 0, 9.0 / 16});
  const auto normal = draws(validated_noise("{type: multiplicative, covariance: [0.5, 0.1]}"), state, kDraws);
  expect_moments(normal, {0, 0}, {4 * 0.5, 0, 0, 9 * 0.1});
  const auto at_zero = draws(validated_noise("{type: multiplicative, covariance: [0.5, 0.1]}"), kOrigin, 10);
  for (const auto& draw : at_zero) EXPECT_EQ(draw, kOrigin);
}

TEST(NoiseSampler, TheSeedFixesTheDraws) {
  for (const std::string noise : {"{covariance: [0.5, 0.1]}", "{distribution: beta, alpha: [2, 2], beta: [3, 3], "
                                                                "support: {lb: [-1, -1], ub: [1, 1]}}"}) {
    const auto first = draws(validated_noise(noise), kOrigin, 5);
    EXPECT_EQ(first, draws(validated_noise(noise), kOrigin, 5)) << noise;
    EXPECT_NE(first[0], first[1]) << noise;
  }
}

}  // namespace
}  // namespace amytiss
