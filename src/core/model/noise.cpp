#include "amytiss/noise.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "amytiss/errors.hpp"
#include "amytiss/format.hpp"
#include "model/noise_laws.hpp"

namespace amytiss {
namespace {

constexpr double kSqrt2 = 1.41421356237309504880;
constexpr double kInvSqrt2Pi = 0.39894228040143267794;
// Beyond |z| = 9 a standard normal has mass 2*Q(9) < 2.3e-19: the quadrature clips there.
constexpr double kQuadratureClipZ = 9.0;
constexpr double kQuadratureClipMass = 2.3e-19;
// Largest window half width kept as an integer; any real grid is smaller.
constexpr double kMaxHalfCells = 1e15;

// Upper tail Q(z) = 1 - Phi(z) through erfc, accurate in relative terms for large z.
double upper_tail(double z) { return 0.5 * std::erfc(z / kSqrt2); }

// Phi(b) - Phi(a) for a <= b, using the tail on the side away from the mean so that tiny masses
// keep their relative precision.
double standard_normal_interval(double a, double b) {
  if (!(a < b)) return 0.0;
  if (a >= 0) return upper_tail(a) - upper_tail(b);
  if (b <= 0) return upper_tail(-b) - upper_tail(-a);
  return 1.0 - upper_tail(b) - upper_tail(-a);
}

double standard_normal_pdf(double z) { return kInvSqrt2Pi * std::exp(-0.5 * z * z); }

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

// The constructor's input passed Config::validate(); a violation is a bug of the caller.
void require(bool invariant, const char* what) {
  if (!invariant) throw std::logic_error(std::string("NoiseModel: expected a validated configuration: ") + what);
}

}  // namespace

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
    const double error = 0.5 * std::erfc(-x / kSqrt2) - p;
    const double u = error * std::sqrt(2.0 * M_PI) * std::exp(0.5 * x * x);
    x = x - u / (1.0 + 0.5 * x * u);
  }
  return -x;
}

