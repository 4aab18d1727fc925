#pragma once
// Noise and exact transition probabilities (docs/semantics.md).
//
// T(x' | x,u,w) = P( f(x,u,w) + noise in cell(x') ), cell(x') = [x' - eta/2, x' + eta/2] (or the
// cell's faces, for a dimension given by them).
// Separable noise (normal with diagonal covariance, uniform) gives T as a product of
// one-dimensional cell masses, each computed exactly (erfc for normal). Full covariance uses
// box_mass() (see its comment for the method and error bound).
//
// Truncation window: for a post mean mu, the kept cells along dimension i are the indices
//   nearest_i(mu) - h_i .. nearest_i(mu) + h_i      (clipped to the grid)
// with h_i = window_half_cells()[i]:
//   none:                h_i = n_i - 1 (the whole grid, whatever mu);
//   fixed_region r:      h_i = floor(r_i/eta_i + 1e-9)  (the AMYTISS convention: a region of
//                        2h+1 cells; BMW paper grid: 1*1*5*5*3*3*3 = 675 cells);
//   cutting_probability gamma (normal): h_i = ceil(z*s_i/eta_i) with 2*(1 - Phi(z)) = gamma/n
//                        and s_i the largest standard deviation of dimension i. The window
//                        contains [mu - h_i*eta_i, mu + h_i*eta_i] because |mu - nearest| <=
//                        eta/2, so the cut mass per transition is at most gamma (union bound).
//   uniform:             h_i = ceil(a_i*s/eta_i) covers the whole support: nothing is cut.
// Exponential, beta and custom noise (noise_i = s_i * Z_i, s_i = 1 additive, |x_i| multiplicative)
// keep an interval [zlo_i, zhi_i] of Z_i: cutting_probability gamma keeps, for the exponential,
// [shift_i, shift_i + ln(n/gamma)/rate_i] (exactly gamma/n cut per dimension), for beta and custom
// the whole support (nothing cut). Additive: the window is centred on the kept interval's centre,
// nearest_i(mu + (zlo_i + zhi_i)/2) +- ceil((zhi_i - zlo_i)/(2 eta_i)); multiplicative: centred on
// nearest_i(mu), h_i = ceil(max(|zlo_i|, |zhi_i|) * max|x_i| / eta_i). fixed_region r cuts at most
// sum_i (1 - P(|s_i Z_i| <= h_i eta_i)) with s_i the largest scale.
// A state dimension given by its faces keeps, instead of nearest +- h, the cells that meet
// [c - R_i, c + R_i], c = mu + offset_i, with the kept radius R_i (window_radius()) in state units:
// fixed_region r_i; cutting_probability z*s_i (normal), the kept interval's half-width (additive
// exponential/beta/custom) or max(|zlo_i|, |zhi_i|) * max|x_i| (multiplicative); uniform a_i*s.
// h_i is then the most cells such a window reaches on either side of the cell containing c
// (clamped to the grid), so the window still lies in clamp(cell(c)) +- h_i.
// Cells outside the window get probability 0, so every value computed is a lower bound.
// Multiplicative noise: noise_i scales with |x_i| of the current state (diagonal only).
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/grid.hpp"

namespace amytiss {

namespace detail {
struct UnitLaw;
}

class NoiseModel {
 public:
  static constexpr std::size_t kMaxFullCovarianceDims = 4;
  static constexpr std::size_t kGaussLegendreOrder = 8;

  /// `config` must have passed Config::validate() for these states (sizes, symmetric positive
  /// definite covariance, positive half-widths, truncation parameters); the constructor asserts
  /// it (std::logic_error), it does not judge user input. `constants` are those custom densities
  /// may use (the configuration's `constants`).
  NoiseModel(const NoiseConfig& config, const Grid& states, const std::map<std::string, double>& constants = {});

  std::size_t dims() const { return dims_; }
  NoiseType type() const { return type_; }
  Distribution distribution() const { return distribution_; }
  /// True when T is the product of per-dimension masses (all but a full normal covariance).
  bool separable() const { return separable_; }
  /// True for the laws whose masses the OpenCL dense sweep computes on the device (normal,
  /// uniform); the others are computed on the host only (reference engine, factored sweep).
  bool device_masses() const {
    return distribution_ == Distribution::Normal || distribution_ == Distribution::Uniform;
  }

