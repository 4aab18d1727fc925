#pragma once
// One application of the Bellman operator of docs/semantics.md,
//   out(x) = max_u min_w sum_x' T(x'|x,u,w) in(x')   on Free cells,
// with fixed cells holding their role's value: what every engine's time step computes. The
// finite recursion applies it T_d times (solve/backward_driver.hpp); interval iteration
// (solve/interval_iteration.hpp) applies it to a lower and an upper value sequence.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "amytiss/abstraction.hpp"

namespace amytiss::detail {

class BellmanStep {
 public:
  virtual ~BellmanStep() = default;
  /// out = T(in) for every state cell (flat index), chosen = the maximizing input (ties: lowest
  /// index; fixed cells: 0). in and out have states.size() values and do not overlap.
  virtual void apply(const double* in, double* out, std::uint32_t* chosen) = 0;
  /// apply() when `in` holds what the step already has: V_{T_d} before the first call, else the
  /// previous call's output, unchanged. A device step then need not upload it again.
  virtual void apply_resident(const double* in, double* out, std::uint32_t* chosen) { apply(in, out, chosen); }
  /// Multiply-adds of one apply() (0 when not counted), and operand bytes.
  virtual double multiply_adds() const { return 0; }
  virtual double bytes() const { return 0; }
  /// Memory bytes one apply() cannot avoid (its tensors read and written once); 0 when not counted.
  virtual double memory_bytes() const { return 0; }
  /// How far apart two of its values must be to differ by more than its arithmetic's rounding.
  virtual double resolution() const { return 1e-14; }
  /// out = T_sigma(in): the step of one stationary controller (the certification of an unbounded
  /// run): on Free cells the value of input controller[x] (min over disturbances), fixed cells
  /// their role's value. Only the host's steps have it (the serial step, the robust steps).
  virtual void evaluate(const double* in, double* out, const std::uint32_t* controller);
};

}  // namespace amytiss::detail
