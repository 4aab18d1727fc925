// Config::validate()'s checks of the `noise` section (docs/configuration.md, "Noise"): the
// normal's covariance, the uniform's half-widths, the exponential's rates, the beta's shape and
// support, a custom density's expression, sign and integral, and the truncation parameters.
#include <cmath>
#include <string>

#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/expression.hpp"
#include "amytiss/noise.hpp"
#include "config/messages.hpp"
#include "model/noise_laws.hpp"

namespace amytiss::detail {
namespace {

// Covariance entries (r, k) and (k, r) may differ by this much relative to max(1, |entry|).
constexpr double kSymmetryTolerance = 1e-12;
// A custom density must integrate to 1 within this over its support (it is then normalized).
constexpr double kDensityIntegralTolerance = 1e-6;

// Each distribution's own keys; a key of another distribution is a mistake worth naming.
void check_keys_of_distribution(const NoiseConfig& noise) {
  struct Owned {
    const char* key;
    bool given;
    bool allowed;
    const char* owner;
  };
  const Distribution d = noise.distribution;
  const Owned keys[] = {
      {"covariance", !noise.covariance.empty(), d == Distribution::Normal, "normal"},
      {"half_width", !noise.half_width.empty(), d == Distribution::Uniform, "uniform"},
      {"rate", !noise.rate.empty(), d == Distribution::Exponential, "exponential"},
      {"shift", !noise.shift.empty(), d == Distribution::Exponential, "exponential"},
      {"alpha", !noise.alpha.empty(), d == Distribution::Beta, "beta"},
      {"beta", !noise.beta.empty(), d == Distribution::Beta, "beta"},
      {"density", !noise.density.empty(), d == Distribution::Custom, "custom"},
      {"support", noise.support.has_value(), d == Distribution::Beta || d == Distribution::Custom, "beta and custom"},
  };
  const char* own = d == Distribution::Normal        ? "covariance"
                    : d == Distribution::Uniform     ? "half_width"
                    : d == Distribution::Exponential ? "rate, shift"
                    : d == Distribution::Beta        ? "alpha, beta, support"
                                                     : "density, support";
  for (const Owned& key : keys)
    if (key.given && !key.allowed)
      throw ConfigError(std::string("noise.") + key.key, "given for distribution " + to_string(d) +
                                                             "; it is only used by distribution " + key.owner +
                                                             " (distribution " + to_string(d) + " uses noise." +
                                                             own + ")");
}

// A list of exactly n finite numbers, each > 0 when `positive`.
void check_list(const std::vector<double>& values, std::size_t n, const std::string& key, bool positive,
                const std::string& example) {
  if (values.size() != n)
    fail(key, std::to_string(values.size()) + " values", std::to_string(n) + " values (one per state)", example);
  check_finite_list(values, key, example);
  if (positive)
    for (std::size_t i = 0; i < n; ++i)
      if (!(values[i] > 0)) fail(indexed(key, i), format_number(values[i]), "a number > 0", example);
}

void check_support(const NoiseConfig& noise, std::size_t n) {
  const std::string example = "support: {lb: [-1, -1], ub: [1, 1]}";
  if (!noise.support)
    throw ConfigError("noise.support", "missing, expected the interval the noise lives in for distribution " +
                                           to_string(noise.distribution) + " (example: " + example + ")");
  check_list(noise.support->lb, n, "noise.support.lb", false, example);
  check_list(noise.support->ub, n, "noise.support.ub", false, example);
  for (std::size_t i = 0; i < n; ++i)
    if (!(noise.support->lb[i] < noise.support->ub[i]))
      fail(indexed("noise.support.ub", i), format_number(noise.support->ub[i]),
           "a number > noise.support.lb[" + std::to_string(i) + "] = " + format_number(noise.support->lb[i]),
           example);
}

void check_density(const NoiseConfig& noise, std::size_t i, const std::map<std::string, double>& constants) {
  const std::string key = indexed("noise.density", i);
  Expression density;
  try {
    density = Expression::parse_density(noise.density[i], constants);
  } catch (const ParseError& error) {
    throw ConfigError(key, std::string(error.what()) + " in \"" + noise.density[i] + "\"");
  }
  const double lo = noise.support->lb[i], hi = noise.support->ub[i];
  const DensityCheck check = detail::check_density(density, lo, hi);
  const std::string where = " on the support [" + format_number(lo) + ", " + format_number(hi) + "]";
  if (!check.finite)
    throw ConfigError(key, "'" + noise.density[i] + "' is not finite at z = " + format_number(check.nonfinite_at) +
                               where + "; expected a finite density >= 0 (example: \"0.5*exp(-abs(z))\")");
  if (check.smallest < 0)
    throw ConfigError(key, "'" + noise.density[i] + "' is negative at z = " + format_number(check.smallest_at) +
                               " (value " + format_number(check.smallest) + ")" + where +
                               "; expected a density >= 0 (example: \"0.5*exp(-abs(z))\")");
  if (!(std::fabs(check.integral.value - 1.0) <= kDensityIntegralTolerance))
    throw ConfigError(key, "'" + noise.density[i] + "' integrates to " + format_number(check.integral.value) + where +
                               ", expected 1 within " + format_number(kDensityIntegralTolerance) +
                               " (scale the density or widen noise.support; example: \"0.5*exp(-abs(z))\" on "
                               "[-40, 40])");
}

// Exponential, beta and custom noise.
void check_law_noise(const NoiseConfig& noise, std::size_t n, const std::map<std::string, double>& constants) {
  switch (noise.distribution) {
    case Distribution::Exponential:
      check_list(noise.rate, n, "noise.rate", true, "rate: [2.0, 2.0]");
      if (!noise.shift.empty()) check_list(noise.shift, n, "noise.shift", false, "shift: [-0.5, -0.5]");
      break;
    case Distribution::Beta:
      check_list(noise.alpha, n, "noise.alpha", true, "alpha: [2, 2]");
      check_list(noise.beta, n, "noise.beta", true, "beta: [5, 5]");
      check_support(noise, n);
      break;
    default: {
      const std::string example = "density: [\"0.5*exp(-abs(z))\", ...] (one per state)";
      if (noise.density.size() != n)
        fail("noise.density", std::to_string(noise.density.size()) + " expressions", std::to_string(n) +
             " (one per state)", example);
      check_support(noise, n);
      for (std::size_t i = 0; i < n; ++i) check_density(noise, i, constants);
      break;
    }
  }
}

void check_normal(const NoiseConfig& noise, std::size_t n) {
  const std::string n_text = std::to_string(n);
  const std::string example = n == 2 ? "covariance: [0.75, 0.75]" : "covariance: [" + n_text + " variances]";
  const auto& c = noise.covariance;
  if (c.size() != n && c.size() != n * n)
    fail("noise.covariance", std::to_string(c.size()) + " values",
         n_text + " values (diagonal) or " + std::to_string(n * n) + " values (full matrix, row-major)", example);
  check_finite_list(c, "noise.covariance", example);
  if (c.size() == n) {
    for (std::size_t i = 0; i < n; ++i)
      if (c[i] < 0)
        fail(indexed("noise.covariance", i), format_number(c[i]),
             "a variance >= 0 (0: no noise in that dimension)", example);
  } else {
    if (noise.type == NoiseType::Multiplicative)
      throw ConfigError("noise.covariance",
                        "a full covariance matrix with multiplicative noise is not supported; give the " + n_text +
                            " diagonal variances (example: " + example + ")");
    bool diagonal = true;
    for (std::size_t r = 0; r < n; ++r)
      for (std::size_t k = 0; k < n; ++k)
        if (r != k && c[r * n + k] != 0.0) diagonal = false;
    if (!diagonal && n > NoiseModel::kMaxFullCovarianceDims)
      throw ConfigError("noise.covariance",
                        "a full (non-diagonal) covariance is supported up to " +
                            std::to_string(NoiseModel::kMaxFullCovarianceDims) + " state dimensions, got " + n_text +
                            " (the quadrature cost grows like points^(n-1)); give the " + n_text +
                            " diagonal variances (example: " + example + ")");
    const auto entry = [&](std::size_t r, std::size_t k) { return c[r * n + k]; };
    for (std::size_t r = 0; r < n; ++r)
      for (std::size_t k = r + 1; k < n; ++k)
        if (std::fabs(entry(r, k) - entry(k, r)) >
            kSymmetryTolerance * std::max(1.0, std::max(std::fabs(entry(r, k)), std::fabs(entry(k, r)))))
          throw ConfigError("noise.covariance",
                            "got a matrix that is not symmetric: entry (" + std::to_string(r) + "," +
                                std::to_string(k) + ") = " + format_number(entry(r, k)) + " but (" +
                                std::to_string(k) + "," + std::to_string(r) + ") = " + format_number(entry(k, r)) +
                                "; expected a symmetric positive definite " + n_text + "x" + n_text +
                                " matrix, row-major");
    // The same factorization the noise model computes its masses with.
    if (!cholesky_factor(c, n))
      throw ConfigError("noise.covariance", "got " + format_list(c) +
                                                ", which is not positive definite (Cholesky failed); expected a "
                                                "symmetric positive definite " + n_text + "x" + n_text +
                                                " matrix, row-major, or " + n_text + " positive variances");
  }
}

void check_uniform(const NoiseConfig& noise, std::size_t n) {
  const std::string n_text = std::to_string(n);
  const std::string example = "half_width: [" + n_text + " positive numbers]";
  if (noise.half_width.size() != n)
    fail("noise.half_width", std::to_string(noise.half_width.size()) + " values", n_text + " values (one per state)",
         example);
  check_finite_list(noise.half_width, "noise.half_width", example);
  for (std::size_t i = 0; i < n; ++i)
    if (noise.half_width[i] <= 0)
      fail(indexed("noise.half_width", i), format_number(noise.half_width[i]), "a number > 0", example);
}

void check_truncation(const NoiseConfig& noise, std::size_t n) {
  const std::string n_text = std::to_string(n);
  if (noise.cutting_probability && noise.truncation != Truncation::CuttingProbability)
    throw ConfigError("noise.cutting_probability", "given but noise.truncation is " + to_string(noise.truncation) +
                                                       "; set truncation: cutting_probability to use it");
  const double gamma = noise.cutting_probability_or_default();
  if (!(gamma > 0 && gamma < 1))
    fail("noise.cutting_probability", format_number(gamma), "a probability in (0, 1)", "cutting_probability: 1.0e-3");
  if (noise.truncation == Truncation::FixedRegion) {
    const std::string example = "fixed_region: [" + n_text + " half-widths in state units]";
    if (noise.fixed_region.size() != n)
      fail("noise.fixed_region", std::to_string(noise.fixed_region.size()) + " values",
           n_text + " values (one per state)", example);
    check_finite_list(noise.fixed_region, "noise.fixed_region", example);
    for (std::size_t i = 0; i < n; ++i)
      if (noise.fixed_region[i] <= 0)
        fail(indexed("noise.fixed_region", i), format_number(noise.fixed_region[i]), "a number > 0", example);
  } else if (!noise.fixed_region.empty()) {
    throw ConfigError("noise.fixed_region", "given but noise.truncation is " + to_string(noise.truncation) +
                                                "; set truncation: fixed_region to use it");
  }
}

}  // namespace

void check_noise(const NoiseConfig& noise, std::size_t n, const std::map<std::string, double>& constants) {
  check_keys_of_distribution(noise);
  if (noise.distribution == Distribution::Normal)
    check_normal(noise, n);
  else if (noise.distribution == Distribution::Uniform)
    check_uniform(noise, n);
  else
    check_law_noise(noise, n, constants);
  check_truncation(noise, n);
}


}  // namespace amytiss::detail
