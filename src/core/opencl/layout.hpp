#pragma once
// How the OpenCL engine lays a problem out in device memory (docs/engine.md): the padded value
// array and the transition record of one (state, input, disturbance) triple.
#include <cstddef>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "factored/factored_plan.hpp"  // dense_window_width(), contraction_multiply_adds()

namespace amytiss::detail {

/// Zero cells after the padded values: the last vector of a window row may read up to 3 beyond it.
constexpr std::size_t kValueSlack = 4;

/// Layout numbers of a problem, shared by the generated prelude and the host. Per state
/// dimension i (count n_i, window half width h_i of the noise model):
///   whole[i]          1 when the window is the whole grid dimension (truncation none)
///   half[i]           padding on each side: 0 for a whole dimension, else min(h_i, n_i - 1)
///   width[i]          window cells: n_i for a whole dimension, else 2*half[i] + 1
///   mass_offset[i]    first float of dimension i's masses in a record
///   padded_count[i]   n_i + 2*half[i]; padded_stride[i]: row-major stride of the padded array
///   mass_record       sum_i width[i]: floats of one record
///   padded_size       product of padded_count: cells of the padded value array
struct Layout {
  std::vector<long long> half, width, mass_offset, padded_count, padded_stride, whole;
  long long mass_record = 0;
  std::size_t padded_size = 1;

  explicit Layout(const Abstraction& a);
  /// Place in the padded array of the state cell with flat index `flat`.
  std::size_t padded_offset(const Grid& states, std::size_t flat) const;
  /// Bytes of one stored transition record: a uint32 padded offset + mass_record float32 masses.
  std::size_t record_bytes() const;
};

}  // namespace amytiss::detail
