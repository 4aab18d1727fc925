#pragma once
// The standard normal law as the noise model computes with it: tails through erfc, interval masses
// that keep tiny masses' relative precision, the density, and Gauss-Legendre rules for the full
// covariance quadrature. Internal to the core; cholesky_factor() and normal_upper_quantile() are
// public (amytiss/noise.hpp).
#include <cmath>
#include <cstddef>
#include <vector>

namespace amytiss::detail {

constexpr double kSqrt2 = 1.41421356237309504880;
constexpr double kInvSqrt2Pi = 0.39894228040143267794;

// Upper tail Q(z) = 1 - Phi(z) through erfc, accurate in relative terms for large z.
inline double upper_tail(double z) { return 0.5 * std::erfc(z / kSqrt2); }

// Phi(b) - Phi(a) for a <= b, using the tail on the side away from the mean so that tiny masses
// keep their relative precision.
inline double standard_normal_interval(double a, double b) {
  if (!(a < b)) return 0.0;
  if (a >= 0) return upper_tail(a) - upper_tail(b);
  if (b <= 0) return upper_tail(-b) - upper_tail(-a);
  return 1.0 - upper_tail(b) - upper_tail(-a);
}

inline double standard_normal_pdf(double z) { return kInvSqrt2Pi * std::exp(-0.5 * z * z); }

/// Gauss-Legendre nodes and weights of the given order on [-1, 1].
void gauss_legendre(std::size_t order, std::vector<double>& nodes, std::vector<double>& weights);

}  // namespace amytiss::detail
