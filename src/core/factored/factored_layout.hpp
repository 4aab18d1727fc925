#pragma once
// The factored sweep's tensor layouts (internal, not installed): the digits of each stage's
// output, the strides of its input, of its mass tables' tuples and of its contracted cell, for
// the OpenCL kernels or for the host's line-by-line sweep (FactoredLayout, factored/factored_plan.hpp).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "factored/factored_plan.hpp"

namespace amytiss::detail {

/// Doubles per cache line: a padded digit spans a multiple of it.
constexpr std::uint64_t kLineDoubles = 8;
/// A digit is padded only where that adds at most 1/kMaxLinePadding of its values.
constexpr std::uint64_t kMaxLinePadding = 8;

/// Row-major strides of a layout (the last digit fastest).
std::vector<std::uint64_t> strides_of(const std::vector<TensorDigit>& layout);

/// The stages of elimination order `order` (post dimensions), for slices of `slice_cells` cells of
/// the last dimension eliminated: `reads` per post dimension as FactoredPlan::reads, `counts` and
/// `widths` (kept cells) per dimension. `pad_to_lines`: the stage tensors' fastest digit spans a
/// whole number of cache lines where that adds at most 1/kMaxLinePadding of the tensor (the last
/// stage's output, Q, is never padded).
std::vector<FactoredStage> build_stages(const std::vector<std::size_t>& order,
                                        const std::vector<std::vector<std::size_t>>& reads,
                                        const std::vector<FactorVariable>& variables,
                                        const std::vector<std::size_t>& counts, const std::vector<std::size_t>& widths,
                                        std::size_t slice_cells, FactoredLayout layout, bool pad_to_lines);

}  // namespace amytiss::detail
