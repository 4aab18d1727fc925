#include "amytiss/interval.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace amytiss {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
bool both_defined(const Interval& a, const Interval& b) { return a.defined && b.defined; }

// The product as interval arithmetic needs it: 0 times anything (an infinite bound) is 0.
double bound_product(double a, double b) { return a == 0.0 || b == 0.0 ? 0.0 : a * b; }

Interval from_values(const double* values, int count, bool defined, int steps) {
  for (int i = 0; i < count; ++i)
    if (std::isnan(values[i])) return Interval(-kInfinity, kInfinity, defined);
  const auto range = std::minmax_element(values, values + count);
  return rounded_outward(*range.first, *range.second, steps, defined);
}

const Interval kFalse = Interval::point(0.0);
const Interval kTrue = Interval::point(1.0);
const Interval kEither = Interval(0.0, 1.0);

Interval with_defined(Interval value, bool defined) {
  value.defined = value.defined && defined;
  return value;
}

}  // namespace

double Interval::mid() const {
  if (is_empty()) return lo;
  if (lo == -kInfinity) return hi > 0.0 ? 0.0 : hi;
  if (hi == kInfinity) return lo < 0.0 ? 0.0 : lo;
  return std::clamp(0.5 * lo + 0.5 * hi, lo, hi);
}

Interval rounded_outward(double lo, double hi, int steps, bool defined) {
  return {std::isnan(lo) ? -kInfinity : round_down(lo, steps), std::isnan(hi) ? kInfinity : round_up(hi, steps),
          defined};
}

namespace {

// std::nextafter(value, -+infinity) by the representation's order (IEEE 754 doubles of one sign
// are ordered like their bit patterns): the same results, without the library call, which the
// interval bounds make hundreds of millions of times.
double step_toward(double value, bool up) {
  if (std::isnan(value) || value == (up ? kInfinity : -kInfinity)) return value;
  if (value == 0.0) return up ? std::numeric_limits<double>::denorm_min() : -std::numeric_limits<double>::denorm_min();
  std::uint64_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  // Away from zero the magnitude grows, toward zero it shrinks.
  if ((value > 0.0) == up) ++bits;
  else --bits;
  std::memcpy(&value, &bits, sizeof bits);
  return value;
}

}  // namespace

double round_down(double value, int steps) {
  for (int i = 0; i < steps; ++i) value = step_toward(value, false);
  return value;
}

double round_up(double value, int steps) {
  for (int i = 0; i < steps; ++i) value = step_toward(value, true);
  return value;
}

Interval hull(const Interval& a, const Interval& b) {
  if (a.is_empty()) return with_defined(b, a.defined);
  if (b.is_empty()) return with_defined(a, b.defined);
  return {std::min(a.lo, b.lo), std::max(a.hi, b.hi), both_defined(a, b)};
}

Interval intersect(const Interval& a, const Interval& b) {
  if (a.is_empty() || b.is_empty() || a.hi < b.lo || b.hi < a.lo) return Interval::empty(both_defined(a, b));
  return {std::max(a.lo, b.lo), std::min(a.hi, b.hi), both_defined(a, b)};
}

Interval operator-(const Interval& a) { return {-a.hi, -a.lo, a.defined}; }

Interval operator+(const Interval& a, const Interval& b) {
  if (a.is_empty() || b.is_empty()) return Interval::empty(both_defined(a, b));
  return rounded_outward(a.lo + b.lo, a.hi + b.hi, kExactRoundingSteps, both_defined(a, b));
}

Interval operator-(const Interval& a, const Interval& b) {
  if (a.is_empty() || b.is_empty()) return Interval::empty(both_defined(a, b));
  return rounded_outward(a.lo - b.hi, a.hi - b.lo, kExactRoundingSteps, both_defined(a, b));
}

Interval operator*(const Interval& a, const Interval& b) {
  if (a.is_empty() || b.is_empty()) return Interval::empty(both_defined(a, b));
  const double products[] = {bound_product(a.lo, b.lo), bound_product(a.lo, b.hi), bound_product(a.hi, b.lo),
                             bound_product(a.hi, b.hi)};
  return from_values(products, 4, both_defined(a, b), kExactRoundingSteps);
}

// A divisor that contains 0 (even as an end point, where a signed zero decides between +inf and
// -inf) gives the whole line; 0/0 is NaN, so a numerator that contains 0 as well clears `defined`.
Interval operator/(const Interval& a, const Interval& b) {
  if (a.is_empty() || b.is_empty()) return Interval::empty(both_defined(a, b));
  if (b.contains_zero()) return Interval(-kInfinity, kInfinity, both_defined(a, b) && !a.contains_zero());
  const double quotients[] = {a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi};
  return from_values(quotients, 4, both_defined(a, b), kExactRoundingSteps);
}

bool is_integer_exponent(const Interval& y) {
  constexpr double kExactInteger = 9007199254740992.0;  // 2^53: every double integer up to it converts exactly
  return y.is_point() && std::floor(y.lo) == y.lo && std::fabs(y.lo) <= kExactInteger;
}

Interval integer_power(const Interval& x, long n) {
  if (x.is_empty()) return x;
  if (n == 0) return Interval(1.0, 1.0, x.defined);
  const double power_lo = std::pow(x.lo, static_cast<double>(n));
  const double power_hi = std::pow(x.hi, static_cast<double>(n));
  const bool even = n % 2 == 0;
  if (x.contains_zero() && x.lo < x.hi) {
    if (n < 0 && !even) return Interval(-kInfinity, kInfinity, x.defined);
    if (n < 0) return rounded_outward(std::min(power_lo, power_hi), kInfinity, kLibmRoundingSteps, x.defined);
    if (even) return rounded_outward(0.0, std::max(power_lo, power_hi), kLibmRoundingSteps, x.defined);
  }
  // Monotone over x: a single sign, or an odd positive power.
  const double values[] = {power_lo, power_hi};
  Interval result = from_values(values, 2, x.defined, kLibmRoundingSteps);
  if (even && n > 0) result.lo = std::max(result.lo, 0.0);
  return result;
}

