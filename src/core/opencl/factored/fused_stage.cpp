#include "opencl/factored/fused_stage.hpp"

#include "opencl/factored/kernel_text.hpp"
#include "opencl/factored/row_kernel.hpp"

namespace amytiss::detail {
namespace {

// The digit of `next`'s output of the same variable as `digit`, if any.
std::optional<std::size_t> digit_in(const FactoredStage& next, const TensorDigit& digit) {
  for (std::size_t j = 0; j < next.output.size(); ++j)
    if (next.output[j].post == digit.post && next.output[j].id == digit.id) return j;
  return std::nullopt;
}

}  // namespace

bool fuses_next(const FactoredPlan& plan, std::size_t k, const StageShape& shape) {
  if (!shape.row_per_item || shape.split_by_team || plan.slices != 1 || k + 2 != plan.stages.size()) return false;
  const FactoredStage &stage = plan.stages[k], &next = plan.stages[k + 1];
  if (!stage.vector_digit || !next.vector_digit) return false;
  const std::optional<std::size_t> tiled = tiled_digit(stage, shape);
  if (!tiled) return false;
  const TensorDigit& contracted = stage.output[*stage.vector_digit];
  return contracted.post && contracted.id == next.dimension &&
         digit_in(next, stage.output[*tiled]) == next.vector_digit;
}

NextStrides next_strides(const FactoredStage& stage, const FactoredStage& next) {
  NextStrides strides;
  for (const TensorDigit& digit : stage.output) {
    const std::optional<std::size_t> j = digit_in(next, digit);
    strides.tuple.push_back(j ? next.tuple_stride[*j] : 0);
    strides.out.push_back(j ? next.output_stride[*j] : 0);
  }
  return strides;
}

void contract_kept_lines(std::ostringstream& s, const FactoredStage& stage, const FactoredStage& next,
                         std::optional<std::size_t> paired, const std::vector<std::string>& rows) {
  // Variables new to `next` (read by its masses only): every tuple of them, for each line.
  std::vector<std::uint64_t> fresh_radices, fresh_tuple, fresh_out;
  std::uint64_t fresh_tuples = 1;
  for (std::size_t j = 0; j < next.output.size(); ++j) {
    if (next.input_stride[j] != 0) continue;
    fresh_radices.push_back(next.output[j].radix);
    fresh_tuple.push_back(next.tuple_stride[j]);
    fresh_out.push_back(next.output_stride[j]);
    fresh_tuples *= next.output[j].radix;
  }
  const NextStrides strides = next_strides(stage, next);
  const std::uint64_t line_stride = next.output_stride[*next.vector_digit];
  s << "  for (uint fresh = 0; fresh < " << fresh_tuples << "u; ++fresh) {\n"
    << "    ulong next_tuple_f = next_tuple, next_out_f = next_out;\n    {\n";
  decode_digits(s, "fresh", fresh_radices, {fresh_tuple, fresh_out}, {"next_tuple_f", "next_out_f"});
  s << "    }\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string& row = rows[i];
    const std::string tuple_shift = i ? " + " + std::to_string(i * strides.tuple[*paired]) + "UL" : "";
    const std::string out_shift = i ? " + " + std::to_string(i * strides.out[*paired]) + "UL" : "";
    s << (i ? "    if (has" + row + ") {\n" : "    {\n") << "      const ulong tuple_n = next_tuple_f" << tuple_shift
      << ";\n"
      << "      const uint lo_n = next_first[tuple_n];\n"
      << "      const int cells_n = (int)next_count[tuple_n];\n"
      << "      __global const double* m_n = next_masses + tuple_n * " << next.width << "UL;\n"
      << "      double8 line = 0.0;\n"
      << "      for (int c = 0; c < cells_n; ++c)\n"
      << "        line = fma((double8)(m_n[c]), vload8(lo_n + (uint)c, kept" << row << "), line);\n"
      << "      __global double* target = out + next_out_f" << out_shift << ";\n";
    const char* lanes = "01234567";
    for (std::uint64_t r = 0; r < 8; ++r)
      s << "      " << (r ? "if (tile_rows > " + std::to_string(r) + "u) " : "") << "target[" << r * line_stride
        << "UL] = line.s" << lanes[r] << ";\n";
    s << "    }\n";
  }
  s << "  }\n";
}

}  // namespace amytiss::detail
