#pragma once
// The factored sweep's stage kernels for SIMD devices (internal): a row of the vector digit per
// work-item in explicit double vectors, two or four rows where their windows share most cells,
// a line of rows where a row's entries lie a line or more apart.
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>

#include "factored/factored_plan.hpp"
#include "opencl/factored/program.hpp"

namespace amytiss::detail {

/// The output digit whose neighbouring values a work-item takes two at a time (a row kernel's
/// rows, or one entry per work-item's entries): the digit that picks only masses (input stride 0)
/// with the most values (the finest grid: the two windows are shifted least), ties to the faster
/// digit; none when no such digit has two values or more. A team's shape (split_by_team) takes it
/// after the vector digit only, and none in a stage without one (the team splits it by entries).
std::optional<std::size_t> paired_digit(const FactoredStage& stage, const StageShape& shape);

/// The output's fastest digit where it is not the vector digit (nor the paired digit) and has
/// more than two values: a row work-item takes a line of its neighbouring values.
std::optional<std::size_t> tiled_digit(const FactoredStage& stage, const StageShape& shape);

/// Rows (or entries) a work-item takes along the paired digit: 1 without one; in a row kernel
/// kMaxRowsPerItem where their accumulators fit the register budget in one block (short rows:
/// each vector loaded once for that many FMAs), else 2. Row names: row_name(0) = "_a", ...
constexpr std::uint64_t kMaxRowsPerItem = 4;
std::uint64_t rows_per_item(const FactoredStage& stage, const StageShape& shape);
std::string row_name(std::uint64_t i);

/// Whether a group of rows (a pair, or rows_per_item) takes one pass over the union of its
/// windows (cells [lo, hi) each, clipped to the block): where the union is at most 3/4 of their
/// cells together (kShareUnionWeight x union <= kShareCellsWeight x cells; the kernels test the same).
constexpr long long kShareUnionWeight = 4, kShareCellsWeight = 3;
constexpr bool rows_share_pass(long long union_cells, long long cells) {
  return kShareUnionWeight * union_cells <= kShareCellsWeight * cells;
}

/// Whether a stage's kernel stores its output past the caches (AMYTISS_STREAM_LINE, whole lines
/// of 8 doubles): where its output is larger than shape.stream_output_bytes (it would not stay
/// cached until the next stage reads it, and a cached store first reads the line it writes) and
/// every line of entries of the fastest digit starts a cache line (padded or whole lines).
bool streams_output(const FactoredStage& stage, const StageShape& shape);

/// Work-items of a stage with a vector digit on a SIMD device: its rows, or its pairs of rows.
std::uint64_t row_work_items(const FactoredStage& stage, const StageShape& shape);

/// Stage kernel `k` (a stage with a vector digit) for a SIMD device; `fused_next`: the last
/// stage, computed from this one's lines of kept rows (fuses_next in fused_stage.hpp).
void row_stage_kernel(std::ostringstream& s, const FactoredStage& stage, std::size_t k, const StageShape& shape,
                      const FactoredStage* fused_next = nullptr);

}  // namespace amytiss::detail