Interval sqr(const Interval& x) { return integer_power(x, 2); }

// Over x >= 0, pow(x, y) = exp(y log x) is monotone in each argument (log x bilinear with y), so
// its extremes lie at the corners of the box, limits included (pow(0, y) for y < 0 is +inf).
Interval pow(const Interval& x, const Interval& y) {
  if (x.is_empty() || y.is_empty()) return Interval::empty(both_defined(x, y));
  if (is_integer_exponent(y))
    return with_defined(integer_power(x, static_cast<long>(y.lo)), y.defined);
  bool defined = both_defined(x, y);
  Interval base = x;
  if (x.lo < 0.0) {
    // A negative base is defined only for integer exponents, which y may hold when not a point.
    const bool integer_inside = !y.is_point() && std::floor(y.hi) >= std::ceil(y.lo);
    if (integer_inside) return Interval(-kInfinity, kInfinity, false);
    if (x.hi < 0.0) return Interval::empty(false);
    base.lo = 0.0;
    defined = false;
  }
  const double corners[] = {std::pow(base.lo, y.lo), std::pow(base.lo, y.hi), std::pow(base.hi, y.lo),
                            std::pow(base.hi, y.hi)};
  Interval result = from_values(corners, 4, defined, kLibmRoundingSteps);
  result.lo = std::max(result.lo, 0.0);
  return result;
}

Interval abs(const Interval& x) {
  if (x.is_empty() || x.lo >= 0.0) return x;
  if (x.hi <= 0.0) return -x;
  return {0.0, std::max(-x.lo, x.hi), x.defined};
}

Interval min(const Interval& a, const Interval& b) {
  if (a.is_empty() || b.is_empty()) return Interval::empty(both_defined(a, b));
  return {std::min(a.lo, b.lo), std::min(a.hi, b.hi), both_defined(a, b)};
}

Interval max(const Interval& a, const Interval& b) {
  if (a.is_empty() || b.is_empty()) return Interval::empty(both_defined(a, b));
  return {std::max(a.lo, b.lo), std::max(a.hi, b.hi), both_defined(a, b)};
}

Interval floor(const Interval& x) { return x.is_empty() ? x : Interval(std::floor(x.lo), std::floor(x.hi), x.defined); }

Interval ceil(const Interval& x) { return x.is_empty() ? x : Interval(std::ceil(x.lo), std::ceil(x.hi), x.defined); }

Interval truth(const Interval& x) {
  if (x.is_empty()) return x;
  if (!x.contains_zero()) return with_defined(kTrue, x.defined);
  if (x.lo == 0.0 && x.hi == 0.0) return with_defined(kFalse, x.defined);
  return with_defined(kEither, x.defined);
}

Interval logical_not(const Interval& x) {
  const Interval t = truth(x);
  if (t.is_empty()) return t;
  return {1.0 - t.hi, 1.0 - t.lo, t.defined};
}

// As in C, the right operand does not matter when the left one decides (it is not evaluated).
Interval logical_and(const Interval& a, const Interval& b) {
  const Interval left = truth(a);
  if (left.is_empty() || left.hi == 0.0) return left;
  const Interval right = truth(b);
  if (right.is_empty()) return Interval::empty(false);
  return {std::min(left.lo, right.lo), std::min(left.hi, right.hi), both_defined(left, right)};
}

Interval logical_or(const Interval& a, const Interval& b) {
  const Interval left = truth(a);
  if (left.is_empty() || left.lo == 1.0) return left;
  const Interval right = truth(b);
  if (right.is_empty()) return Interval::empty(false);
  return {std::max(left.lo, right.lo), std::max(left.hi, right.hi), both_defined(left, right)};
}

Interval less(const Interval& a, const Interval& b) {
  if (a.is_empty() || b.is_empty()) return Interval::empty(both_defined(a, b));
  if (a.hi < b.lo) return with_defined(kTrue, both_defined(a, b));
  if (a.lo >= b.hi) return with_defined(kFalse, both_defined(a, b));
  return with_defined(kEither, both_defined(a, b));
}

Interval less_equal(const Interval& a, const Interval& b) {
  if (a.is_empty() || b.is_empty()) return Interval::empty(both_defined(a, b));
  if (a.hi <= b.lo) return with_defined(kTrue, both_defined(a, b));
  if (a.lo > b.hi) return with_defined(kFalse, both_defined(a, b));
  return with_defined(kEither, both_defined(a, b));
}

Interval equal(const Interval& a, const Interval& b) {
  if (a.is_empty() || b.is_empty()) return Interval::empty(both_defined(a, b));
  if (a.is_point() && b.is_point() && a.lo == b.lo) return with_defined(kTrue, both_defined(a, b));
  if (a.hi < b.lo || b.hi < a.lo) return with_defined(kFalse, both_defined(a, b));
  return with_defined(kEither, both_defined(a, b));
}

Interval select(const Interval& c, const Interval& a, const Interval& b) {
  const Interval t = truth(c);
  if (t.is_empty()) return t;
  if (t.lo == 1.0) return with_defined(a, t.defined);
  if (t.hi == 0.0) return with_defined(b, t.defined);
  return with_defined(hull(a, b), t.defined);
}

}  // namespace amytiss
