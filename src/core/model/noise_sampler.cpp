#include "amytiss/noise_sampler.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "amytiss/noise.hpp"
#include "common/require.hpp"
#include "model/noise_laws.hpp"

namespace amytiss {
namespace {

// A custom law's CDF is tabulated at this many pieces of its support; a draw then bisects within
// one piece, so each draw costs kBisections quadratures of a short interval.
constexpr std::size_t kCdfPieces = 256;
constexpr int kBisections = 60;

// The sampler's input passed Config::validate(); a violation is a bug of the caller.
constexpr detail::Require require{"NoiseSampler: expected a validated configuration: "};

std::vector<double> normal_factor(const std::vector<double>& covariance, std::size_t n) {
  require(covariance.size() == n || covariance.size() == n * n, "covariance of n or n*n values");
  std::vector<double> factor(n * n, 0.0);
  if (covariance.size() == n) {
    for (std::size_t i = 0; i < n; ++i) factor[i * n + i] = std::sqrt(covariance[i]);
    return factor;
  }
  auto cholesky = cholesky_factor(covariance, n);
  require(cholesky.has_value(), "a positive definite covariance");
  return *cholesky;
}

// CDF of the law at lo + (hi - lo) * k / kCdfPieces, k = 0..kCdfPieces, by the law's own masses.
std::vector<double> tabulate_cdf(const detail::UnitLaw& law) {
  std::vector<double> cumulative(kCdfPieces + 1, 0.0);
  const double width = (law.hi - law.lo) / double(kCdfPieces);
  for (std::size_t k = 0; k < kCdfPieces; ++k) {
    const double from = law.lo + double(k) * width;
    cumulative[k + 1] = cumulative[k] + law.mass(from, from + width);
  }
  return cumulative;
}

}  // namespace

NoiseSampler::NoiseSampler(const NoiseConfig& noise, std::size_t dims, const std::map<std::string, double>& constants)
    : dims_(dims), noise_(noise) {
  switch (noise.distribution) {
    case Distribution::Normal:
      factor_ = normal_factor(noise.covariance, dims);
      break;
    case Distribution::Uniform:
      require(noise.half_width.size() == dims, "one half-width per dimension");
      factor_.assign(dims * dims, 0.0);
      for (std::size_t i = 0; i < dims; ++i) factor_[i * dims + i] = noise.half_width[i];
      break;
    default:
      for (std::size_t i = 0; i < dims; ++i) {
        laws_.push_back(std::make_shared<detail::UnitLaw>(detail::unit_law(noise, i, constants)));
        if (noise.distribution == Distribution::Custom) cumulative_.push_back(tabulate_cdf(*laws_.back()));
      }
  }
}

NoiseSampler::~NoiseSampler() = default;

std::vector<double> NoiseSampler::draw(const double* x, std::mt19937_64& random) const {
  std::vector<double> noise(dims_, 0.0);
  if (laws_.empty()) {
    // Normal and uniform: Z = factor * (standard draws), row i using draws 0..i.
    const std::vector<double> standard = standard_draws(random);
    for (std::size_t i = 0; i < dims_; ++i)
      for (std::size_t k = 0; k <= i; ++k) noise[i] += factor_[i * dims_ + k] * standard[k];
  } else {
    for (std::size_t i = 0; i < dims_; ++i) noise[i] = unit_draw(i, random);
  }
  if (noise_.type == NoiseType::Multiplicative)
    for (std::size_t i = 0; i < dims_; ++i) noise[i] *= std::fabs(x[i]);
  return noise;
}

std::vector<double> NoiseSampler::standard_draws(std::mt19937_64& random) const {
  std::vector<double> standard(dims_);
  const bool uniform = noise_.distribution == Distribution::Uniform;
  for (double& z : standard)
    z = uniform ? std::uniform_real_distribution<double>(-1.0, 1.0)(random)
                : std::normal_distribution<double>(0.0, 1.0)(random);
  return standard;
}

double NoiseSampler::unit_draw(std::size_t dim, std::mt19937_64& random) const {
  const detail::UnitLaw& law = *laws_[dim];
  switch (law.distribution) {
    case Distribution::Exponential:
      return law.shift + std::exponential_distribution<double>(law.rate)(random);
    case Distribution::Beta: {
      const double a = std::gamma_distribution<double>(law.alpha, 1.0)(random);
      const double b = std::gamma_distribution<double>(law.beta, 1.0)(random);
      return law.lo + (law.hi - law.lo) * (a / (a + b));
    }
    default:
      return custom_draw(dim, std::uniform_real_distribution<double>(0.0, 1.0)(random));
  }
}

// The z with CDF(z) = probability: the tabulated piece that holds it, then bisection on the
// piece's partial mass.
double NoiseSampler::custom_draw(std::size_t dim, double probability) const {
  const detail::UnitLaw& law = *laws_[dim];
  const std::vector<double>& cumulative = cumulative_[dim];
  const double target = probability * cumulative.back();
  const auto above = std::upper_bound(cumulative.begin() + 1, cumulative.end() - 1, target);
  const std::size_t piece = std::size_t(above - cumulative.begin()) - 1;
  const double width = (law.hi - law.lo) / double(kCdfPieces);
  const double from = law.lo + double(piece) * width;
  const double wanted = target - cumulative[piece];
  double lo = from, hi = from + width;
  for (int step = 0; step < kBisections && lo < hi; ++step) {
    const double middle = 0.5 * (lo + hi);
    if (law.mass(from, middle) < wanted) lo = middle;
    else hi = middle;
  }
  return 0.5 * (lo + hi);
}

}  // namespace amytiss
