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

/// The serial engine's step, in double precision: the reference engine's, and the host's
/// computations of interval iteration (a fixed policy's value, single expected values).
class ReferenceStep : public BellmanStep {
 public:
  explicit ReferenceStep(const Abstraction& abstraction);
  void apply(const double* in, double* out, std::uint32_t* chosen) override;
  double multiply_adds() const override { return multiply_adds_; }
  /// out = T_sigma(in): on Free cells the value of input policy[x] (min over disturbances).
  void apply_fixed(const double* in, double* out, const std::uint32_t* policy);
  /// sum_x' T(x'|x,u,w) in(x') for state cell x, input index u, disturbance index w.
  double expected(std::size_t cell, std::size_t input, std::size_t disturbance, const double* in);
  /// min over disturbances of expected().
  double input_value(std::size_t cell, std::size_t input, const double* in);

 private:
  const Abstraction& a_;
  std::vector<std::vector<double>> input_points_, disturbance_points_;
  std::vector<std::size_t> strides_, multi_;
  std::vector<double> x_, mean_;
  std::vector<std::int64_t> first_, last_;
  std::vector<std::vector<double>> masses_;
  double multiply_adds_ = 0;
  double counted_ = 0;  // multiply-adds of the current apply()
  double window_sum(std::size_t dim, std::size_t offset, double probability, const double* in);
};

}  // namespace amytiss::detail