NoiseModel::NoiseModel(const NoiseConfig& config, const Grid& states, const std::map<std::string, double>& constants)
    : dims_(states.dims()),
      type_(config.type),
      distribution_(config.distribution),
      lb_(states.lb()),
      eta_(states.eta()),
      counts_(states.counts()),
      grid_size_(states.size()) {
  const std::size_t n = dims_;
  if (distribution_ == Distribution::Normal) {
    const auto& cov = config.covariance;
    require(cov.size() == n || cov.size() == n * n, "covariance of n or n*n values");
    covariance_.assign(n * n, 0.0);
    // The diagonal form (n values) may give a variance of exactly 0: that dimension has no noise
    // (a point mass). A full matrix is positive definite for the conditioning quadrature.
    const bool diagonal_form = cov.size() == n;
    if (diagonal_form) {
      for (std::size_t i = 0; i < n; ++i) {
        require(cov[i] >= 0, "variances >= 0");
        covariance_[i * n + i] = cov[i];
      }
      cholesky_.assign(n * n, 0.0);
      for (std::size_t i = 0; i < n; ++i) cholesky_[i * n + i] = std::sqrt(covariance_[i * n + i]);
    } else {
      covariance_ = cov;
      auto factor = cholesky_factor(covariance_, n);
      require(factor.has_value(), "a positive definite covariance");
      cholesky_ = std::move(*factor);
    }
    separable_ = true;
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j)
        if (i != j && covariance_[i * n + j] != 0.0) separable_ = false;
    base_scale_.resize(n);
    for (std::size_t i = 0; i < n; ++i) base_scale_[i] = std::sqrt(covariance_[i * n + i]);
    require(separable_ || (type_ == NoiseType::Additive && n <= kMaxFullCovarianceDims),
            "a full covariance only with additive noise and at most kMaxFullCovarianceDims dimensions");
  } else if (distribution_ == Distribution::Uniform) {
    require(config.half_width.size() == n, "one half-width per dimension");
    for (std::size_t i = 0; i < n; ++i) require(config.half_width[i] > 0, "positive half-widths");
    base_scale_ = config.half_width;
    separable_ = true;
  } else {
    // noise_i = scale * Z_i with the unit law of Z_i (model/noise_laws.hpp).
    for (std::size_t i = 0; i < n; ++i) laws_.push_back(std::make_shared<detail::UnitLaw>(detail::unit_law(config, i, constants)));
    base_scale_.assign(n, 1.0);
    separable_ = true;
  }
  window_offset_.assign(n, 0.0);

  // The largest scale per dimension over the grid bounds the window for every current state.
  std::vector<double> largest_scale(n);
  for (std::size_t i = 0; i < n; ++i) {
    double factor = 1.0;
    if (type_ == NoiseType::Multiplicative)
      factor = std::max(std::fabs(lb_[i]), std::fabs(states.coordinate(i, counts_[i] - 1)));
    largest_scale[i] = base_scale_[i] * factor;
  }

  window_half_cells_.assign(n, 0);
  whole_grid_dims_.assign(n, 0);
  cut_mass_bound_ = 0.0;
  auto set_half = [&](std::size_t i, double half_cells) {
    window_half_cells_[i] = static_cast<std::int64_t>(std::min(half_cells, kMaxHalfCells));
  };
  switch (config.truncation) {
    case Truncation::None:
      for (std::size_t i = 0; i < n; ++i) {
        window_half_cells_[i] = std::int64_t(counts_[i]) - 1;
        whole_grid_dims_[i] = 1;
      }
      break;
    case Truncation::FixedRegion: {
      require(config.fixed_region.size() == n, "one fixed_region half-width per dimension");
      double cut = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        const double region = config.fixed_region[i];
        require(std::isfinite(region) && region > 0, "positive fixed_region half-widths");
        set_half(i, std::floor(region / eta_[i] + 1e-9));
        // The window contains [mu - h*eta, mu + h*eta] (|mu - nearest point| <= eta/2).
        const double kept = double(window_half_cells_[i]) * eta_[i];
        if (largest_scale[i] > 0) {
          if (distribution_ == Distribution::Normal)
            cut += 2.0 * upper_tail(kept / largest_scale[i]);
          else if (distribution_ == Distribution::Uniform)
            cut += std::max(0.0, 1.0 - kept / largest_scale[i]);
          else  // P(|s Z| > kept) grows with s: the largest scale bounds every state's cut.
            cut += std::max(0.0, 1.0 - laws_[i]->mass(-kept / largest_scale[i], kept / largest_scale[i]));
        }
      }
      cut_mass_bound_ = std::min(1.0, cut);
      break;
    }
    case Truncation::CuttingProbability: {
      const double gamma = config.cutting_probability_or_default();
      require(gamma > 0 && gamma < 1, "a cutting probability in (0, 1)");
      if (distribution_ == Distribution::Normal) {
        // Union bound over dimensions: each may lose gamma/n, split over both tails.
        const double z = normal_upper_quantile(gamma / (2.0 * double(std::max<std::size_t>(n, 1))));
        double cut = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
          set_half(i, std::ceil(z * largest_scale[i] / eta_[i]));
          if (largest_scale[i] > 0)
            cut += 2.0 * upper_tail(double(window_half_cells_[i]) * eta_[i] / largest_scale[i]);
        }
        cut_mass_bound_ = std::min(gamma, cut);
      } else if (!laws_.empty()) {
        // The kept interval [zlo, zhi] of Z: the exponential's upper tail beyond it has mass
        // exp(-rate*ln(n/gamma)/rate) = gamma/n; beta and custom keep their whole support.
        double cut = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
          const detail::UnitLaw& law = *laws_[i];
          double zlo = law.lo, zhi = law.hi;
          if (law.distribution == Distribution::Exponential) {
            zhi = law.shift + std::log(double(std::max<std::size_t>(n, 1)) / gamma) / law.rate;
            if (largest_scale[i] > 0) cut += gamma / double(std::max<std::size_t>(n, 1));
          }
          if (type_ == NoiseType::Additive) {
            window_offset_[i] = 0.5 * (zlo + zhi);
            set_half(i, std::ceil(0.5 * (zhi - zlo) / eta_[i]));
          } else {
            set_half(i, std::ceil(std::max(std::fabs(zlo), std::fabs(zhi)) * largest_scale[i] / eta_[i]));
          }
        }
        cut_mass_bound_ = std::min(gamma, cut);
      } else {
        // The window covers the whole support of the uniform law: nothing is cut.
        for (std::size_t i = 0; i < n; ++i) set_half(i, std::ceil(largest_scale[i] / eta_[i]));
        cut_mass_bound_ = 0.0;
      }
      break;
    }
  }
  // A dimension without noise anywhere on the grid puts all its mass in one cell (the one
  // containing the post state): its window is that cell, whatever the truncation mode.
  for (std::size_t i = 0; i < n; ++i) {
    if (largest_scale[i] == 0.0) {
      window_half_cells_[i] = 0;
      whole_grid_dims_[i] = 0;
      window_offset_[i] = 0.0;
    }
  }
  if (distribution_ == Distribution::Custom) {
    // Each cell mass within kCustomMassTolerance, the normalization within 1e-15 relative: the
    // row's l1 error is at most prod_i (1 + E_i) - 1 with E_i the dimension's summed mass error.
    double product = 1.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double cells = std::min<double>(double(2 * window_half_cells_[i] + 1), double(counts_[i]));
      product *= 1.0 + cells * detail::UnitLaw::kCustomMassTolerance + 1e-15;
    }
    quadrature_error_bound_ = product - 1.0;
  }

  if (!separable_) {
    gauss_legendre(kGaussLegendreOrder, legendre_nodes_, legendre_weights_);
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
    gauss_legendre(2 * kGaussLegendreOrder, fine_nodes, fine_weights);
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
}

