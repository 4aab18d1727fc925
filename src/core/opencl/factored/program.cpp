// OpenCL C of the factored sweep: one kernel per elimination stage, with the plan's radices and
// strides as literals (the compiler turns the digit decoding into multiply-shifts), and the
// kernel that takes min over disturbances and max over inputs from Q.
#include "opencl/factored/program.hpp"

#include <algorithm>
#include <sstream>

#include "amytiss/abstraction.hpp"
#include "opencl/factored/fused_stage.hpp"
#include "opencl/factored/kernel_text.hpp"
#include "opencl/factored/row_kernel.hpp"

namespace amytiss::detail {
namespace {

// Each row's FMA chain over cells [lo, hi) of the window into sum<row>; with two rows (a pass over
// both windows) a cell outside a row's own window adds fma(0, v, s) == s exactly.
void entry_chain(std::ostringstream& s, const FactoredStage& stage, const std::vector<std::string>& rows,
                 const std::string& lo, const std::string& hi, const std::string& indent) {
  s << indent << "for (uint c = " << lo << "; c < " << hi << "; ++c) {\n"
    << indent << "  const double value = in[in_index + (ulong)(c - block_first) * " << stage.contracted_stride
    << "UL];\n";
  for (const std::string& row : rows)
    s << indent << "  sum" << row << " = fma("
      << (rows.size() == 1 ? "m" + row + "[c - lo" + row + "]"
                           : "c >= lo" + row + " && c < hi" + row + " ? m" + row + "[c - lo" + row + "] : 0.0")
      << ", value, sum" << row << ");\n";
  s << indent << "}\n";
}

// One entry per work-item, or two along the paired digit (neighbouring states whose windows
// nearly coincide: one pass over their union loads each value once for both, where
// rows_share_pass); the vector digit (if any) fastest, so that neighbouring work-items read
// neighbouring values (SIMT devices, and stages without a vector digit).
void entry_stage_kernel(std::ostringstream& s, const FactoredStage& stage, std::size_t k, const StageShape& shape) {
  const std::vector<std::uint64_t>& strides = stage.output_stride;
  const std::optional<std::size_t> paired = paired_digit(stage, shape);
  std::vector<std::size_t> order;
  for (std::size_t j = 0; j < stage.output.size(); ++j)
    if (stage.vector_digit != j) order.push_back(j);
  if (stage.vector_digit) order.push_back(*stage.vector_digit);
  std::vector<std::uint64_t> radices, input_strides, tuple_strides, out_strides, pair_strides;
  for (std::size_t j : order) {
    const std::uint64_t scale = paired == j ? rows_per_item(stage, shape) : 1;
    radices.push_back((stage.output[j].radix + scale - 1) / scale);
    input_strides.push_back(stage.input_stride[j] * scale);
    tuple_strides.push_back(stage.tuple_stride[j] * scale);
    out_strides.push_back(strides[j] * scale);
    pair_strides.push_back(paired == j ? scale : 0);
  }
  s << kernel_head(k) << "  const ulong item = get_global_id(0);\n"
    << "  if (item >= " << stage_work_items(stage, shape) << "UL) return;\n"
    << "  ulong in_index = in_offset, tuple = 0, out_index = 0, pair_first = 0;\n";
  decode_digits(s, "item", radices, {input_strides, tuple_strides, out_strides, pair_strides},
                {"in_index", "tuple", "out_index", "pair_first"});
  s << "  const ulong tuple_a = tuple;\n  double sum_a = 0.0;\n";
  window_of_tuple(s, stage, "_a", "  ");
  if (!paired) {
    entry_chain(s, stage, {"_a"}, "lo_a", "hi_a", "  ");
    s << "  out[out_index] = accumulate ? out[out_index] + sum_a : sum_a;\n}\n\n";
    return;
  }
  s << "  const bool has_b = pair_first + 1 < " << stage.output[*paired].radix << "UL;\n"
    << "  const ulong tuple_b = tuple + (has_b ? " << stage.tuple_stride[*paired] << "UL : 0UL);\n"
    << "  double sum_b = 0.0;\n";
  window_of_tuple(s, stage, "_b", "  ");
  s << "  const uint lo_ab = min(lo_a, lo_b), hi_ab = max(hi_a, hi_b);\n"
    << "  if (has_b && " << kShareUnionWeight << " * (int)(hi_ab - lo_ab) <= " << kShareCellsWeight
    << " * (cells_a + cells_b)) {\n";
  entry_chain(s, stage, {"_a", "_b"}, "lo_ab", "hi_ab", "    ");
  s << "  } else {\n";
  entry_chain(s, stage, {"_a"}, "lo_a", "hi_a", "    ");
  s << "    if (has_b) {\n";
  entry_chain(s, stage, {"_b"}, "lo_b", "hi_b", "      ");
  s << "    }\n  }\n"
    << "  out[out_index] = accumulate ? out[out_index] + sum_a : sum_a;\n"
    << "  if (has_b) {\n    const ulong out_b = out_index + " << strides[*paired] << "UL;\n"
    << "    out[out_b] = accumulate ? out[out_b] + sum_b : sum_b;\n  }\n}\n\n";
}

void stage_kernel(std::ostringstream& s, const FactoredPlan& plan, std::size_t k, const StageShape& shape) {
  const FactoredStage& stage = plan.stages[k];
  if (stage.vector_digit && shape.row_per_item)
    row_stage_kernel(s, stage, k, shape, fuses_next(plan, k, shape) ? &plan.stages[k + 1] : nullptr);
  else
    entry_stage_kernel(s, stage, k, shape);
}

// Q's radices and strides of the variables of one space, in the variables' order.
std::pair<std::vector<std::uint64_t>, std::vector<std::uint64_t>> q_digits(const FactoredPlan& plan,
                                                                          FactorVariable::Space space) {
  std::vector<std::uint64_t> radices, strides;
  for (std::size_t v = 0; v < plan.variables.size(); ++v) {
    if (plan.variables[v].space != space) continue;
    radices.push_back(plan.variables[v].count);
    strides.push_back(plan.q_stride[v]);
  }
  return {radices, strides};
}

// One state's choice, from `state` and its offset in Q `state_offset`.
void choose_state(std::ostringstream& s, const Abstraction& a, const FactoredPlan& plan, const std::string& indent) {
  const auto [input_radices, input_strides] = q_digits(plan, FactorVariable::Space::Input);
  const auto [dist_radices, dist_strides] = q_digits(plan, FactorVariable::Space::Disturbance);
  std::ostringstream body;
  body << "const uchar role = roles[state];\n"
       << "if (role != " << int(CellRole::Free) << ") {\n"
       << "  v_next[state] = role == " << int(CellRole::FixedOne) << " ? 1.0 : 0.0;\n"
       << "  best_input[state] = 0;\n} else {\n"
       << "double best = -1.0;\nuint best_index = 0;\n"
       << "for (uint input = 0; input < " << a.inputs.size() << "u; ++input) {\n"
       << "  ulong input_offset = state_offset;\n  {\n";
  decode_digits(body, "input", input_radices, {input_strides}, {"input_offset"});
  body << "  }\n  double worst = INFINITY;\n"
       << "  for (uint disturbance = 0; disturbance < " << a.disturbances.size() << "u; ++disturbance) {\n"
       << "    ulong offset = input_offset;\n    {\n";
  decode_digits(body, "disturbance", dist_radices, {dist_strides}, {"offset"});
  body << "    }\n    worst = fmin(worst, q[offset]);\n  }\n"
       << "  if (worst > best) {\n    best = worst;\n    best_index = input;\n  }\n}\n"
       // Exact masses sum to at most 1; the excess of a rounded sum is rounding, not probability.
       << "v_next[state] = fmin(best, 1.0);\nbest_input[state] = best_index;\n}\n";
  std::istringstream lines(body.str());
  for (std::string line; std::getline(lines, line);) s << indent << line << "\n";
}

// Runs of states need a second component to order the runs by (one component: a state each).
bool runs_of_states(const Abstraction& a, const StageShape& shape) {
  return shape.states_in_q_order && a.states.dims() > 1;
}

// max over inputs of min over disturbances of Q; ties: the lowest input index. One state per
// work-item; or (states_in_q_order) a run of the last state component (contiguous states) per
// work-item, the work-items in Q's order of the other components, so that consecutive
// work-items read neighbouring stretches of Q instead of one cache line each far apart.
void choose_inputs_kernel(std::ostringstream& s, const Abstraction& a, const FactoredPlan& plan,
                          const StageShape& shape) {
  auto [radices, q_strides] = q_digits(plan, FactorVariable::Space::State);
  std::vector<std::uint64_t> state_strides(radices.size());
  std::uint64_t stride = 1;
  for (std::size_t j = radices.size(); j-- > 0;) {
    state_strides[j] = stride;
    stride *= radices[j];
  }
  s << "// max over inputs of min over disturbances of Q; ties: the lowest input index.\n"
       "__kernel void choose_inputs(__global const double* q, __global double* v_next,\n"
       "    __global uint* best_input, __global const uchar* roles) {\n"
    << "  const ulong item = get_global_id(0);\n"
    << "  if (item >= " << choose_work_items(a, shape) << "UL) return;\n";
  if (!runs_of_states(a, shape)) {
    s << "  const ulong state = item;\n  ulong state_offset = 0;\n  {\n";
    decode_digits(s, "state", radices, {q_strides}, {"state_offset"});
    s << "  }\n";
    choose_state(s, a, plan, "  ");
    s << "}\n";
    return;
  }
  const std::uint64_t run = radices.back(), run_q_stride = q_strides.back();
  std::vector<std::size_t> order(radices.size() - 1);
  for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t i, std::size_t j) { return q_strides[i] > q_strides[j]; });
  std::vector<std::uint64_t> item_radices, item_q_strides, item_state_strides;
  for (std::size_t j : order) {
    item_radices.push_back(radices[j]);
    item_q_strides.push_back(q_strides[j]);
    item_state_strides.push_back(state_strides[j]);
  }
  s << "  ulong first_state = 0, first_offset = 0;\n  {\n";
  decode_digits(s, "item", item_radices, {item_state_strides, item_q_strides}, {"first_state", "first_offset"});
  s << "  }\n  for (uint cell = 0; cell < " << run << "u; ++cell) {\n"
    << "    const ulong state = first_state + cell;\n"
    << "    const ulong state_offset = first_offset + (ulong)cell * " << run_q_stride << "UL;\n";
  choose_state(s, a, plan, "    ");
  s << "  }\n}\n";
}

}  // namespace