  /// Scale of dimension `dim` at current state x: normal: standard deviation sqrt(Sigma_ii);
  /// uniform: half-width; exponential, beta, custom: 1; multiplicative: times |x[dim]|.
  double scale(std::size_t dim, const double* x) const;
  /// Base scale (the additive one): stddev or half-width per dimension.
  const std::vector<double>& base_scale() const { return base_scale_; }

  /// h_i per dimension (see above); the window has 2*h_i + 1 cells before clipping.
  const std::vector<std::int64_t>& window_half_cells() const { return window_half_cells_; }
  /// Per dimension: 1 when the window is the whole grid dimension whatever the post mean
  /// (truncation none, noise present), 0 otherwise.
  const std::vector<char>& whole_grid_dims() const { return whole_grid_dims_; }
  /// Cells in the unclipped window: product of (2h_i + 1), capped at the grid size.
  std::size_t window_cells() const;
  /// Upper bound of the probability mass a transition loses to truncation (0 for none/uniform).
  double cut_mass_bound() const { return cut_mass_bound_; }
  /// Custom densities: bound of sum_x' |T computed - T exact| per transition from the adaptive
  /// quadrature, prod_i (1 + w_i * 1e-12 + 1e-15) - 1 over the window widths w_i (each cell
  /// mass to 1e-12 by its Gauss-Kronrod estimate, the normalization to 1e-15); 0 for the laws
  /// with closed forms. An estimate-based bound (docs/semantics.md), like box_mass_tolerance().
  double quadrature_error_bound() const { return quadrature_error_bound_; }
  /// Centre offset of the window per dimension (state units): nearest_i(mu + offset_i) is its
  /// middle cell. 0 except for additive exponential/beta/custom noise with an asymmetric kept interval.
  const std::vector<double>& window_offset() const { return window_offset_; }

  /// The law of Z_dim for exponential, beta and custom noise (noise = scale * Z, model/noise_laws.hpp);
  /// nullptr for normal and uniform noise.
  const detail::UnitLaw* unit_law(std::size_t dim) const { return laws_.empty() ? nullptr : laws_[dim].get(); }
  /// Support [lo, hi] of the unit law Z_i of dimension `dim` (noise_i = scale(i, x) * Z_i, before
  /// truncation): normal (-inf, inf), uniform [-1, 1], exponential [shift, inf), beta and custom
  /// their `support`. A separable row keeps all its mass exactly when this interval, scaled and
  /// moved to the post mean, lies inside its kept cells.
  std::pair<double, double> unit_support(std::size_t dim) const;

  /// Mass of [lo, hi] under the 1-d law of dimension dim with the given mean and scale (a scale of
  /// 0 is a point mass: 1 when lo <= mean < hi). Exact (erfc), double precision.
  double interval_mass(std::size_t dim, double lo, double hi, double mean, double scale) const;
  /// Mass of the cell of grid index k along dim.
  double cell_mass(std::size_t dim, std::size_t k, double mean, double scale) const;
  /// cell_mass(dim, k, mean, scale) for k = first..last into out[k - first], bit-identical to it;
  /// each shared cell face's tail is computed once (one erfc per face instead of two per cell).
  void cell_masses(std::size_t dim, std::int64_t first, std::int64_t last, double mean, double scale,
                   double* out) const;

  /// Non-separable (full covariance) mass of the box [lo, hi] with mean `mean`. Method and error
  /// bound in model/full_covariance.cpp and docs/semantics.md ("Transition probabilities"); |error| <= box_mass_tolerance().
  /// Method: sequential conditioning x = mean + L z (L Cholesky, z standard normal), nested
  /// composite Gauss-Legendre over z_0..z_{n-2} (panel width <= 1 standard deviation, narrowed
  /// where later bounds depend steeply on z_i), exact erfc for z_{n-1}, z clipped to |z| <= 9.
  /// The tolerance is measured at construction: 10 x the largest difference between order
  /// kGaussLegendreOrder and twice that order on sample boxes (cells of this grid around random
  /// means), plus the clipped tail mass. Full covariance is supported up to
  /// kMaxFullCovarianceDims dimensions (the cost grows like (points per level)^(n-1)). For a
  /// separable model this is the exact product of interval masses.
  double box_mass(const double* lo, const double* hi, const double* mean) const;
  double box_mass_tolerance() const { return box_mass_tolerance_; }

