// Why two (or four) rows per work-item: on a CPU a row's contraction loads a vector of values per
// FMA, and the loads, not the FMAs, bound it (the stage's values come from L2, a cache line or two
// per vector). Rows whose windows cover nearly the same cells of the same values (neighbouring
// values of a digit that picks only masses: neighbouring states whose post coordinates lie a
// fraction of a cell apart) load each vector once for two (four) FMAs.
#include "opencl/factored/row_kernel.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "factored/factored_layout.hpp"
#include "opencl/factored/fused_stage.hpp"
#include "opencl/factored/kernel_text.hpp"

namespace amytiss::detail {
namespace {

// The work-item digits of a row kernel: every output digit but the vector digit.
struct ItemDigits {
  std::vector<std::uint64_t> radices, input_strides, tuple_strides, out_strides, pair_strides, tile_strides;
  std::vector<std::uint64_t> next_tuple_strides, next_out_strides;  ///< a fused next stage's
};

// Rows per work-item where the vector digit is not the output's fastest digit (a row's entries
// lie a line or more apart): a line of neighbouring entries of the fastest digit, kept in private
// memory and stored a line at a time instead of one entry per line.
constexpr std::uint64_t kStoreTile = 8;
static_assert(kStoreTile == kLineDoubles, "a streamed line of kept rows is one cache line");

// Values the rows between two visits of the same block may read in output order for that block
// to be still in a core's cache (the L2 of the CPUs measured: 512 KiB).
constexpr double kRowReuseBytes = 512.0 * 1024;

// After the major digit (kept major: a team splits a stage's rows by it), the digits that pick
// only masses (input stride 0) fastest, so that consecutive work-items of a group (run one after
// another by a CPU thread) contract the same block of values with windows shifted by a cell or
// so: the block stays in the core's cache instead of being fetched again after a pass over every
// other block. Only where those passes outgrow the cache: otherwise output order already reuses
// the blocks, and writes its rows' lanes (often a cache line apart) line by line.
void order_rows_by_window(const FactoredStage& stage, std::uint64_t radix, ItemDigits& digits) {
  double pass_bytes = double(stage.width) * double(radix) * sizeof(double);
  for (std::size_t j = digits.radices.size(); j-- > 1 && digits.input_strides[j] != 0;)
    pass_bytes *= double(digits.radices[j]) * double(digits.tile_strides[j] ? kStoreTile : 1);
  if (pass_bytes <= kRowReuseBytes) return;
  std::vector<std::size_t> order(digits.radices.size());
  for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
  if (order.size() > 1)
    std::stable_partition(order.begin() + 1, order.end(), [&](std::size_t j) { return digits.input_strides[j] != 0; });
  for (auto* values :
       {&digits.radices, &digits.input_strides, &digits.tuple_strides, &digits.out_strides, &digits.pair_strides,
        &digits.tile_strides, &digits.next_tuple_strides, &digits.next_out_strides}) {
    std::vector<std::uint64_t> permuted;
    for (std::size_t j : order) permuted.push_back((*values)[j]);
    *values = permuted;
  }
}

// Entries per vector of a row of `radix` entries.
std::uint64_t row_lanes(std::uint64_t radix) { return radix >= 8 ? 8 : radix >= 4 ? 4 : 2; }

// Doubles a work-item's accumulators may hold: 24 vector registers of 32 with AVX-512, 12 of 16
// with AVX2 (the rest hold the masses and the addresses).
std::uint64_t accumulator_doubles(unsigned native_double_width) {
  return (native_double_width >= 8 ? 24 : 12) * std::uint64_t(native_double_width);
}

// What the passes of a row kernel share: the stage, the row's shape and where results go.
struct RowPass {
  const FactoredStage& stage;
  std::uint64_t radix, lanes, lane_stride, accumulators;
  std::string indent;
  std::string in_index = "in_index";  ///< the rows' first value in the input
  bool kept = false;                  ///< store into kept<row>[entry * kStoreTile + r], not out
  bool stream = false;                ///< streams_output(): whole lines past the caches
  const FactoredStage* next = nullptr;  ///< the last stage, fused: lines of kept rows go into Q
  std::uint64_t group = 1;              ///< rows along the paired digit (rows_per_item)
};

// Stores entry `entry` .. + lanes - 1 of a row: one line past the caches where the row's entries
// are contiguous and the output streams (lanes beyond the row, in its padding, set to 0), else
// entry by entry.
void store_chunk(std::ostringstream& s, const RowPass& pass, const std::string& row, const std::string& sum,
                 std::uint64_t entry, std::uint64_t valid) {
  const std::string& in = pass.indent;
  const std::string target = "out + out_index" + row + " + " + std::to_string(entry * pass.lane_stride) + "UL";
  auto lane = [&](std::uint64_t l) { return sum + ".s" + "01234567"[l]; };
  if (pass.stream && pass.lane_stride == 1 && pass.lanes == kLineDoubles) {
    s << in << "  {\n" << in << "    __global double* target = " << target << ";\n"
      << in << "    if (accumulate) {\n";
    for (std::uint64_t l = 0; l < valid; ++l) s << in << "      target[" << l << "] += " << lane(l) << ";\n";
    std::string line = sum;
    if (valid < pass.lanes) {
      line = "(double8)(";
      for (std::uint64_t l = 0; l < pass.lanes; ++l) line += (l ? ", " : "") + (l < valid ? lane(l) : "0.0");
      line += ")";
    }
    s << in << "    } else {\n" << in << "      AMYTISS_STREAM_LINE(" << line << ", target);\n"
      << in << "    }\n" << in << "  }\n";
    return;
  }
  for (std::uint64_t l = 0; l < valid; ++l)
    s << in << "  { __global double* target = out + out_index" << row << " + " << (entry + l) * pass.lane_stride
      << "UL; *target = accumulate ? *target + " << lane(l) << " : " << lane(l) << "; }\n";
}

// One pass over cells [lo, hi) of the window per block of the row's chunks: per cell, the
// block's stretch of the row (contiguous values) is loaded once, a vector per chunk, and added
// with each named row's mass into that row's accumulators. Where the window's rows lie one after
// another (the vector digit spans the contracted cell's stride), a block as wide as the row reads
// the window in memory order: a stream the hardware prefetches. A row's mass outside its own
// window is 0, and fma(0, v, s) == s for every finite v: each entry is the same FMA chain over
// its own cells, in order, as one row alone would compute.
void row_pass(std::ostringstream& s, const RowPass& pass, const std::vector<std::string>& rows, const std::string& lo,
              const std::string& hi) {
  const std::uint64_t chunks = (pass.radix + pass.lanes - 1) / pass.lanes;
  const std::uint64_t per_block = std::clamp<std::uint64_t>(pass.accumulators / rows.size(), 1, chunks);
  const std::string vector_type = "double" + std::to_string(pass.lanes), in = pass.indent;
  const bool alone = rows.size() == 1;
  for (std::uint64_t first = 0; first < chunks; first += per_block) {
    const std::uint64_t count = std::min(per_block, chunks - first);
    s << in << "{\n";
    for (const std::string& row : rows)
      for (std::uint64_t j = 0; j < count; ++j) s << in << "  " << vector_type << " sum" << row << j << " = 0.0;\n";
    s << in << "  __global const double* line = in + " << pass.in_index << " + (ulong)(" << lo << " - block_first) * "
      << pass.stage.contracted_stride << "UL + " << first * pass.lanes << "UL;\n"
      << in << "  for (uint c = " << lo << "; c < " << hi << "; ++c, line += " << pass.stage.contracted_stride
      << "UL) {\n";
    for (const std::string& row : rows)
      s << in << "    const " << vector_type << " mass" << row << " = (" << vector_type << ")("
        << (alone ? "m" + row + "[c - lo" + row + "]"
                  : "c >= lo" + row + " && c < hi" + row + " ? m" + row + "[c - lo" + row + "] : 0.0")
        << ");\n";
    for (std::uint64_t j = 0; j < count; ++j) {
      s << in << "    {\n" << in << "      const " << vector_type << " values = vload" << pass.lanes << "(" << j
        << ", line);\n";
      for (const std::string& row : rows)
        s << in << "      sum" << row << j << " = fma(mass" << row << ", values, sum" << row << j << ");\n";
      s << in << "    }\n";
    }
    s << in << "  }\n";
    // A group's pass computes every row; a row the paired digit lacks (past its last value) is
    // not stored: its entries would land on another row's.
    for (const std::string& row : rows)
      for (std::uint64_t j = 0; j < count; ++j) {
        const std::uint64_t chunk = first + j, valid = std::min(pass.lanes, pass.radix - chunk * pass.lanes);
        const std::string sum = "sum" + row + std::to_string(j);
        if (!pass.kept) {
          const bool guarded = row != "_a";
          if (guarded) s << in << "  if (has" << row << ") {\n";
          store_chunk(s, pass, row, sum, chunk * pass.lanes, valid);
          if (guarded) s << in << "  }\n";
          continue;
        }
        for (std::uint64_t lane = 0; lane < valid; ++lane)
          s << in << "  kept" << row << "[" << (chunk * pass.lanes + lane) * kStoreTile << " + r] = " << sum << ".s"
            << "01234567"[lane] << ";\n";
      }
    s << in << "}\n";
  }
}

// The kernel's body after the digit decoding, with a paired digit: rows _a, _b, ... (row_name),
// those past _a where the digit has their values (has_<row>); one pass for all where
// rows_share_pass over the union of their windows, else a pass each.
void grouped_rows(std::ostringstream& s, const RowPass& pass, const std::string& tuple, std::uint64_t pair_tuple_stride,
                  std::uint64_t group) {
  const std::string& in = pass.indent;
  std::vector<std::string> rows;
  for (std::uint64_t i = 0; i < group; ++i) rows.push_back(row_name(i));
  s << in << "const ulong tuple_a = " << tuple << ";\n";
  for (std::uint64_t i = 1; i < group; ++i)
    s << in << "const ulong tuple" << rows[i] << " = " << tuple << " + (has" << rows[i] << " ? "
      << i * pair_tuple_stride << "UL : 0UL);\n";
  for (const std::string& row : rows) window_of_tuple(s, pass.stage, row, in);
  // A row the digit lacks repeats row _a's window: the union is that of the rows present.
  std::string lo = "lo_a", hi = "hi_a", cells = "cells_a";
  for (std::uint64_t i = 1; i < group; ++i) {
    lo = "min(" + lo + ", lo" + rows[i] + ")";
    hi = "max(" + hi + ", hi" + rows[i] + ")";
    cells += " + (has" + rows[i] + " ? cells" + rows[i] + " : 0)";
  }
  s << in << "const uint lo_all = " << lo << ", hi_all = " << hi << ";\n"
    << in << "if (has_b && " << kShareUnionWeight << " * (int)(hi_all - lo_all) <= " << kShareCellsWeight << " * ("
    << cells << ")) {\n";
  RowPass inner = pass;
  inner.indent = in + "  ";
  row_pass(s, inner, rows, "lo_all", "hi_all");
  s << in << "} else {\n";
  row_pass(s, inner, {"_a"}, "lo_a", "hi_a");
  inner.indent = in + "    ";
  for (std::uint64_t i = 1; i < group; ++i) {
    s << in << "  if (has" << rows[i] << ") {\n";
    row_pass(s, inner, {rows[i]}, "lo" + rows[i], "hi" + rows[i]);
    s << in << "  }\n";
  }
  s << in << "}\n";
}

// The rows of a work-item (one, or a group) from tuple `tuple` and input index `pass.in_index`.
void item_rows(std::ostringstream& s, const RowPass& pass, const std::string& tuple,
               std::optional<std::uint64_t> pair_tuple_stride) {
  if (pair_tuple_stride) {
    grouped_rows(s, pass, tuple, *pair_tuple_stride, pass.group);
    return;
  }
  s << pass.indent << "const ulong tuple_a = " << tuple << ";\n";
  window_of_tuple(s, pass.stage, "_a", pass.indent);
  row_pass(s, pass, {"_a"}, "lo_a", "hi_a");
}


// A line of kStoreTile rows along digit `tiled` (the output's fastest), each row (or pair) into
// private memory, then the line's entries stored side by side.
void tiled_rows(std::ostringstream& s, RowPass pass, std::size_t tiled, std::optional<std::uint64_t> pair_tuple_stride,
                const StageShape& shape) {
  const FactoredStage& stage = pass.stage;
  std::vector<std::string> rows;
  for (std::uint64_t i = 0; i < pass.group; ++i) rows.push_back(row_name(i));
  for (const std::string& row : rows) s << "  double kept" << row << "[" << pass.radix * kStoreTile << "];\n";
  s << "  const uint tile_rows = min(" << kStoreTile << "u, " << stage.output[tiled].radix
    << "u - (uint)tile_first);\n"
    << "  for (uint r = 0; r < tile_rows; ++r) {\n"
    << "    const ulong tuple_r = tuple + (ulong)r * " << stage.tuple_stride[tiled] << "UL;\n"
    << "    const ulong in_index_r = in_index + (ulong)r * " << stage.input_stride[tiled] << "UL;\n";
  pass.indent = "    ";
  pass.in_index = "in_index_r";
  pass.kept = true;
  item_rows(s, pass, "tuple_r", pair_tuple_stride);
  s << "  }\n";
  if (pass.next) {
    contract_kept_lines(s, stage, *pass.next, paired_digit(stage, shape), rows);
    return;
  }
  for (const std::string& row : rows) {
    const bool guarded = row != "_a";
    const std::string indent = guarded ? "    " : "  ";
    if (guarded) s << "  if (has" << row << ") {\n";
    s << indent << "for (uint entry = 0; entry < " << pass.radix << "u; ++entry) {\n"
      << indent << "  __global double* line = out + out_index" << row << " + (ulong)entry * " << pass.lane_stride
      << "UL;\n";
    // A streamed line of kStoreTile entries starts a cache line; the last one of the digit ends in
    // its padding, which gets zeros.
    if (pass.stream)
      s << indent << "  if (!accumulate) {\n"
        << indent << "    for (uint r = tile_rows; r < " << kStoreTile << "u; ++r) kept" << row << "[entry * "
        << kStoreTile << "u + r] = 0.0;\n"
        << indent << "    AMYTISS_STREAM_LINE(vload8(entry, kept" << row << "), line);\n"
        << indent << "    continue;\n" << indent << "  }\n";
    s << indent << "  for (uint r = 0; r < tile_rows; ++r)\n"
      << indent << "    line[r] = accumulate ? line[r] + kept" << row << "[entry * " << kStoreTile << "u + r] : kept"
      << row << "[entry * " << kStoreTile << "u + r];\n"
      << indent << "}\n";
    if (guarded) s << "  }\n";
  }
}

}  // namespace

std::optional<std::size_t> paired_digit(const FactoredStage& stage, const StageShape& shape) {
  std::optional<std::size_t> best;
  if (shape.split_by_team && !stage.vector_digit) return best;  // a team splits it by entries
  const std::size_t first = shape.split_by_team ? *stage.vector_digit + 1 : 0;
  for (std::size_t j = first; j < stage.output.size(); ++j) {
    if (stage.vector_digit == j || stage.input_stride[j] != 0 || stage.tuple_stride[j] == 0) continue;
    if (stage.output[j].radix < 2) continue;
    if (!best || stage.output[j].radix >= stage.output[*best].radix) best = j;
  }
  return best;
}

std::optional<std::size_t> tiled_digit(const FactoredStage& stage, const StageShape& shape) {
  const std::size_t last = stage.output.size() - 1;
  if (stage.vector_digit == last || paired_digit(stage, shape) == last || stage.output[last].radix <= 2)
    return std::nullopt;
  return last;
}

std::string row_name(std::uint64_t i) { return std::string("_") + char('a' + i); }

std::uint64_t rows_per_item(const FactoredStage& stage, const StageShape& shape) {
  const std::optional<std::size_t> paired = paired_digit(stage, shape);
  if (!paired) return 1;
  if (!stage.vector_digit || !shape.row_per_item) return 2;
  const std::uint64_t radix = stage.output[*stage.vector_digit].radix, lanes = row_lanes(radix);
  const std::uint64_t chunks = (radix + lanes - 1) / lanes;
  const std::uint64_t accumulators = accumulator_doubles(shape.native_double_width) / lanes;
  return kMaxRowsPerItem * chunks <= accumulators && stage.output[*paired].radix >= kMaxRowsPerItem ? kMaxRowsPerItem
                                                                                                    : 2;
}

bool streams_output(const FactoredStage& stage, const StageShape& shape) {
  const std::size_t digits = stage.output.size();
  const bool lines_start_lines = digits > 1 && stage.output_stride[digits - 2] % kLineDoubles == 0;
  return lines_start_lines && double(stage.output_size) * sizeof(double) > shape.stream_output_bytes;
}

std::uint64_t row_work_items(const FactoredStage& stage, const StageShape& shape) {
  std::uint64_t items = stage.output_entries / stage.output[*stage.vector_digit].radix;
  auto group = [&](std::optional<std::size_t> digit, std::uint64_t size) {
    if (!digit) return;
    const std::uint64_t radix = stage.output[*digit].radix;
    items = items / radix * ((radix + size - 1) / size);
  };
  group(paired_digit(stage, shape), rows_per_item(stage, shape));
  group(tiled_digit(stage, shape), kStoreTile);
  return items;
}

void row_stage_kernel(std::ostringstream& s, const FactoredStage& stage, std::size_t k, const StageShape& shape,
                      const FactoredStage* fused_next) {
  const std::size_t vector_digit = *stage.vector_digit;
  const std::uint64_t radix = stage.output[vector_digit].radix;
  const std::vector<std::uint64_t>& strides = stage.output_stride;
  const std::optional<std::size_t> paired = paired_digit(stage, shape), tiled = tiled_digit(stage, shape);
  const std::uint64_t group = rows_per_item(stage, shape);
  ItemDigits digits;
  const NextStrides next = fused_next ? next_strides(stage, *fused_next) : NextStrides{};
  for (std::size_t j = 0; j < stage.output.size(); ++j) {
    if (j == vector_digit) continue;
    const std::uint64_t scale = paired == j ? group : tiled == j ? kStoreTile : 1;
    digits.next_tuple_strides.push_back(fused_next ? next.tuple[j] * scale : 0);
    digits.next_out_strides.push_back(fused_next ? next.out[j] * scale : 0);
    digits.radices.push_back((stage.output[j].radix + scale - 1) / scale);
    digits.input_strides.push_back(stage.input_stride[j] * scale);
    digits.tuple_strides.push_back(stage.tuple_stride[j] * scale);
    digits.out_strides.push_back(strides[j] * scale);
    digits.pair_strides.push_back(paired == j ? group : 0);
    digits.tile_strides.push_back(tiled == j ? kStoreTile : 0);
  }
  if (!shape.rows_in_output_order) order_rows_by_window(stage, radix, digits);
  s << kernel_head(k, fused_next) << "  const ulong item = get_global_id(0);\n"
    << "  if (item >= " << row_work_items(stage, shape) << "UL) return;\n"
    << "  ulong in_index = in_offset, tuple = 0, out_index = 0, pair_first = 0, tile_first = 0, next_tuple = 0, "
       "next_out = 0;\n";
  decode_digits(s, "item", digits.radices,
                {digits.input_strides, digits.tuple_strides, digits.out_strides, digits.pair_strides,
                 digits.tile_strides, digits.next_tuple_strides, digits.next_out_strides},
                {"in_index", "tuple", "out_index", "pair_first", "tile_first", "next_tuple", "next_out"});
  s << "  const ulong out_index_a = out_index;\n";
  for (std::uint64_t i = 1; i < group; ++i)
    s << "  const bool has" << row_name(i) << " = pair_first + " << i << " < " << stage.output[*paired].radix << "UL;\n"
      << "  const ulong out_index" << row_name(i) << " = out_index + " << i * strides[*paired] << "UL;\n";
  std::optional<std::uint64_t> pair_tuple_stride;
  if (paired) pair_tuple_stride = stage.tuple_stride[*paired];
  const std::uint64_t lanes = row_lanes(radix);
  RowPass pass{stage, radix, lanes, strides[vector_digit], accumulator_doubles(shape.native_double_width) / lanes,
               "  "};
  pass.stream = streams_output(stage, shape);
  pass.next = fused_next;
  pass.group = group;
  if (tiled)
    tiled_rows(s, pass, *tiled, pair_tuple_stride, shape);
  else
    item_rows(s, pass, "tuple", pair_tuple_stride);
  s << "}\n\n";
}

}  // namespace amytiss::detail