double NoiseModel::scale(std::size_t dim, const double* x) const {
  if (type_ == NoiseType::Multiplicative) return base_scale_[dim] * std::fabs(x[dim]);
  return base_scale_[dim];
}

std::size_t NoiseModel::window_cells() const {
  std::size_t cells = 1;
  for (std::size_t i = 0; i < dims_; ++i) {
    const std::size_t span = std::min<std::size_t>(std::size_t(2 * window_half_cells_[i] + 1), counts_[i]);
    cells *= span;
  }
  return std::min(cells, grid_size_);
}

std::pair<double, double> NoiseModel::unit_support(std::size_t dim) const {
  if (distribution_ == Distribution::Normal)
    return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  if (laws_.empty()) return {-1.0, 1.0};  // uniform: the half-width is the scale
  return {laws_[dim]->lo, laws_[dim]->hi};
}

double NoiseModel::interval_mass(std::size_t dim, double lo, double hi, double mean, double scale) const {
  if (!(lo < hi)) return 0.0;
  if (scale == 0.0) return (lo <= mean && mean < hi) ? 1.0 : 0.0;
  if (distribution_ == Distribution::Normal)
    return standard_normal_interval((lo - mean) / scale, (hi - mean) / scale);
  if (!laws_.empty()) return laws_[dim]->mass((lo - mean) / scale, (hi - mean) / scale);
  const double overlap = std::min(hi, mean + scale) - std::max(lo, mean - scale);
  return overlap > 0 ? std::min(1.0, overlap / (2.0 * scale)) : 0.0;
}

double NoiseModel::cell_mass(std::size_t dim, std::size_t k, double mean, double scale) const {
  // lb + (k +- 1/2)*eta: neighbouring cells share the exact same bound.
  const double lo = lb_[dim] + (double(k) - 0.5) * eta_[dim];
  const double hi = lb_[dim] + (double(k) + 0.5) * eta_[dim];
  return interval_mass(dim, lo, hi, mean, scale);
}

