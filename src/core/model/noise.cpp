// NoiseModel: its set-up by law and truncation, and the one-dimensional masses and windows the
// engines use. The full covariance quadrature is in model/full_covariance.cpp, the normal law's
// helpers in model/normal_law.cpp.
#include "amytiss/noise.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/require.hpp"
#include "model/noise_laws.hpp"
#include "model/normal_law.hpp"

namespace amytiss {
namespace {

using detail::standard_normal_interval;
using detail::upper_tail;

// Largest window half width kept as an integer; any real grid is smaller.
constexpr double kMaxHalfCells = 1e15;

// The constructor's input passed Config::validate(); a violation is a bug of the caller.
constexpr detail::Require require{"NoiseModel: expected a validated configuration: "};

}  // namespace

NoiseModel::NoiseModel(const NoiseConfig& config, const Grid& states, const std::map<std::string, double>& constants)
    : dims_(states.dims()),
      type_(config.type),
      distribution_(config.distribution),
      lb_(states.lb()),
      eta_(states.eta()),
      counts_(states.counts()),
      grid_size_(states.size()) {
  const std::size_t n = dims_;
  faces_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    if (!states.uniform(i)) faces_[i] = states.faces(i);
  if (distribution_ == Distribution::Normal) {
    set_up_normal(config);
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
  set_up_window(config, states);
  if (distribution_ == Distribution::Custom) set_up_custom_error_bound();
  if (!separable_) set_up_full_covariance(states);
}

void NoiseModel::set_up_normal(const NoiseConfig& config) {
  const std::size_t n = dims_;
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
}

void NoiseModel::set_up_window(const NoiseConfig& config, const Grid& states) {
  const std::size_t n = dims_;
  window_offset_.assign(n, 0.0);
  window_radius_.assign(n, 0.0);

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
  switch (config.truncation) {
    case Truncation::None:
      for (std::size_t i = 0; i < n; ++i) {
        window_half_cells_[i] = std::int64_t(counts_[i]) - 1;
        whole_grid_dims_[i] = 1;
      }
      break;
    case Truncation::FixedRegion:
      set_up_fixed_region(config, largest_scale);
      break;
    case Truncation::CuttingProbability:
      set_up_cutting_probability(config, largest_scale);
      break;
  }
  // A dimension without noise anywhere on the grid puts all its mass in one cell (the one
  // containing the post state): its window is that cell, whatever the truncation mode.
  for (std::size_t i = 0; i < n; ++i) {
    if (largest_scale[i] == 0.0) {
      window_half_cells_[i] = 0;
      whole_grid_dims_[i] = 0;
      window_offset_[i] = 0.0;
      window_radius_[i] = 0.0;
    }
  }
}

void NoiseModel::set_half_cells(std::size_t dim, double half_cells) {
  window_half_cells_[dim] = static_cast<std::int64_t>(std::min(half_cells, kMaxHalfCells));
}

// The most cells a window of radius R reaches beyond the cell containing its centre, over every
// cell of the dimension; cells beyond the grid do not count (the window is clipped).
void NoiseModel::set_radius(std::size_t dim, double radius) {
  window_radius_[dim] = radius;
  const std::vector<double>& f = faces_[dim];
  const auto n = static_cast<std::int64_t>(f.size()) - 1;
  auto cell = [&](double v) {
    return std::clamp<std::int64_t>(std::int64_t(std::upper_bound(f.begin(), f.end(), v) - f.begin()) - 1, 0, n - 1);
  };
  std::int64_t half = 0;
  for (std::int64_t c = 0; c < n && half < n - 1; ++c)
    half = std::max({half, c - cell(f[std::size_t(c)] - radius), cell(f[std::size_t(c) + 1] + radius) - c});
  window_half_cells_[dim] = half;
}

void NoiseModel::set_up_fixed_region(const NoiseConfig& config, const std::vector<double>& largest_scale) {
  const std::size_t n = dims_;
  require(config.fixed_region.size() == n, "one fixed_region half-width per dimension");
  double cut = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double region = config.fixed_region[i];
    require(std::isfinite(region) && region > 0, "positive fixed_region half-widths");
    if (faces_[i].empty()) set_half_cells(i, std::floor(region / eta_[i] + 1e-9));
    else set_radius(i, region);
    // The window contains [mu - h*eta, mu + h*eta] (|mu - nearest point| <= eta/2), or [mu - R, mu + R].
    const double kept = faces_[i].empty() ? double(window_half_cells_[i]) * eta_[i] : region;
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
}

void NoiseModel::set_up_cutting_probability(const NoiseConfig& config, const std::vector<double>& largest_scale) {
  const std::size_t n = dims_;
  const double gamma = config.cutting_probability_or_default();
  require(gamma > 0 && gamma < 1, "a cutting probability in (0, 1)");
  if (distribution_ == Distribution::Normal) {
    // Union bound over dimensions: each may lose gamma/n, split over both tails.
    const double z = normal_upper_quantile(gamma / (2.0 * double(std::max<std::size_t>(n, 1))));
    double cut = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (faces_[i].empty()) set_half_cells(i, std::ceil(z * largest_scale[i] / eta_[i]));
      else set_radius(i, z * largest_scale[i]);
      const double kept = faces_[i].empty() ? double(window_half_cells_[i]) * eta_[i] : window_radius_[i];
      if (largest_scale[i] > 0) cut += 2.0 * upper_tail(kept / largest_scale[i]);
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
      if (type_ == NoiseType::Additive) window_offset_[i] = 0.5 * (zlo + zhi);
      const double radius = type_ == NoiseType::Additive ? 0.5 * (zhi - zlo)
                                                         : std::max(std::fabs(zlo), std::fabs(zhi)) * largest_scale[i];
      if (faces_[i].empty()) set_half_cells(i, std::ceil(radius / eta_[i]));
      else set_radius(i, radius);
    }
    cut_mass_bound_ = std::min(gamma, cut);
  } else {
    // The window covers the whole support of the uniform law: nothing is cut.
    for (std::size_t i = 0; i < n; ++i) {
      if (faces_[i].empty()) set_half_cells(i, std::ceil(largest_scale[i] / eta_[i]));
      else set_radius(i, largest_scale[i]);
    }
    cut_mass_bound_ = 0.0;
  }
}

void NoiseModel::set_up_custom_error_bound() {
  const std::size_t n = dims_;
  // Each cell mass within kCustomMassTolerance, the normalization within 1e-15 relative: the
  // row's l1 error is at most prod_i (1 + E_i) - 1 with E_i the dimension's summed mass error.
  double product = 1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double cells = std::min<double>(double(2 * window_half_cells_[i] + 1), double(counts_[i]));
    product *= 1.0 + cells * detail::UnitLaw::kCustomMassTolerance + 1e-15;
  }
  quadrature_error_bound_ = product - 1.0;
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
  if (!faces_[dim].empty()) return interval_mass(dim, faces_[dim][k], faces_[dim][k + 1], mean, scale);
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
    const double face = this->face(dim, first + std::int64_t(f));
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

bool NoiseModel::window(const Grid& states, const double* mean, std::int64_t* first, std::int64_t* last) const {
  for (std::size_t i = 0; i < dims_; ++i)
    if (!dimension_window(states, i, mean[i], first + i, last + i)) return false;
  return true;
}

bool NoiseModel::dimension_window(const Grid& states, std::size_t dim, double mean, std::int64_t* first,
                                  std::int64_t* last) const {
  return window_range(states, dim, mean, mean, first, last);
}

bool NoiseModel::window_range(const Grid& states, std::size_t dim, double m_lo, double m_hi, std::int64_t* first,
                              std::int64_t* last) const {
  const auto count = static_cast<std::int64_t>(counts_[dim]);
  if (whole_grid_dims_[dim]) {
    *first = 0;
    *last = count - 1;
    return true;
  }
  // A non-finite post state carries no mass onto the grid.
  if (!std::isfinite(m_lo) || !std::isfinite(m_hi)) return false;
  if (!faces_[dim].empty()) {
    const double lo = m_lo + window_offset_[dim] - window_radius_[dim];
    const double hi = m_hi + window_offset_[dim] + window_radius_[dim];
    if (hi < faces_[dim].front() || lo > faces_[dim].back()) return false;
    *first = states.clamped_cell(dim, lo);
    *last = states.clamped_cell(dim, hi);
    return true;
  }
  const std::int64_t low_centre = states.nearest(dim, m_lo + window_offset_[dim]);
  const std::int64_t high_centre = states.nearest(dim, m_hi + window_offset_[dim]);
  const std::int64_t half = window_half_cells_[dim];
  if (low_centre - half > count - 1 || high_centre + half < 0) return false;
  *first = std::max<std::int64_t>(0, low_centre - half);
  *last = std::min<std::int64_t>(count - 1, high_centre + half);
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
    lo[i] = face(i, std::int64_t(multi[i]));
    hi[i] = faces_[i].empty() ? lb_[i] + (double(multi[i]) + 0.5) * eta_[i] : face(i, std::int64_t(multi[i]) + 1);
  }
  return box_mass(lo, hi, mean);
}

}  // namespace amytiss
