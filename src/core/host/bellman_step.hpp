#pragma once
// One application of the Bellman operator of docs/semantics.md,
//   out(x) = max_u min_w sum_x' T(x'|x,u,w) in(x')   on Free cells,
// with fixed cells holding their role's value: what every engine's time step computes. The
// finite recursion applies it T_d times; interval iteration (host/interval_iteration.hpp) applies it to
// a lower and an upper value sequence.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
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
};

/// A step given as a function (the OpenCL sweeps' launches and read-backs); the function gets
/// in = nullptr when its device already holds the input (apply_resident).
class FunctionStep : public BellmanStep {
 public:
  using Function = std::function<void(const double* in, double* out, std::uint32_t* chosen)>;
  FunctionStep(Function function, double multiply_adds, double bytes, double resolution = 1e-14)
      : function_(std::move(function)), multiply_adds_(multiply_adds), bytes_(bytes), resolution_(resolution) {}
  double resolution() const override { return resolution_; }
  void apply(const double* in, double* out, std::uint32_t* chosen) override { function_(in, out, chosen); }
  void apply_resident(const double*, double* out, std::uint32_t* chosen) override { function_(nullptr, out, chosen); }
  double multiply_adds() const override { return multiply_adds_; }
  double bytes() const override { return bytes_; }

 private:
  Function function_;
  double multiply_adds_, bytes_, resolution_;
};

}  // namespace amytiss::detail
