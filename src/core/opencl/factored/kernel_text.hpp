#pragma once
// Text pieces that the factored sweep's generated kernels share (internal).
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "factored/factored_plan.hpp"

namespace amytiss::detail {

/// Digit decoding of `index` into the sums of digit * stride for each named target, minor digit
/// first. Digits whose strides are all zero are skipped, except for advancing the remainder.
void decode_digits(std::ostringstream& s, const std::string& index, const std::vector<std::uint64_t>& radices,
                   const std::vector<std::vector<std::uint64_t>>& strides, const std::vector<std::string>& targets);

/// The signature of stage kernel `k` (its arguments: device_parts.cpp sets them); `fused`: also
/// the next stage's mass table (next_first, next_count, next_masses).
std::string kernel_head(std::size_t k, bool fused = false);

/// The kept cells of the window of tuple `tuple<suffix>` that lie in the block of the contracted
/// dimension held by the input ([block_first, block_end): all of it, except in the last stage of
/// a slice): lo<suffix>, hi<suffix>, cells<suffix>, and m<suffix>, its masses from lo<suffix>.
void window_of_tuple(std::ostringstream& s, const FactoredStage& stage, const std::string& suffix,
                     const std::string& indent);

}  // namespace amytiss::detail
