#pragma once
// One-dimensional noise laws beyond the normal and the uniform (docs/semantics.md, "Transition
// probabilities"): the exponential and the beta with closed-form CDFs, and a user density of z
// integrated by adaptive Gauss-Kronrod quadrature. Internal to the core (NoiseModel and
// Config::validate() use it).
#include <functional>
#include <memory>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/expression.hpp"

namespace amytiss::detail {

/// Regularized incomplete beta function I_x(a, b) for x in [0, 1], a, b > 0 (continued fraction,
/// modified Lentz; relative accuracy about 1e-14), and its complement 1 - I_x(a, b) computed
/// without cancellation.
double incomplete_beta(double x, double a, double b);
double incomplete_beta_complement(double x, double a, double b);

/// Integral of f over [a, b] by adaptive Gauss-Kronrod (7-point Gauss inside the 15-point
/// Kronrod rule), bisecting until each piece's |K15 - G7| is at most its share (width / (b - a))
/// of `tolerance`. `error` is the sum of the pieces' |K15 - G7|: an estimate (the Kronrod value is
/// far more accurate than the Gauss value it is compared with), not a proof.
struct Quadrature {
  double value = 0;
  double error = 0;
};
Quadrature integrate_adaptive(const std::function<double(double)>& f, double a, double b, double tolerance);

/// The law of Z for one dimension, noise = scale * Z (additive: scale 1).
///   exponential: Z = shift + Exp(rate);  beta: Z = lo + (hi - lo) * Beta(alpha, beta);
///   custom: density(z) / normalization on [lo, hi].
struct UnitLaw {
  /// Absolute error target of a custom law's quadrature per interval mass.
  static constexpr double kCustomMassTolerance = 1e-12;

  Distribution distribution = Distribution::Exponential;
  double rate = 1, shift = 0;
  double alpha = 1, beta = 1;
  double lo = 0, hi = 1;  ///< support of Z (exponential: lo = shift, hi = +infinity)
  std::shared_ptr<const Expression> density;
  double normalization = 1;  ///< custom: the density's integral over [lo, hi]

  /// P(a <= Z <= b) for a <= b.
  double mass(double a, double b) const;
};

/// The law of dimension `dim` of a noise configuration of a non-normal, non-uniform
/// distribution that Config::validate() accepted (custom densities parsed with `constants`).
UnitLaw unit_law(const NoiseConfig& noise, std::size_t dim, const std::map<std::string, double>& constants);

/// A custom density checked on its support: the smallest value on kDensitySamples evenly spaced
/// points (with both ends), whether every sample is finite, and its integral with error.
struct DensityCheck {
  static constexpr int kDensitySamples = 2001;
  double smallest = 0;
  double smallest_at = 0;
  bool finite = true;
  double nonfinite_at = 0;
  Quadrature integral;
};
DensityCheck check_density(const Expression& density, double lo, double hi);

}  // namespace amytiss::detail