void NoiseModel::cell_masses(std::size_t dim, std::int64_t first, std::int64_t last, double mean, double scale,
                             double* out) const {
  if (distribution_ != Distribution::Normal || scale == 0.0 || last < first) {
    for (std::int64_t k = first; k <= last; ++k) out[k - first] = cell_mass(dim, std::size_t(k), mean, scale);
    return;
  }
  // Each face is shared by two cells (lb + (k + 1/2)*eta == lb + ((k+1) - 1/2)*eta exactly for
  // integer k), so its standardized position z and tail Q(|z|) are computed once. Every cell then
  // takes exactly the branch and the operands of standard_normal_interval: bit-identical masses.
  thread_local std::vector<double> z, tail;
  const std::size_t faces = std::size_t(last - first) + 2;
  z.resize(faces);
  tail.resize(faces);
  for (std::size_t f = 0; f < faces; ++f) {
    const double face = lb_[dim] + (double(first + std::int64_t(f)) - 0.5) * eta_[dim];
    z[f] = (face - mean) / scale;
    tail[f] = upper_tail(z[f] >= 0 ? z[f] : -z[f]);
  }
  for (std::size_t c = 0; c + 1 < faces; ++c) {
    const double a = z[c], b = z[c + 1];
    double mass;
    if (!(a < b)) mass = 0.0;
    else if (a >= 0) mass = tail[c] - tail[c + 1];
    else if (b <= 0) mass = tail[c + 1] - tail[c];
    else mass = 1.0 - tail[c + 1] - tail[c];
    out[c] = mass;
  }
}

double NoiseModel::box_mass(const double* lo, const double* hi, const double* mean) const {
  if (separable_) {
    double mass = 1.0;
    for (std::size_t i = 0; i < dims_ && mass > 0; ++i)
      mass *= interval_mass(i, lo[i], hi[i], mean[i], base_scale_[i]);
    return mass;
  }
  return box_mass_with(lo, hi, mean, legendre_nodes_, legendre_weights_);
}

namespace {

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

bool NoiseModel::window(const Grid& states, const double* mean, std::int64_t* first, std::int64_t* last) const {
  for (std::size_t i = 0; i < dims_; ++i)
    if (!dimension_window(states, i, mean[i], first + i, last + i)) return false;
  return true;
}

bool NoiseModel::dimension_window(const Grid& states, std::size_t dim, double mean, std::int64_t* first,
                                  std::int64_t* last) const {
  const auto count = static_cast<std::int64_t>(counts_[dim]);
  if (whole_grid_dims_[dim]) {
    *first = 0;
    *last = count - 1;
    return true;
  }
  // A non-finite post state carries no mass onto the grid.
  if (!std::isfinite(mean)) return false;
  const std::int64_t center = states.nearest(dim, mean + window_offset_[dim]);
  const std::int64_t half = window_half_cells_[dim];
  if (center - half > count - 1 || center + half < 0) return false;
  *first = std::max<std::int64_t>(0, center - half);
  *last = std::min<std::int64_t>(count - 1, center + half);
  return true;
}

double NoiseModel::transition_probability(const Grid& states, std::size_t target, const double* mean,
                                          const double* x) const {
  std::int64_t first[64], last[64];
  std::size_t multi[64];
  if (dims_ > 64) throw std::logic_error("transition_probability: more than 64 state dimensions");
  if (!window(states, mean, first, last)) return 0.0;
  states.multi_index(target, multi);
  for (std::size_t i = 0; i < dims_; ++i)
    if (std::int64_t(multi[i]) < first[i] || std::int64_t(multi[i]) > last[i]) return 0.0;
  if (separable_) {
    double probability = 1.0;
    for (std::size_t i = 0; i < dims_ && probability > 0; ++i)
      probability *= cell_mass(i, multi[i], mean[i], scale(i, x));
    return probability;
  }
  double lo[kMaxFullCovarianceDims], hi[kMaxFullCovarianceDims];
  for (std::size_t i = 0; i < dims_; ++i) {
    lo[i] = lb_[i] + (double(multi[i]) - 0.5) * eta_[i];
    hi[i] = lb_[i] + (double(multi[i]) + 0.5) * eta_[i];
  }
  return box_mass(lo, hi, mean);
}

}  // namespace amytiss
