#include "bounds/mass_bounds.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "amytiss/errors.hpp"
#include "common/require.hpp"
#include "model/noise_laws.hpp"

namespace amytiss {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Bisection steps for the beta peak: far more than the 2^-1074..2^1024 range of doubles needs.
constexpr int kMaxBisections = 2200;

// num / s for s >= 0: the limit s -> 0+ (+-infinity) for s = 0, and 0 for num = 0 whatever s.
double ratio(double num, double s) { return num == 0.0 ? 0.0 : num / s; }

// Range of num / s over num in [num_lo, num_hi] and s in [s_lo, s_hi] (0 <= s_lo, 0 < s_hi),
// rounded outward for the subtraction that made num and the division.
MassInterval ratio_range(double num_lo, double num_hi, double s_lo, double s_hi) {
  const double lo = num_lo >= 0 ? ratio(num_lo, s_hi) : ratio(num_lo, s_lo);
  const double hi = num_hi >= 0 ? ratio(num_hi, s_lo) : ratio(num_hi, s_hi);
  return {round_down(lo, MassBounds::kRoundingUlps), round_up(hi, MassBounds::kRoundingUlps)};
}

constexpr detail::Require require{"MassBounds: "};

}  // namespace

MassInterval remainder(const MassInterval* cells, std::size_t count) {
  if (count == 0) return {1.0, 1.0};
  double sum_lo = 0.0, sum_hi = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    sum_lo += cells[k].lo;
    sum_hi += cells[k].hi;
  }
  // A sum of n non-negative terms errs by at most (n - 1) u times the sum (plus u to spare).
  const double slack = double(count + 1) * kUnitRoundoff;
  const double sum_lo_down = sum_lo - slack * sum_lo, sum_hi_up = sum_hi + slack * sum_hi;
  return {std::max(0.0, round_down(1.0 - sum_hi_up)), std::min(1.0, round_up(1.0 - sum_lo_down))};
}

MassBounds::MassBounds(const NoiseModel& noise, std::size_t dim) : noise_(noise), dim_(dim) {
  if (!noise.separable())
    throw ConfigError("noise.covariance",
                      "got a covariance with off-diagonal entries; interval transition bounds need independent "
                      "dimensions, i.e. a diagonal covariance (example: covariance: [0.04, 0.04])");
  require(dim < noise.dims(), "dimension out of range");
  switch (noise.distribution()) {
    case Distribution::Normal:
      peak_ = Peak::Centred;
      support_lo_ = -kInfinity;
      support_hi_ = kInfinity;
      break;
    case Distribution::Uniform:
      peak_ = Peak::Centred;
      support_lo_ = -1.0;
      support_hi_ = 1.0;
      break;
    case Distribution::Exponential:
    case Distribution::Beta:
    case Distribution::Custom: {
      const detail::UnitLaw& law = *noise.unit_law(dim);
      support_lo_ = law.lo;
      support_hi_ = law.hi;
      if (law.distribution == Distribution::Exponential) {
        peak_ = Peak::AtShift;
        centre_z_ = law.shift;
      } else if (law.distribution == Distribution::Beta) {
        mass_error_ = kBetaMassError;
        // Log-concave densities (alpha, beta >= 1) give a unimodal g; the others only the CDF bound.
        if (law.alpha >= 1.0 && law.beta >= 1.0) peak_ = law.alpha == law.beta ? Peak::Centred : Peak::Bisection;
        centre_z_ = 0.5 * (law.lo + law.hi);
      } else {
        mass_error_ = kCustomMassError;
      }
      break;
    }
  }
}

double MassBounds::standard_mass(double za, double zb) const { return noise_.interval_mass(dim_, za, zb, 0.0, 1.0); }

double MassBounds::lower_mass(double za, double zb) const {
  const double mass = standard_mass(za, zb) - mass_error_;
  return mass > 0.0 ? std::max(0.0, round_down(mass)) : 0.0;
}

