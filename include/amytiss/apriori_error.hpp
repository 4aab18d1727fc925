#pragma once
// The paper's a-priori error of the abstraction (its citation "SAM15, Theorem 9"), with every
// factor bounded soundly (docs/semantics.md, "The paper's a-priori error"):
//   epsilon = T * H * L(A) * delta,
// T the horizon, H a Lipschitz constant in x of the transition density t(x' | x, u, w) of the
// continuous system, L(A) the Lebesgue measure of the set the values are integrated over and delta
// the paper's state discretization parameter (the largest distance between two points of one cell).
// For a state x of a Free cell the paper bounds |P(continuous system satisfies the spec from x) -
// V_0(cell)| by epsilon; epsilon >= 1 says nothing (vacuous). It is reported for comparison with the
// continuous-system bounds of `guarantee: system`, which need no such constant.
#include <cstddef>
#include <string>

#include "amytiss/abstraction.hpp"

namespace amytiss {

struct AprioriError {
  /// T * H * L * delta (dimensionless); infinite when a factor is.
  double epsilon = 0;
  /// Lipschitz constant of t(x' | x, u, w) in x (Euclidean norm), for every x' and every x in a
  /// Free cell, input and disturbance of the grids: density_slope * jacobian_norm
  /// (1 / state units^(n + 1)).
  double lipschitz = 0;
  /// sup over x' of |grad_m density(x' - m)| (Euclidean), m the post mean (1 / state units^(n + 1)).
  double density_slope = 0;
  /// Upper bound of the spectral norm of df/dx over every Free cell, input and disturbance point,
  /// from ImageEnclosure::jacobian() (dimensionless in state units); infinite when a Jacobian row is
  /// not valid (f may jump inside a cell). Not computed (0) when density_slope is infinite.
  double jacobian_norm = 0;
  /// L(A): measure of the cells whose value can be positive (all but FixedZero: avoid or unsafe
  /// cells), cells times the product of eta (state units^n).
  double measure = 0;
  /// The paper's delta: the diameter of a cell, |eta| (Euclidean, state units).
  double delta = 0;
  /// Cells per box over which one interval Jacobian was taken (1: every cell; more when
  /// max_jacobians asked for fewer Jacobians: a sound, looser bound).
  std::size_t cells_per_box = 1;
  /// T: the horizon (steps); infinite for an unbounded specification.
  double horizon = 0;
  /// What each factor is and, when epsilon is infinite, why.
  std::string explanation;

  /// epsilon >= 1 (or infinite): the bound carries no information about the continuous system.
  bool vacuous() const { return !(epsilon < 1.0); }
};

/// The density factor alone (cheap): sup over x' of the gradient's norm of the noise density in its
/// mean, for additive normal noise (diagonal or full covariance, every variance > 0); infinite for
/// densities that are not Lipschitz (uniform, exponential: they jump) and for the laws without a
/// closed form here (beta, custom, multiplicative noise, a variance of 0), with the reason in
/// `why_not` (empty when finite). Rounded up.
double noise_density_slope(const Abstraction& abstraction, std::string* why_not);

/// The paper's epsilon for an abstraction built by Abstraction::from_config (its Config gives the
/// dynamics to ImageEnclosure). Cost: when the density factor is finite, one interval Jacobian per
/// (box, input, disturbance), a box being one cell, or, when that makes more than `max_jacobians`
/// (0: no limit), the hull of 2^k neighbouring cells along the dimensions with the most cells, as
/// few as fit (every box holds a Free cell); nothing else.
AprioriError apriori_error(const Abstraction& abstraction, std::size_t max_jacobians = 0);

/// One line for people: "a-priori error of the abstraction (paper's bound): 6.7e+02, vacuous: T 16 x
/// H ..." (", vacuous" when epsilon >= 1; the factors, and why a factor is infinite, after the colon).
std::string describe_apriori_error(const AprioriError& error);

}  // namespace amytiss
