#pragma once
// A stage fused with the last one (internal). Where the last stage contracts the vector digit of
// the stage before it and computes its entries along that stage's line of kept rows (traffic
// 3-d: x'2 after x'0), a work-item of the stage before contracts its lines of kept rows into Q
// itself: the stage tensor between them (688 MB a step for traffic 3-d) is never written or read.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "factored/factored_plan.hpp"
#include "opencl/factored/program.hpp"

namespace amytiss::detail {

/// Whether stage k's kernel also computes stage k + 1, the last: on a SIMD device (row kernels),
/// in one slice, outside a team, where stage k keeps lines of rows along a digit (tiled_digit)
/// that stage k + 1 takes in vectors, and stage k + 1 contracts stage k's vector digit.
bool fuses_next(const FactoredPlan& plan, std::size_t k, const StageShape& shape);

/// Per output digit of `stage`: the tuple and output strides of the digit of the same variable
/// in `next` (0 for the digit that `next` contracts).
struct NextStrides {
  std::vector<std::uint64_t> tuple, out;
};
NextStrides next_strides(const FactoredStage& stage, const FactoredStage& next);

/// What replaces the stores of a fused kernel's lines of kept rows: for every tuple of the
/// variables new to `next` and every row (`rows`: _a, then _b, ... where has_<row>), the line's kept
/// entries contracted over `next`'s window of the tuple into Q, the same FMA chain per entry as
/// `next`'s own kernel. Reads next_tuple, next_out (the work-item's first line in `next`'s
/// tuples and output), tile_rows and kept<row>.
void contract_kept_lines(std::ostringstream& s, const FactoredStage& stage, const FactoredStage& next,
                         std::optional<std::size_t> paired, const std::vector<std::string>& rows);

}  // namespace amytiss::detail