double MassBounds::upper_mass(double za, double zb) const {
  return std::min(1.0, round_up(standard_mass(za, zb) + mass_error_));
}

double MassBounds::lower_at_mean(double a, double b, double m, double s) const {
  const MassInterval za = ratio_range(a - m, a - m, s, s), zb = ratio_range(b - m, b - m, s, s);
  return lower_mass(za.hi, zb.lo);
}

double MassBounds::upper_at_mean(double a, double b, double m, double s) const {
  const MassInterval za = ratio_range(a - m, a - m, s, s), zb = ratio_range(b - m, b - m, s, s);
  return upper_mass(za.lo, zb.hi);
}

MassInterval MassBounds::cdf_bounds(double a, double b, double m_lo, double m_hi, double s_lo, double s_hi,
                                    std::size_t splits) const {
  require(s_hi > 0 && splits > 0, "cdf_bounds needs a positive largest scale and at least one piece");
  if (m_lo == m_hi) splits = 1;
  MassInterval result{1.0, 0.0};
  const double width = m_hi - m_lo;
  // Piece i is [p(i), p(i + 1)] with one formula for both ends, so the pieces cover [m_lo, m_hi].
  auto point = [&](std::size_t i) { return i == splits ? m_hi : m_lo + width * (double(i) / double(splits)); };
  for (std::size_t i = 0; i < splits; ++i) {
    const double p1 = point(i), p2 = point(i + 1);
    const MassInterval za = ratio_range(a - p2, a - p1, s_lo, s_hi);
    const MassInterval zb = ratio_range(b - p2, b - p1, s_lo, s_hi);
    result.lo = std::min(result.lo, lower_mass(za.hi, zb.lo));
    result.hi = std::max(result.hi, upper_mass(za.lo, zb.hi));
  }
  return result;
}

MassInterval MassBounds::bounds(double a, double b, double m_lo, double m_hi, double s_lo, double s_hi) const {
  require(a < b && m_lo <= m_hi && 0.0 <= s_lo && s_lo <= s_hi, "expected a < b, m_lo <= m_hi, 0 <= s_lo <= s_hi");
  MassInterval point_mass{1.0, 0.0};  // empty: no zero scale
  if (s_lo == 0.0) {
    // Scale 0: all mass at m, in the cell when a <= m < b (closed [a, b] for the upper bound).
    point_mass = {(a <= m_lo && m_hi < b) ? 1.0 : 0.0, (m_hi >= a && m_lo <= b) ? 1.0 : 0.0};
    if (s_hi == 0.0) return point_mass;
  }
  MassInterval result;
  if (!std::isfinite(a) || !std::isfinite(b)) {
    // A half-line: g is monotone in m and in s, so the CDF bound at the corners is exact.
    result = cdf_bounds(a, b, m_lo, m_hi, s_lo, s_hi, 1);
  } else if (s_lo == s_hi && peak_ != Peak::None) {
    // g is unimodal in m: its minimum at an endpoint, its maximum at the (clamped) peak.
    result.lo = std::min(lower_at_mean(a, b, m_lo, s_lo), lower_at_mean(a, b, m_hi, s_lo));
    result.hi = peak_upper(a, b, m_lo, m_hi, s_lo);
  } else {
    result = cdf_bounds(a, b, m_lo, m_hi, s_lo, s_hi, kSplits);
  }
  return {std::min(result.lo, point_mass.lo), std::max(result.hi, point_mass.hi)};
}

