#pragma once
// Image enclosures (docs/semantics.md, "Image enclosures"): for a cell (a box of states X), an
// input u and a disturbance w (or a box W of them), a box that contains f(x, u, w) for every x in X
// (and w in W), where f is the
// system map of a configuration (dynamics expressions, or a vector field stepped by the
// integrator, built-in models included); and the interval Jacobian of f over X. Sound under
// rounding: see interval.hpp.
#include <memory>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/interval.hpp"

namespace amytiss {

/// A box of images f(x, u, w), x in the cell, in state units.
struct ImageBox {
  IntervalBox box;
  /// False when f may be undefined (NaN) at some x in the cell: `box` then holds the values where
  /// f is defined, and a caller that needs every image must treat the cell as unbounded.
  bool defined = true;
  /// enclose() only (natural() leaves it empty): per coordinate i, a lower bound of |df_i/dx_i|
  /// over the cell, so that moving x_i by d moves f_i by at least expansion[i] * |d| (0 where the
  /// coordinate may jump in the cell or its derivative in x_i may vanish or change sign).
  std::vector<double> expansion;
};

/// entries[i][j] contains the partial derivative of f_i in x_j at every x of the cell.
struct IntervalJacobian {
  std::vector<IntervalBox> entries;
  /// Per row i: false when f_i may jump inside the cell (floor, ceil, a comparison or a branch that
  /// the cell does not decide, a value outside a function's domain); that row bounds nothing.
  std::vector<bool> valid;
};

class ImageEnclosure {
 public:
  /// The system map of a validated configuration (Config::validate()), as make_dynamics() builds
  /// it: `dynamics` expressions, integrated when `integrator.tau` is given, or a built-in `model`
  /// (its equations as expressions) stepped by the integrator with the model's own step.
  explicit ImageEnclosure(const Config& config);
  ~ImageEnclosure();
  ImageEnclosure(ImageEnclosure&&) noexcept;
  ImageEnclosure& operator=(ImageEnclosure&&) noexcept;

  std::size_t state_dims() const;
  std::size_t input_dims() const;
  std::size_t disturbance_dims() const;

  /// The natural interval extension: every operation of f evaluated over intervals.
  ImageBox natural(const IntervalBox& cell, const std::vector<double>& u, const std::vector<double>& w) const;
  /// The same for every disturbance in the box `w` (one interval per disturbance dimension).
  ImageBox natural_over(const IntervalBox& cell, const std::vector<double>& u, const IntervalBox& w) const;
  /// The natural form intersected, per coordinate, with the centred (mean-value) form
  /// f(c) + J(X) (X - c), c the centre of the cell, J the interval Jacobian (rows not valid keep
  /// the natural form). Never wider than natural().
  ImageBox enclose(const IntervalBox& cell, const std::vector<double>& u, const std::vector<double>& w) const;
  /// The same for every disturbance in the box `w` (one interval per disturbance dimension):
  /// f(c, W) + J(X, W) (X - c), J in x only. A box of points gives enclose() bit for bit.
  ImageBox enclose_over(const IntervalBox& cell, const std::vector<double>& u, const IntervalBox& w) const;
  /// The interval Jacobian of f over the cell (for Lipschitz bounds: |df_i/dx_j| <= magnitude).
  IntervalJacobian jacobian(const IntervalBox& cell, const std::vector<double>& u, const std::vector<double>& w) const;

 private:
  struct Map;
  std::unique_ptr<const Map> map_;
};

}  // namespace amytiss