  /// Kept radius per dimension (state units) of a dimension given by its faces (see above); 0 for
  /// a uniform one, whose window is nearest +- h.
  const std::vector<double>& window_radius() const { return window_radius_; }
  /// Clipped window for post mean `mean`: first[i]..last[i] (inclusive grid indices). Returns
  /// false when the window misses the grid in some dimension (all mass leaves the grid).
  bool window(const Grid& states, const double* mean, std::int64_t* first, std::int64_t* last) const;
  /// The same for one dimension: the window of post coordinate `mean` along `dim`.
  bool dimension_window(const Grid& states, std::size_t dim, double mean, std::int64_t* first,
                        std::int64_t* last) const;
  /// The union of dimension_window() over the post coordinates in [m_lo, m_hi] (nearest() is
  /// monotone: it is the span from m_lo's window to m_hi's). False when every window misses the grid.
  bool window_range(const Grid& states, std::size_t dim, double m_lo, double m_hi, std::int64_t* first,
                    std::int64_t* last) const;

  /// Probability T(x'|x,u,w) of the state cell `target` (flat index) for post mean `mean` from
  /// current state x (used by the reference engine and tests): 0 outside the window.
  double transition_probability(const Grid& states, std::size_t target, const double* mean,
                                const double* x) const;

 private:
  std::size_t dims_ = 0;
  NoiseType type_ = NoiseType::Additive;
  Distribution distribution_ = Distribution::Normal;
  bool separable_ = true;
  std::vector<double> base_scale_;
  std::vector<double> covariance_;       // full n*n, row-major
  std::vector<double> cholesky_;         // lower triangular, row-major (full covariance)
  std::vector<double> lb_, eta_;        // the state grid's (cell bounds lb + (k -+ 1/2)*eta)
  std::vector<std::vector<double>> faces_;  // a dimension's faces, empty for a uniform one
  std::vector<double> window_radius_;
  std::vector<std::size_t> counts_;     // the state grid's points per dimension
  std::vector<std::int64_t> window_half_cells_;
  std::vector<char> whole_grid_dims_;  // truncation none (and some noise): the whole dimension
  // Full covariance quadrature (see model/full_covariance.cpp): Gauss-Legendre nodes/weights on [-1, 1] and the
  // panel width per conditioning level in standard-normal units.
  std::vector<double> legendre_nodes_, legendre_weights_;
  std::vector<double> panel_width_;
  double box_mass_with(const double* lo, const double* hi, const double* mean,
                       const std::vector<double>& nodes, const std::vector<double>& weights) const;
  double cut_mass_bound_ = 0.0;
  double box_mass_tolerance_ = 0.0;
  double quadrature_error_bound_ = 0.0;
  std::vector<double> window_offset_;
  std::vector<std::shared_ptr<const detail::UnitLaw>> laws_;  // exponential, beta, custom
  std::size_t grid_size_ = 1;

  // Set-up steps of the constructor, one per job (model/noise.cpp, model/full_covariance.cpp).
  void set_up_normal(const NoiseConfig& config);
  void set_up_window(const NoiseConfig& config, const Grid& states);
  void set_half_cells(std::size_t dim, double half_cells);
  void set_radius(std::size_t dim, double radius);
  double face(std::size_t dim, std::int64_t k) const {
    return faces_[dim].empty() ? lb_[dim] + (double(k) - 0.5) * eta_[dim] : faces_[dim][std::size_t(k)];
  }
  void set_up_fixed_region(const NoiseConfig& config, const std::vector<double>& largest_scale);
  void set_up_cutting_probability(const NoiseConfig& config, const std::vector<double>& largest_scale);
  void set_up_custom_error_bound();
  void set_up_full_covariance(const Grid& states);
};

/// Lower-triangular Cholesky factor L (row-major n*n, matrix = L L^T) of a symmetric n*n matrix
/// (row-major, only its lower triangle is read); nothing when the matrix is not positive
/// definite (a pivot <= 0). Config::validate() refuses such a covariance with this same function.
std::optional<std::vector<double>> cholesky_factor(const std::vector<double>& matrix, std::size_t n);
/// Standard normal upper tail quantile: z with 1 - Phi(z) = p, for p in (0, 0.5].
double normal_upper_quantile(double p);

}  // namespace amytiss
