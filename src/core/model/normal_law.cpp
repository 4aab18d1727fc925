#include "model/normal_law.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "amytiss/format.hpp"
#include "amytiss/noise.hpp"

namespace amytiss {
namespace detail {

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n from the Chebyshev guesses).
void gauss_legendre(std::size_t order, std::vector<double>& nodes, std::vector<double>& weights) {
  nodes.assign(order, 0.0);
  weights.assign(order, 0.0);
  const double n = double(order);
  for (std::size_t i = 0; i < (order + 1) / 2; ++i) {
    double x = std::cos(M_PI * (double(i) + 0.75) / (n + 0.5));
    double derivative = 0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0, p1 = x;
      for (std::size_t k = 2; k <= order; ++k) {
        const double p2 = ((2.0 * double(k) - 1.0) * x * p1 - (double(k) - 1.0) * p0) / double(k);
        p0 = p1;
        p1 = p2;
      }
      if (order == 1) p0 = 1.0;
      derivative = n * (x * p1 - p0) / (x * x - 1.0);
      const double step = p1 / derivative;
      x -= step;
      if (std::fabs(step) < 1e-16) break;
    }
    // Re-evaluate the derivative at the converged node for the weight.
    double p0 = 1.0, p1 = x;
    for (std::size_t k = 2; k <= order; ++k) {
      const double p2 = ((2.0 * double(k) - 1.0) * x * p1 - (double(k) - 1.0) * p0) / double(k);
      p0 = p1;
      p1 = p2;
    }
    derivative = n * (x * p1 - p0) / (x * x - 1.0);
    nodes[i] = -x;
    nodes[order - 1 - i] = x;
    weights[i] = weights[order - 1 - i] = 2.0 / ((1.0 - x * x) * derivative * derivative);
  }
}

}  // namespace detail

std::optional<std::vector<double>> cholesky_factor(const std::vector<double>& matrix, std::size_t n) {
  std::vector<double> factor(n * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j <= i; ++j) {
      double sum = matrix.at(i * n + j);
      for (std::size_t k = 0; k < j; ++k) sum -= factor[i * n + k] * factor[j * n + k];
      if (i == j) {
        // A non-positive (or NaN) pivot means the matrix is not positive definite.
        if (!(sum > 0)) return std::nullopt;
        factor[i * n + i] = std::sqrt(sum);
      } else {
        factor[i * n + j] = sum / factor[j * n + j];
      }
    }
  }
  return factor;
}

double normal_upper_quantile(double p) {
  if (!(p > 0.0 && p <= 0.5))
    throw std::invalid_argument("normal_upper_quantile: p = " + format_number(p) + ", expected 0 < p <= 0.5");
  // Acklam's rational approximation of the lower quantile x = Phi^{-1}(p) (relative error
  // 1.15e-9), then one Halley step on erfc; z = -x.
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01,  -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  constexpr double kLowRegion = 0.02425;
  double x;
  if (p < kLowRegion) {
    const double q = std::sqrt(-2.0 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else {
    const double q = p - 0.5;
    const double r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  }
  for (int refinement = 0; refinement < 2; ++refinement) {
    const double error = 0.5 * std::erfc(-x / detail::kSqrt2) - p;
    const double u = error * std::sqrt(2.0 * M_PI) * std::exp(0.5 * x * x);
    x = x - u / (1.0 + 0.5 * x * u);
  }
  return -x;
}

}  // namespace amytiss
