#pragma once
// The factored sweep's tensor layouts (internal, not installed): the digits of each stage's
// output, the strides of its input, of its mass tables' tuples and of its contracted cell, for
// the OpenCL kernels or for the host's line-by-line sweep (FactoredLayout, host/factored_plan.hpp).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "host/factored_plan.hpp"

namespace amytiss::detail {

/// Row-major strides of a layout (the last digit fastest).
std::vector<std::uint64_t> strides_of(const std::vector<TensorDigit>& layout);

/// The stages of elimination order `order` (post dimensions), for slices of `slice_cells` cells of
/// the last dimension eliminated: `reads` per post dimension as FactoredPlan::reads, `counts` and
/// `widths` (kept cells) per dimension.
std::vector<FactoredStage> build_stages(const std::vector<std::size_t>& order,
                                        const std::vector<std::vector<std::size_t>>& reads,
                                        const std::vector<FactorVariable>& variables,
                                        const std::vector<std::size_t>& counts, const std::vector<std::size_t>& widths,
                                        std::size_t slice_cells, FactoredLayout layout);

}  // namespace amytiss::detail
