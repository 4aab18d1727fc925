#pragma once
// The factored sweep's plan (internal, not installed): exact variable elimination of the expected
// next value along the dynamics' dependency graph.
//
// With separable noise, T(x'|x,u,w) = prod_i m_i(x'_i | p_i), where the post coordinate
// p_i = f_i(x,u,w) reads only the components S_i (plus x_i when the noise is multiplicative, whose
// scale is |x_i|). The expected next value
//   Q(x,u,w) = sum_{x'} prod_i m_i(x'_i | p_i) V(x')
// is contracted one post dimension at a time, in an elimination order e_1..e_d:
//   W_0 = V,   W_k[remaining post cells, U_k] = sum_a m_{e_k}(a | p_{e_k}) W_{k-1}[..., a, ...],
//   U_k = S_{e_1} u ... u S_{e_k},   Q = W_d.
// An entry of W_k is computed once and shared by every (x, u, w) that agrees on U_k: the same
// sums as the dense sweep, in another order, so the values agree up to rounding. Masses outside
// each dimension's kept window are zero in both, so cut mass and lower bounds are unchanged.
//
// Memory: W_k holds every remaining post cell of the last dimension eliminated; when the tensors
// do not fit, that dimension's cells are split into equal slices, each contracted through all
// stages and accumulated into Q.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"

namespace amytiss::detail {

/// One component of the state, input or disturbance grid.
struct FactorVariable {
  enum class Space { State, Input, Disturbance };
  Space space = Space::State;
  std::size_t index = 0;  ///< component within its space
  std::size_t count = 0;  ///< grid points of the component
};

/// One digit of a tensor layout (row-major, the last digit fastest).
struct TensorDigit {
  bool post = false;       ///< true: post-state cell of dimension `id`; false: variable `id`
  std::size_t id = 0;      ///< post dimension, or index into FactoredPlan::variables
  std::size_t radix = 0;   ///< values of the digit (a post digit of the sliced dimension: the slice)
};

/// One elimination step: contracts post dimension `dimension` of the input tensor.
struct FactoredStage {
  std::size_t dimension = 0;
  std::vector<TensorDigit> output;           ///< layout of the output tensor, major to minor
  std::vector<std::uint64_t> input_stride;   ///< per output digit: stride in the input (0: absent)
  std::vector<std::uint64_t> tuple_stride;   ///< per output digit: stride in the mass table's tuples
  std::uint64_t contracted_stride = 0;       ///< input stride of the contracted post cell
  std::vector<std::uint64_t> output_stride;  ///< per output digit: stride in the output buffer
  std::uint64_t output_entries = 0;          ///< entries of the output tensor (one slice): the radices' product
  /// Doubles of the output buffer (one slice): output_entries, or more where the fastest digit's
  /// values are padded to whole cache lines (output_stride of the digit before it).
  std::uint64_t output_size = 0;
  std::size_t width = 0;                     ///< largest number of kept cells of `dimension`
  /// Output digit whose entries are computed several at a time: input stride 1 (contiguous
  /// values), tuple stride 0 (shared masses). None: one entry per work-item.
  std::optional<std::size_t> vector_digit;
};

struct FactoredPlan {
  std::vector<FactorVariable> variables;        ///< state components, then inputs, then disturbances
  std::vector<std::vector<std::size_t>> reads;  ///< S_i per post dimension (indices, ascending)
  std::vector<std::size_t> order;               ///< elimination order e_1..e_d
  std::vector<FactoredStage> stages;            ///< one per dimension, in elimination order
  std::size_t slice_cells = 0;    ///< post cells of order.back() per slice (divides its count)
  std::size_t slices = 1;
  std::vector<std::uint64_t> q_stride;  ///< per variable: stride in Q (0: Q does not depend on it)
  std::uint64_t q_size = 0;
  std::uint64_t largest_stage_tensor = 0;  ///< doubles of the largest W_k buffer, 0 < k < d, one slice
  double multiply_adds = 0;        ///< per time step, all slices
  double dense_multiply_adds = 0;  ///< what the dense sweep does per time step (nominal)
  std::size_t device_bytes = 0;    ///< values, Q, both stage tensors and mass tables (fused stages need less)

  /// One line for the engine notes: order, slices, multiply-adds against the dense sweep.
  std::string describe() const;
};

/// Cells of dimension `dim` that the dense sweep's window spans: the whole dimension without
/// truncation, else 2 h + 1 for the noise's half-width h, h at most count - 1 (the window never
/// needs more than the grid on either side).
std::size_t dense_window_width(const Abstraction& abstraction, std::size_t dim);
/// Nominal multiply-adds of one separable contraction of the problem's window.
double contraction_multiply_adds(const Abstraction& abstraction);

/// How a plan lays out its tensors. Kernels: for the OpenCL stages, each stage's output ends with
/// the next stage's contracted cell and vector digit (work-items read contiguous windows), and
/// the fastest digit of W_1..W_{d-1} is padded to whole cache lines where that costs at most an
/// eighth of the tensor (rows and lines of entries then start on a line). Lines:
/// for a host sweep that contracts one line at a time and applies every tuple of new variables to
/// it, the output keeps the input's order, then the new variables (a line's results side by side),
/// then the largest remaining post cell that the next stage does not contract (the next stage's
/// neighbouring lines: close values, the same windows, side by side in memory); the order is
/// chosen by multiply-adds alone, and no stage has a vector digit.
enum class FactoredLayout { Kernels, Lines };

/// The cheapest elimination order whose buffers fit `budget_bytes` in all and `max_buffer_bytes`
/// each, or nullopt with the reason (dynamics without dependency information, non-separable
/// noise, nothing fits).
std::optional<FactoredPlan> plan_factored_sweep(const Abstraction& abstraction, double budget_bytes,
                                                double max_buffer_bytes, std::string* reason,
                                                FactoredLayout layout = FactoredLayout::Kernels);

}  // namespace amytiss::detail
