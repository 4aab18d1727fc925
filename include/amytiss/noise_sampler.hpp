#pragma once
// Concrete noise for closed-loop simulation, drawn from the same noise description the
// abstraction computes its probabilities with (docs/semantics.md, "Drawing concrete noise"): every
// law the configuration accepts, additive or multiplicative.
//   normal:       Z = L z, z standard normal, L the Cholesky factor of the covariance (diagonal:
//                 the standard deviations);
//   uniform:      Z_i = h_i * U(-1, 1);
//   exponential:  Z_i = shift_i + Exp(rate_i);
//   beta:         Z_i = lb_i + (ub_i - lb_i) * Beta(alpha_i, beta_i) (as X / (X + Y) of two gammas);
//   custom:       Z_i by inverting the CDF of the normalized density on its support, with the
//                 masses the abstraction uses (adaptive quadrature, each to 1e-12).
// The noise added to the post state is Z (additive) or |x_i| * Z_i (multiplicative), in state units.
#include <cstddef>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "amytiss/config.hpp"

namespace amytiss {

namespace detail {
struct UnitLaw;
}

class NoiseSampler {
 public:
  /// `noise` must have passed Config::validate() for `dims` state dimensions; a violation is a
  /// bug of the caller (std::logic_error). `constants` are those custom densities may use.
  NoiseSampler(const NoiseConfig& noise, std::size_t dims, const std::map<std::string, double>& constants = {});
  ~NoiseSampler();

  std::size_t dims() const { return dims_; }
  /// One noise vector (dims() values, state units) for the current state x[0..dims()), drawn with
  /// `random`: the same seed gives the same draws.
  std::vector<double> draw(const double* x, std::mt19937_64& random) const;

 private:
  std::size_t dims_ = 0;
  NoiseConfig noise_;
  std::vector<double> factor_;  // normal: lower-triangular n*n, row-major; uniform: half-widths on the diagonal
  std::vector<std::shared_ptr<const detail::UnitLaw>> laws_;  // exponential, beta, custom
  std::vector<std::vector<double>> cumulative_;  // custom: the CDF at kCdfPieces + 1 evenly spaced points

  std::vector<double> standard_draws(std::mt19937_64& random) const;
  double unit_draw(std::size_t dim, std::mt19937_64& random) const;
  double custom_draw(std::size_t dim, double probability) const;
};

}  // namespace amytiss
