#pragma once
// Closed intervals of doubles with outward rounding, for enclosures of the dynamics over a cell
// (docs/semantics.md, "Image enclosures"). Every operation returns an interval that contains the
// operation's real result for every choice of points in its operands, and also the double that the
// C++ evaluation of the same operation returns at those points.
//
// Rounding: each bound is computed in the default round-to-nearest mode and then moved outward with
// std::nextafter: one step for + - * / and sqrt (correctly rounded, so within half a step), four
// steps for the libm functions (sin, exp, pow, ...: not correctly rounded; glibc's measured
// maxima on x86-64 are one or two units in the last place in double precision, a bound from its
// tests, not a proof: soundness rests on it, and a libm with larger errors needs a larger
// kLibmRoundingSteps). The rounding mode is never changed: fesetround is global to the thread, is
// ignored by libm and by compilers without -frounding-math, and would disturb the engines'
// arithmetic running beside it.
//
// Domains: an operation whose operand leaves its domain (log or sqrt of negatives, asin of values
// beyond 1, a negative base with a non-integer exponent, 0/0) encloses its values over the part of
// the operand where it is defined and clears `defined`, which then propagates: the real function
// may be NaN for some points. Where no point is in the domain the result is empty. Unbounded
// results (division by an interval that contains 0, tan over a pole, log near 0) have infinite
// bounds; an infinite bound is never lost to rounding.
#include <cstddef>
#include <limits>
#include <vector>

namespace amytiss {

struct Interval {
  double lo = 0.0, hi = 0.0;  ///< bounds, lo <= hi (both NaN: the empty interval)
  /// False when some point of the operands is outside an operation's domain (the result then
  /// encloses the defined values only).
  bool defined = true;

  Interval() = default;
  Interval(double lower, double upper, bool is_defined = true) : lo(lower), hi(upper), defined(is_defined) {}
  static Interval point(double value) { return {value, value}; }
  static Interval entire() {
    return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  }
  static Interval empty(bool is_defined = false) {
    return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(), is_defined};
  }

  bool is_empty() const { return lo != lo; }
  bool is_point() const { return lo == hi; }
  bool contains(double value) const { return lo <= value && value <= hi; }
  bool contains_zero() const { return lo <= 0.0 && 0.0 <= hi; }
  double width() const { return is_empty() ? 0.0 : hi - lo; }
  /// The largest absolute value (of a Jacobian entry: a Lipschitz constant).
  double magnitude() const { return is_empty() ? 0.0 : (-lo > hi ? -lo : hi); }
  double mid() const;  ///< a double inside the interval (0 for the entire line)
};

/// A box: one interval per component.
using IntervalBox = std::vector<Interval>;

/// Outward steps after a libm function (not correctly rounded) and after + - * / sqrt (correctly
/// rounded).
constexpr int kLibmRoundingSteps = 4;
constexpr int kExactRoundingSteps = 1;

/// The next double below / above `value`, `steps` times (infinities stay infinite outward).
double round_down(double value, int steps = 1);
double round_up(double value, int steps = 1);
/// [lo, hi] computed in round-to-nearest, moved `steps` outward; a NaN bound (infinity minus
/// infinity) becomes infinite.
Interval rounded_outward(double lo, double hi, int steps, bool defined = true);

Interval hull(const Interval& a, const Interval& b);       ///< smallest interval holding both
Interval intersect(const Interval& a, const Interval& b);  ///< empty when disjoint

Interval operator-(const Interval& a);
Interval operator+(const Interval& a, const Interval& b);
Interval operator-(const Interval& a, const Interval& b);
Interval operator*(const Interval& a, const Interval& b);  ///< 0 * infinity counts as 0
Interval operator/(const Interval& a, const Interval& b);

/// Whether y is a single integer that integer_power() takes exactly (|y| <= 2^53).
bool is_integer_exponent(const Interval& y);
/// x^n for an integer n (exact integer exponent: the sign pattern of even and odd powers).
Interval integer_power(const Interval& x, long n);
/// pow(x, y) as std::pow: integer y handled by integer_power(), else x restricted to x >= 0.
Interval pow(const Interval& x, const Interval& y);
Interval sqr(const Interval& x);

Interval abs(const Interval& x);
Interval min(const Interval& a, const Interval& b);
Interval max(const Interval& a, const Interval& b);
Interval floor(const Interval& x);
Interval ceil(const Interval& x);

Interval sqrt(const Interval& x);
Interval exp(const Interval& x);
Interval log(const Interval& x);
Interval sin(const Interval& x);
Interval cos(const Interval& x);
Interval tan(const Interval& x);
Interval asin(const Interval& x);
Interval acos(const Interval& x);
Interval atan(const Interval& x);
Interval atan2(const Interval& y, const Interval& x);

// Truth values: 1 (true), 0 (false), [0, 1] (either, for different points).
/// The truth value of "x != 0".
Interval truth(const Interval& x);
Interval logical_not(const Interval& x);
Interval logical_and(const Interval& a, const Interval& b);
Interval logical_or(const Interval& a, const Interval& b);
Interval less(const Interval& a, const Interval& b);
Interval less_equal(const Interval& a, const Interval& b);
Interval equal(const Interval& a, const Interval& b);
/// c ? a : b: the branch that c selects for every point, else the hull of both.
Interval select(const Interval& c, const Interval& a, const Interval& b);

}  // namespace amytiss
