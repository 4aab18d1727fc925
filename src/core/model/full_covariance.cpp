// The full covariance quadrature of NoiseModel (method and error bound in amytiss/noise.hpp,
// box_mass(), and docs/semantics.md): nested Gauss-Legendre over the conditioned normal, and the
// measurement of its tolerance at construction.
#include <algorithm>
#include <cmath>
#include <random>

#include "amytiss/noise.hpp"
#include "model/normal_law.hpp"

namespace amytiss {
namespace {

using detail::standard_normal_interval;
using detail::standard_normal_pdf;

// Beyond |z| = 9 a standard normal has mass 2*Q(9) < 2.3e-19: the quadrature clips there.
constexpr double kQuadratureClipZ = 9.0;
constexpr double kQuadratureClipMass = 2.3e-19;

struct NestedQuadrature {
  std::size_t n;
  const double* cholesky;
  const double* lo;
  const double* hi;
  const double* mean;
  const double* panel_width;
  const std::vector<double>* nodes;
  const std::vector<double>* weights;
  double z[NoiseModel::kMaxFullCovarianceDims];

  // Integral over z_level.. of the standard normal density under the box constraints, given
  // z_0..z_{level-1}.
  double integrate(std::size_t level) {
    double shift = 0.0;
    for (std::size_t j = 0; j < level; ++j) shift += cholesky[level * n + j] * z[j];
    const double pivot = cholesky[level * n + level];
    double a = (lo[level] - mean[level] - shift) / pivot;
    double b = (hi[level] - mean[level] - shift) / pivot;
    // n <= kMaxFullCovarianceDims, so the second test only tells the compiler the array bound.
    if (level + 1 >= n || level + 1 >= NoiseModel::kMaxFullCovarianceDims) return standard_normal_interval(a, b);
    a = std::max(a, -kQuadratureClipZ);
    b = std::min(b, kQuadratureClipZ);
    if (!(a < b)) return 0.0;
    const std::size_t panels = std::size_t(std::ceil((b - a) / panel_width[level]));
    const double width = (b - a) / double(panels);
    double total = 0.0;
    for (std::size_t panel = 0; panel < panels; ++panel) {
      const double center = a + (double(panel) + 0.5) * width;
      double panel_sum = 0.0;
      for (std::size_t q = 0; q < nodes->size(); ++q) {
        z[level] = center + 0.5 * width * (*nodes)[q];
        panel_sum += (*weights)[q] * standard_normal_pdf(z[level]) * integrate(level + 1);
      }
      total += 0.5 * width * panel_sum;
    }
    return total;
  }
};

}  // namespace

double NoiseModel::box_mass_with(const double* lo, const double* hi, const double* mean,
                                 const std::vector<double>& nodes, const std::vector<double>& weights) const {
  NestedQuadrature quadrature{dims_, cholesky_.data(), lo, hi, mean, panel_width_.data(), &nodes, &weights, {}};
  const double mass = quadrature.integrate(0);
  return std::min(1.0, std::max(0.0, mass));
}

void NoiseModel::set_up_full_covariance(const Grid& states) {
  const std::size_t n = dims_;
  detail::gauss_legendre(kGaussLegendreOrder, legendre_nodes_, legendre_weights_);
  // Level i's integrand depends on z_i through the later bounds with slopes L_ki / L_kk: a
  // panel spans at most one unit of that variation.
  panel_width_.assign(n, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    double sensitivity = 1.0;
    for (std::size_t k = i + 1; k < n; ++k)
      sensitivity = std::max(sensitivity, std::fabs(cholesky_[k * n + i]) / cholesky_[k * n + k]);
    panel_width_[i] = 1.0 / sensitivity;
  }
  // Measured bound: order q against 2q on cells around random means (fixed seed).
  std::vector<double> fine_nodes, fine_weights;
  detail::gauss_legendre(2 * kGaussLegendreOrder, fine_nodes, fine_weights);
  std::mt19937_64 generator(20200721);
  std::vector<double> mean(n), lo(n), hi(n);
  double largest_difference = 0.0;
  constexpr int kSampleMeans = 6;
  for (int sample = 0; sample < kSampleMeans; ++sample) {
    for (std::size_t i = 0; i < n; ++i) {
      std::uniform_real_distribution<double> offset(-0.5 * eta_[i], 0.5 * eta_[i]);
      mean[i] = states.coordinate(i, counts_[i] / 2) + offset(generator);
    }
    // The cell of the mean and its neighbours at +-1 along each axis and the diagonal.
    for (int neighbour = -1; neighbour <= int(2 * n); ++neighbour) {
      for (std::size_t i = 0; i < n; ++i) {
        double shift = 0;
        if (neighbour == -1) shift = 0;
        else if (neighbour == int(2 * n)) shift = 1;
        else if (std::size_t(neighbour) / 2 == i) shift = (neighbour % 2) ? 1 : -1;
        const double center = states.coordinate(i, counts_[i] / 2) + shift * eta_[i];
        lo[i] = center - 0.5 * eta_[i];
        hi[i] = center + 0.5 * eta_[i];
      }
      const double coarse = box_mass_with(lo.data(), hi.data(), mean.data(), legendre_nodes_, legendre_weights_);
      const double fine = box_mass_with(lo.data(), hi.data(), mean.data(), fine_nodes, fine_weights);
      largest_difference = std::max(largest_difference, std::fabs(coarse - fine));
    }
  }
  box_mass_tolerance_ = 10.0 * largest_difference + double(n) * kQuadratureClipMass + 1e-15;
}

}  // namespace amytiss
