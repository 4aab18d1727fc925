// The elementary functions of the expression grammar over intervals (amytiss/interval.hpp).
#include <algorithm>
#include <cmath>

#include "amytiss/interval.hpp"

namespace amytiss {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kPi = M_PI;   // the double nearest pi, below it
// Beyond this magnitude the position of x within the period is not known well enough to look for
// extrema; sin and cos then give [-1, 1], tan the whole line.
constexpr double kLargestReducedArgument = 1e12;

Interval libm_outward(double lo, double hi, bool defined) { return rounded_outward(lo, hi, kLibmRoundingSteps, defined); }

Interval clamped(Interval x, double lo, double hi) {
  x.lo = std::max(x.lo, lo);
  x.hi = std::min(x.hi, hi);
  return x;
}

// Whether [lo, hi] may hold a point phase + k * period, k an integer. Errs towards "yes": the
// offsets in periods are computed in doubles (relative error near 1e-16), the slack is far wider.
bool may_hold(double lo, double hi, double phase, double period) {
  constexpr double kSlack = 1e-9;
  const double first = (lo - phase) / period, last = (hi - phase) / period;
  return std::floor(last + kSlack * (1.0 + std::fabs(last))) >= std::ceil(first - kSlack * (1.0 + std::fabs(first)));
}

bool too_wide_for_period(const Interval& x, double period) {
  return !std::isfinite(x.lo) || !std::isfinite(x.hi) || x.hi - x.lo >= period ||
         std::max(std::fabs(x.lo), std::fabs(x.hi)) > kLargestReducedArgument;
}

// sin and cos: the values at the end points, and +-1 where a maximum (minimum) lies inside.
template <typename Function>
Interval periodic(const Interval& x, Function function, double maximum_phase, double minimum_phase) {
  if (x.is_empty()) return x;
  if (too_wide_for_period(x, 2.0 * kPi)) return {-1.0, 1.0, x.defined};
  const double at_lo = function(x.lo), at_hi = function(x.hi);
  Interval result = libm_outward(std::min(at_lo, at_hi), std::max(at_lo, at_hi), x.defined);
  if (may_hold(x.lo, x.hi, maximum_phase, 2.0 * kPi)) result.hi = 1.0;
  if (may_hold(x.lo, x.hi, minimum_phase, 2.0 * kPi)) result.lo = -1.0;
  return clamped(result, -1.0, 1.0);
}

// The part of x inside [lo, hi]; `defined` cleared when x reaches outside.
Interval restricted(const Interval& x, double lo, double hi) {
  if (x.is_empty()) return x;
  if (x.hi < lo || x.lo > hi) return Interval::empty(false);
  return {std::max(x.lo, lo), std::min(x.hi, hi), x.defined && x.lo >= lo && x.hi <= hi};
}

}  // namespace

Interval sqrt(const Interval& x) {
  const Interval domain = restricted(x, 0.0, kInfinity);
  if (domain.is_empty()) return domain;
  // sqrt is correctly rounded: one step outward suffices.
  return clamped(rounded_outward(std::sqrt(domain.lo), std::sqrt(domain.hi), kExactRoundingSteps, domain.defined), 0.0,
                 kInfinity);
}

Interval exp(const Interval& x) {
  if (x.is_empty()) return x;
  return clamped(libm_outward(std::exp(x.lo), std::exp(x.hi), x.defined), 0.0, kInfinity);
}

Interval log(const Interval& x) {
  // log(0) is -inf, not NaN: 0 belongs to the domain.
  const Interval domain = restricted(x, 0.0, kInfinity);
  if (domain.is_empty()) return domain;
  return libm_outward(std::log(domain.lo), std::log(domain.hi), domain.defined);
}

Interval sin(const Interval& x) {
  return periodic(x, [](double v) { return std::sin(v); }, 0.5 * kPi, -0.5 * kPi);
}

Interval cos(const Interval& x) {
  return periodic(x, [](double v) { return std::cos(v); }, 0.0, kPi);
}

// Increasing between poles at pi/2 + k pi; over a pole, the whole line (tan of a double is finite
// but arbitrarily large there).
Interval tan(const Interval& x) {
  if (x.is_empty()) return x;
  if (too_wide_for_period(x, kPi) || may_hold(x.lo, x.hi, 0.5 * kPi, kPi)) return {-kInfinity, kInfinity, x.defined};
  return libm_outward(std::tan(x.lo), std::tan(x.hi), x.defined);
}

Interval asin(const Interval& x) {
  const Interval domain = restricted(x, -1.0, 1.0);
  if (domain.is_empty()) return domain;
  return libm_outward(std::asin(domain.lo), std::asin(domain.hi), domain.defined);
}

Interval acos(const Interval& x) {
  const Interval domain = restricted(x, -1.0, 1.0);
  if (domain.is_empty()) return domain;
  return clamped(libm_outward(std::acos(domain.hi), std::acos(domain.lo), domain.defined), 0.0, kInfinity);
}

Interval atan(const Interval& x) {
  if (x.is_empty()) return x;
  return libm_outward(std::atan(x.lo), std::atan(x.hi), x.defined);
}

// The angle of the point (x, y) in [-pi, pi]. A box that meets the ray x <= 0, y = 0 (the origin
// or the cut where the angle jumps from pi to -pi) gives [-pi, pi]; any other box lies in the
// slit plane, where the angle is continuous and its extremes over a box lie at corners.
Interval atan2(const Interval& y, const Interval& x) {
  if (x.is_empty() || y.is_empty()) return Interval::empty(x.defined && y.defined);
  const bool defined = x.defined && y.defined;
  if (x.lo <= 0.0 && y.contains_zero()) return {round_down(-kPi), round_up(kPi), defined};
  const double corners[] = {std::atan2(y.lo, x.lo), std::atan2(y.lo, x.hi), std::atan2(y.hi, x.lo),
                            std::atan2(y.hi, x.hi)};
  const auto range = std::minmax_element(corners, corners + 4);
  return libm_outward(*range.first, *range.second, defined);
}

}  // namespace amytiss