StageShape stage_shape_for(unsigned native_double_width) {
  StageShape shape;
  shape.row_per_item = native_double_width > 1;
  shape.states_in_q_order = shape.row_per_item;
  shape.native_double_width = native_double_width;
  return shape;
}

std::uint64_t stage_work_items(const FactoredStage& stage, const StageShape& shape) {
  if (stage.vector_digit && shape.row_per_item) return row_work_items(stage, shape);
  const std::optional<std::size_t> paired = paired_digit(stage, shape);
  if (!paired) return stage.output_entries;
  const std::uint64_t radix = stage.output[*paired].radix, group = rows_per_item(stage, shape);
  return stage.output_entries / radix * ((radix + group - 1) / group);
}

std::uint64_t choose_work_items(const Abstraction& abstraction, const StageShape& shape) {
  const std::size_t states = abstraction.states.size();
  return runs_of_states(abstraction, shape) ? states / abstraction.states.count(abstraction.states.dims() - 1) : states;
}

std::string factored_program_source(const Abstraction& abstraction, const FactoredPlan& plan,
                                    const StageShape& shape) {
  std::ostringstream s;
  s << "// Generated by amytiss: the factored sweep of one problem (see src/core/factored/factored_plan.hpp)\n"
    << "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n\n"
    << "// A line of 8 doubles to a 64-byte aligned address, past the caches where the compiler can.\n"
    << "#if defined(__has_builtin)\n#if __has_builtin(__builtin_nontemporal_store)\n"
    << "#define AMYTISS_STREAM_LINE(line, target) __builtin_nontemporal_store(line, (__global double8*)(target))\n"
    << "#endif\n#endif\n#ifndef AMYTISS_STREAM_LINE\n"
    << "#define AMYTISS_STREAM_LINE(line, target) vstore8(line, 0, target)\n#endif\n\n";
  for (std::size_t k = 0; k < plan.stages.size(); ++k) stage_kernel(s, plan, k, shape);
  choose_inputs_kernel(s, abstraction, plan, shape);
  return s.str();
}

}  // namespace amytiss::detail
