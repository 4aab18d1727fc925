#pragma once
// Sound bounds of one-dimensional cell masses over a box of post means (docs/semantics.md,
// "Interval transition bounds"): the per-dimension transition bounds of the interval MDP whose
// values bound the continuous system.
//
// Along dimension `dim` the noise is s * Z (Z standard normal; uniform on [-1, 1]; the unit laws of
// model/noise_laws.hpp) with s the dimension's scale (state units). For a target interval [a, b],
// post means m in [m_lo, m_hi] and scales s in [s_lo, s_hi] (all in state units; the scale range
// is one value for additive noise, base * |x| over the source cell for multiplicative noise):
//   g(m, s) = P(a <= m + s Z <= b) = F((b - m)/s) - F((a - m)/s),
// and bounds() returns [lo, hi] with lo <= g(m, s) <= hi for every such m and s:
//   - every law, from the monotone CDF alone, on each of kSplits equal pieces [m1, m2]:
//       F(min (b - m)/s) - F(max (a - m)/s) <= g <= F(max (b - m)/s) - F(min (a - m)/s);
//   - unimodal g (one scale; normal, uniform, exponential, beta with alpha, beta >= 1): the minimum
//     at an endpoint of [m_lo, m_hi]; the maximum at the peak where it lies in the interval
//     (symmetric laws: the mean that centres the cell on the law's centre; exponential: the one
//     that puts a on the law's shift; other beta laws: found by bisection on the sign of
//     g' = (f((a - m)/s) - f((b - m)/s))/s, the CDF bound closing the last bracket), else at the
//     endpoint nearer to the peak.
// a or b may be infinite (a half-line: g is monotone in m and s, the CDF bound at the corners
// is exact); a scale of 0 is a point mass.
// Rounding: standardized bounds rounded outward (kRoundingUlps ulps), each mass widened by the
// law's evaluation error (mass_error()), lo rounded down, hi rounded up, both clipped to [0, 1].
#include <cstddef>
#include <cstdint>
#include <vector>

#include "amytiss/grid.hpp"
#include "amytiss/interval.hpp"
#include "amytiss/noise.hpp"

namespace amytiss {

/// A probability interval [lo, hi], 0 <= lo <= hi <= 1 (or a scale range, state units).
struct MassInterval {
  double lo = 0;
  double hi = 0;
};

/// The bounds of one row (source cell, input, disturbance) along one dimension: the window's cells
/// and the two other outcomes, which with them make up all the mass.
struct DimensionBounds {
  std::int64_t first = 0, last = -1;  ///< window cells (grid indices); empty when last < first
  std::vector<MassInterval> cells;    ///< cells[k - first]: the mass of cell k
  MassInterval leave;                 ///< the mass beyond the grid's faces (leaves the grid)
  MassInterval cut;                   ///< the mass on grid cells outside the window (cut by the truncation)
};

/// Unit roundoff of double precision: a correctly rounded operation errs by at most this, relative.
constexpr double kUnitRoundoff = 0x1p-53;
// round_down() and round_up() (amytiss/interval.hpp) move a double outward by whole steps.

/// [1 - sum hi, 1 - sum lo] clipped to [0, 1] and rounded outward (sums bounded for their rounding):
/// the mass outside `count` cells whose masses lie in the given intervals.
MassInterval remainder(const MassInterval* cells, std::size_t count);

class MassBounds {
 public:
  static constexpr std::size_t kSplits = 32;
  /// Outward rounding of standardized bounds (a - m)/s: two roundings of at most half an ulp each.
  static constexpr int kRoundingUlps = 3;
  /// Absolute error of one mass evaluation: closed forms (erfc, exp, overlap), the incomplete beta
  /// (relative accuracy about 1e-14 per term) and the custom quadrature (its 1e-12 estimate per cell).
  static constexpr double kClosedFormMassError = 4e-15;
  static constexpr double kBetaMassError = 1e-13;
  static constexpr double kCustomMassError = 4e-12;
  /// Bisection (beta): the sign of log f((a - m)/s) - log f((b - m)/s) is trusted beyond
  /// kSignSafety times its rounding error bound, and only where both ends lie at least kEdge (in
  /// support units) from the support's ends.
  static constexpr double kSignSafety = 4.0;
  static constexpr double kEdge = 1e-6;

  /// Dimension `dim` of a separable noise model; a full covariance with off-diagonal entries is a
  /// ConfigError on noise.covariance (its cell masses are not products of 1-d masses).
  MassBounds(const NoiseModel& noise, std::size_t dim);

  /// Sound [lo, hi] of g(m, s) over m in [m_lo, m_hi], s in [s_lo, s_hi] (see above); a scale of
  /// 0 is a point mass (1 when a <= m < b).
  MassInterval bounds(double a, double b, double m_lo, double m_hi, double s_lo, double s_hi) const;
  /// The CDF bound alone, on `splits` equal pieces of [m_lo, m_hi] (s_hi > 0).
  MassInterval cdf_bounds(double a, double b, double m_lo, double m_hi, double s_lo, double s_hi,
                          std::size_t splits) const;
  /// Scales over the source cell [x_lo, x_hi] along this dimension (rounded outward): the base
  /// scale for additive noise, base * [min |x|, max |x|] for multiplicative noise.
  MassInterval scale_range(double x_lo, double x_hi) const;
  /// Absolute error of one mass evaluation of this law.
  double mass_error() const { return mass_error_; }

  /// The union over post means in [m_lo, m_hi] of the truncation window (NoiseModel::dimension_window):
  /// grid cells first..last. False when it misses the grid (every mean's kept mass leaves it).
  bool window(const Grid& states, double m_lo, double m_hi, std::int64_t* first, std::int64_t* last) const;
  /// Bounds of every window cell, of the mass leaving the grid and of the mass cut (exactly 0 where
  /// m + s Z cannot reach grid cells outside the window), for means in [m_lo, m_hi] and scales in
  /// [s_lo, s_hi]; leave and cut no more than remainder() of the cells. A box that is not finite
  /// gives no cells and leave and cut in [0, 1].
  DimensionBounds dimension_bounds(const Grid& states, double m_lo, double m_hi, double s_lo, double s_hi) const;

 private:
  enum class Peak { Centred, AtShift, Bisection, None };
  const NoiseModel& noise_;
  std::size_t dim_;
  Peak peak_ = Peak::None;
  double centre_z_ = 0;  // Centred: the law's centre; AtShift: the shift
  double mass_error_ = kClosedFormMassError;
  double support_lo_ = 0, support_hi_ = 0;  // of Z (may be infinite)

  double standard_mass(double za, double zb) const;
  double lower_mass(double za, double zb) const;  // standard_mass widened down, rounded down
  double upper_mass(double za, double zb) const;
  double lower_at_mean(double a, double b, double m, double s) const;  // one mean, one scale
  double upper_at_mean(double a, double b, double m, double s) const;
  double peak_upper(double a, double b, double m_lo, double m_hi, double s) const;
  double bisection_upper(double a, double b, double m_lo, double m_hi, double s) const;
  int slope_sign(double a, double b, double m, double s) const;  // certain sign of g', else 0
};

}  // namespace amytiss