double MassBounds::peak_upper(double a, double b, double m_lo, double m_hi, double s) const {
  if (peak_ == Peak::Bisection) return bisection_upper(a, b, m_lo, m_hi, s);
  // The peak mean m* and the standardized window it gives, both rounded outward.
  double peak_mean, magnitude, za, zb;
  const double width_z = round_up((b - a) / s, kRoundingUlps);
  if (peak_ == Peak::Centred) {
    // The cell centred on the law's centre: m* = (a + b)/2 - s * centre.
    peak_mean = 0.5 * (a + b) - s * centre_z_;
    magnitude = std::fabs(a) + std::fabs(b) + std::fabs(s * centre_z_);
    za = round_down(centre_z_ - round_up(0.5 * width_z), kRoundingUlps);
    zb = round_up(centre_z_ + round_up(0.5 * width_z), kRoundingUlps);
  } else {
    // Exponential: the cell starting at the shift, m* = a - s * shift (the density decreases
    // beyond the shift and is 0 before it).
    peak_mean = a - s * centre_z_;
    magnitude = std::fabs(a) + std::fabs(s * centre_z_);
    za = centre_z_;
    zb = round_up(centre_z_ + width_z, kRoundingUlps);
  }
  // Each operation above errs by at most u of its operands' magnitude.
  const double margin = 4.0 * kUnitRoundoff * magnitude + std::numeric_limits<double>::denorm_min();
  if (peak_mean + margin < m_lo) return upper_at_mean(a, b, m_lo, s);
  if (peak_mean - margin > m_hi) return upper_at_mean(a, b, m_hi, s);
  return upper_mass(za, zb);
}

int MassBounds::slope_sign(double a, double b, double m, double s) const {
  const detail::UnitLaw& law = *noise_.unit_law(dim_);
  const double width = law.hi - law.lo;
  const double za = (a - m) / s, zb = (b - m) / s;
  const double ta = (za - law.lo) / width, tb = (zb - law.lo) / width;
  // Near the support's ends rounding could move an end across them: no sign there.
  auto near_end = [](double t) { return std::fabs(t) < kEdge || std::fabs(1.0 - t) < kEdge; };
  if (near_end(ta) || near_end(tb)) return 0;
  auto log_density = [&](double t) {
    if (!(t > 0.0 && t < 1.0)) return -kInfinity;
    double value = 0.0;
    if (law.alpha != 1.0) value += (law.alpha - 1.0) * std::log(t);
    if (law.beta != 1.0) value += (law.beta - 1.0) * std::log1p(-t);
    return value;
  };
  // Error of a computed log density: t errs by at most 4u (|z| + |lo| + width)/width (the four
  // roundings that made it), which moves the log density by its slope times that; the logs and
  // the sum add a few u of the result.
  auto error = [&](double t, double z, double log_value) {
    const double t_error = 4.0 * kUnitRoundoff * (std::fabs(z) + std::fabs(law.lo) + width) / width;
    const double slope = std::fabs(law.alpha - 1.0) / t + std::fabs(law.beta - 1.0) / (1.0 - t);
    return kSignSafety * (slope * t_error + 4.0 * kUnitRoundoff * (1.0 + std::fabs(log_value)));
  };
  const double la = log_density(ta), lb = log_density(tb);
  if (la == -kInfinity && lb == -kInfinity) return 0;
  if (la == -kInfinity) return -1;
  if (lb == -kInfinity) return 1;
  const double difference = la - lb;
  if (std::fabs(difference) <= error(ta, za, la) + error(tb, zb, lb)) return 0;
  return difference > 0 ? 1 : -1;
}

double MassBounds::bisection_upper(double a, double b, double m_lo, double m_hi, double s) const {
  // g is log-concave: g' > 0 at l means g is nondecreasing on [m_lo, l], g' < 0 at r nonincreasing
  // on [r, m_hi]; so the maximum over [m_lo, m_hi] is the maximum over [l, r].
  if (slope_sign(a, b, m_lo, s) < 0) return upper_at_mean(a, b, m_lo, s);
  if (slope_sign(a, b, m_hi, s) > 0) return upper_at_mean(a, b, m_hi, s);
  double l = m_lo, r = m_hi;
  for (int step = 0; step < kMaxBisections; ++step) {
    const double mid = l + 0.5 * (r - l);
    if (!(mid > l && mid < r)) break;
    const int sign = slope_sign(a, b, mid, s);
    if (sign > 0) l = mid;
    else if (sign < 0) r = mid;
    else break;
  }
  return cdf_bounds(a, b, l, r, s, s, kSplits).hi;
}

MassInterval MassBounds::scale_range(double x_lo, double x_hi) const {
  const double base = noise_.base_scale()[dim_];
  if (noise_.type() == NoiseType::Additive) return {base, base};
  const double smallest = (x_lo <= 0.0 && x_hi >= 0.0) ? 0.0 : std::min(std::fabs(x_lo), std::fabs(x_hi));
  const double largest = std::max(std::fabs(x_lo), std::fabs(x_hi));
  return {std::max(0.0, round_down(base * smallest)), round_up(base * largest)};
}

bool MassBounds::window(const Grid& states, double m_lo, double m_hi, std::int64_t* first, std::int64_t* last) const {
  return noise_.window_range(states, dim_, m_lo, m_hi, first, last);
}

DimensionBounds MassBounds::dimension_bounds(const Grid& states, double m_lo, double m_hi, double s_lo,
                                             double s_hi) const {
  DimensionBounds out;
  if (!std::isfinite(m_lo) || !std::isfinite(m_hi)) {
    // An enclosure that blew up says nothing: the mass may go anywhere.
    out.leave = {0.0, 1.0};
    out.cut = {0.0, 1.0};
    return out;
  }
  const auto count = static_cast<std::int64_t>(states.count(dim_));
  // Cell faces as the noise model computes them: lb + (k -+ 1/2) eta, or the listed faces.
  auto face = [&](std::int64_t k) { return states.face(dim_, k); };
  auto mass = [&](double a, double b) { return bounds(a, b, m_lo, m_hi, s_lo, s_hi); };
  auto sum = [](const MassInterval& x, const MassInterval& y) {
    return MassInterval{std::max(0.0, round_down(x.lo + y.lo)), std::min(1.0, round_up(x.hi + y.hi))};
  };
  const bool inside = window(states, m_lo, m_hi, &out.first, &out.last);
  if (inside) {
    out.cells.reserve(std::size_t(out.last - out.first + 1));
    for (std::int64_t k = out.first; k <= out.last; ++k) out.cells.push_back(mass(face(k), face(k + 1)));
  } else {
    out.first = 0;
    out.last = -1;
  }
  // Beyond the grid's faces; on the grid outside the window (both sides, or all of it).
  out.leave = sum(mass(-kInfinity, face(0)), mass(face(count), kInfinity));
  MassInterval cut{0.0, 0.0};
  if (!inside) cut = mass(face(0), face(count));
  if (inside && out.first > 0) cut = sum(cut, mass(face(0), face(out.first)));
  if (inside && out.last < count - 1) cut = sum(cut, mass(face(out.last + 1), face(count)));
  // Where the noise can put mass: m + s Z over the means, the scales and Z's support. A cut it
  // cannot reach is exactly 0 (the bounds above carry the evaluation error).
  auto extent = [&](double z, double s) { return std::isinf(z) ? (s > 0 ? z : 0.0) : s * z; };
  const double reach_lo = round_down(m_lo + std::min(extent(support_lo_, s_lo), extent(support_lo_, s_hi)), 2);
  const double reach_hi = round_up(m_hi + std::max(extent(support_hi_, s_lo), extent(support_hi_, s_hi)), 2);
  auto meets = [&](double lo, double hi) { return lo <= hi && reach_lo <= hi && reach_hi >= lo; };
  const bool reachable = inside ? (out.first > 0 && meets(face(0), face(out.first))) ||
                                      (out.last < count - 1 && meets(face(out.last + 1), face(count)))
                                : meets(face(0), face(count));
  out.cut = reachable ? cut : MassInterval{0.0, 0.0};
  // Together they hold what the cells leave.
  const MassInterval rest = remainder(out.cells.data(), out.cells.size());
  out.leave.hi = std::min(out.leave.hi, rest.hi);
  out.cut.hi = std::min(out.cut.hi, rest.hi);
  return out;
}

}  // namespace amytiss
