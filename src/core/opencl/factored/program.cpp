// OpenCL C of the factored sweep: one kernel per elimination stage, with the plan's radices and
// strides as literals (the compiler turns the digit decoding into multiply-shifts), and the
// kernel that takes min over disturbances and max over inputs from Q.
#include "opencl/factored/program.hpp"

#include <algorithm>
#include <sstream>

#include "amytiss/abstraction.hpp"

namespace amytiss::detail {
namespace {


// Digit decoding of `index` into the sums of digit * stride for each named target, minor digit
// first. Digits whose strides are all zero are skipped, except for advancing the remainder.
void decode_digits(std::ostringstream& s, const std::string& index, const std::vector<std::uint64_t>& radices,
                   const std::vector<std::vector<std::uint64_t>>& strides, const std::vector<std::string>& targets) {
  s << "  ulong rest = " << index << ";\n";
  for (std::size_t j = radices.size(); j-- > 0;) {
    bool used = false;
    for (const auto& target_strides : strides) used = used || target_strides[j] != 0;
    const bool major = j == 0;
    if (!used) {
      if (!major) s << "  rest /= " << radices[j] << "UL;\n";
      continue;
    }
    s << "  {\n    const ulong digit = " << (major ? "rest" : "rest % " + std::to_string(radices[j]) + "UL") << ";\n";
    for (std::size_t t = 0; t < targets.size(); ++t)
      if (strides[t][j]) s << "    " << targets[t] << " += digit * " << strides[t][j] << "UL;\n";
    if (!major) s << "    rest /= " << radices[j] << "UL;\n";
    s << "  }\n";
  }
}

std::string kernel_head(std::size_t k) {
  return "__kernel void stage" + std::to_string(k) +
         "(__global const double* in, __global double* out, __global const uint* first,\n"
         "    __global const uint* count, __global const double* masses, ulong in_offset, uint block_first,\n"
         "    uint block_end, uint accumulate) {\n";
}

// The kept cells of the tuple's window that lie in the block of the contracted dimension held by
// the input ([block_first, block_end): all of it, except in the last stage of a slice).
void window_of_tuple(std::ostringstream& s, const FactoredStage& stage) {
  s << "  const uint kept_first = first[tuple];\n"
       "  const uint lo = max(kept_first, block_first);\n"
       "  const uint hi = min(kept_first + count[tuple], block_end);\n"
       "  const int cells = (int)hi - (int)lo;\n"
    << "  __global const double* m = masses + tuple * " << stage.width << "UL + (lo - kept_first);\n"
    << "  __global const double* v = in + in_index + (ulong)(lo - block_first) * " << stage.contracted_stride
    << "UL;\n";
}

// One output entry per work-item (entries that share no masses or no contiguous values).
void scalar_stage_kernel(std::ostringstream& s, const FactoredStage& stage, std::size_t k) {
  std::vector<std::uint64_t> radices;
  for (const TensorDigit& digit : stage.output) radices.push_back(digit.radix);
  s << kernel_head(k) << "  const ulong entry = get_global_id(0);\n"
    << "  if (entry >= " << stage.output_size << "UL) return;\n"
    << "  ulong in_index = in_offset, tuple = 0;\n";
  decode_digits(s, "entry", radices, {stage.input_stride, stage.tuple_stride}, {"in_index", "tuple"});
  window_of_tuple(s, stage);
  s << "  double sum = 0.0;\n"
    << "  for (int c = 0; c < cells; ++c) sum = fma(m[c], v[(ulong)c * " << stage.contracted_stride << "UL], sum);\n"
    << "  out[entry] = accumulate ? out[entry] + sum : sum;\n}\n\n";
}

// Values the rows between two visits of the same block may read in output order for that block
// to be still in a core's cache (the L2 of the CPUs measured: 512 KiB).
constexpr double kRowReuseBytes = 512.0 * 1024;

// SIMD rows: after the major digit (kept major: a team splits a stage's rows by it), the digits
// that pick only masses (input stride 0) fastest, so that consecutive work-items of a group (run
// one after another by a CPU thread) contract the same block of values with windows shifted by
// a cell or so: the block stays in the core's cache instead of being fetched again after a pass
// over every other block. Only where those passes outgrow the cache: otherwise output order
// already reuses the blocks, and writes its rows' lanes (often a cache line apart) line by line.
void order_rows_by_window(const FactoredStage& stage, std::uint64_t radix, std::vector<std::uint64_t>& radices,
                          std::vector<std::uint64_t>& input_strides, std::vector<std::uint64_t>& tuple_strides,
                          std::vector<std::uint64_t>& out_strides) {
  double pass_bytes = double(stage.width) * double(radix) * sizeof(double);
  for (std::size_t j = radices.size(); j-- > 1 && input_strides[j] != 0;) pass_bytes *= double(radices[j]);
  if (pass_bytes <= kRowReuseBytes) return;
  std::vector<std::size_t> order(radices.size());
  for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
  if (order.size() > 1)
    std::stable_partition(order.begin() + 1, order.end(), [&](std::size_t j) { return input_strides[j] != 0; });
  auto permuted = [&](const std::vector<std::uint64_t>& values) {
    std::vector<std::uint64_t> result;
    for (std::size_t j : order) result.push_back(values[j]);
    return result;
  };
  radices = permuted(radices);
  input_strides = permuted(input_strides);
  tuple_strides = permuted(tuple_strides);
  out_strides = permuted(out_strides);
}

// Entries along the vector digit share the tuple (masses, window) and read contiguous values.
// SIMD devices: one work-item per row of the vector digit, LANES entries per vector load and FMA,
// the row in chunks of LANES. SIMT devices: one work-item per entry (LANES 1), the vector digit
// fastest, so that neighbouring work-items read neighbouring values. Either way each entry is
// one FMA chain over its window cells in order: the same arithmetic as scalar_stage_kernel. The
// last chunk of a row may read past the row (buffers have kTensorSlack cells after their end)
// and stores only its valid lanes.
void vector_stage_kernel(std::ostringstream& s, const FactoredStage& stage, std::size_t k, const StageShape& shape) {
  const std::size_t vector_digit = *stage.vector_digit;
  const std::uint64_t radix = stage.output[vector_digit].radix;
  const std::uint64_t lanes = shape.lanes(radix);
  const std::uint64_t chunks = (radix + lanes - 1) / lanes;
  std::vector<std::uint64_t> output_strides(stage.output.size());
  std::uint64_t stride = 1;
  for (std::size_t j = stage.output.size(); j-- > 0;) {
    output_strides[j] = stride;
    stride *= stage.output[j].radix;
  }
  // Work-item digits: the other output digits, then (SIMT) the chunk of the vector digit.
  std::vector<std::uint64_t> radices, input_strides, tuple_strides, out_strides;
  for (std::size_t j = 0; j < stage.output.size(); ++j) {
    if (j == vector_digit) continue;
    radices.push_back(stage.output[j].radix);
    input_strides.push_back(stage.input_stride[j]);
    tuple_strides.push_back(stage.tuple_stride[j]);
    out_strides.push_back(output_strides[j]);
  }
  const std::uint64_t lane_stride = output_strides[vector_digit];
  if (shape.row_per_item) {
    if (!shape.rows_in_output_order)
      order_rows_by_window(stage, radix, radices, input_strides, tuple_strides, out_strides);
  } else {
    radices.push_back(chunks);
    input_strides.push_back(lanes);
    tuple_strides.push_back(0);
    out_strides.push_back(lanes * lane_stride);
  }
  const std::string vector_type = lanes == 1 ? "double" : "double" + std::to_string(lanes);
  const std::string load = lanes == 1 ? "*(v + (ulong)c * " + std::to_string(stage.contracted_stride) + "UL)"
                                      : "vload" + std::to_string(lanes) + "(0, v + (ulong)c * " +
                                            std::to_string(stage.contracted_stride) + "UL)";
  s << kernel_head(k) << "  const ulong item = get_global_id(0);\n"
    << "  if (item >= " << stage_work_items(stage, shape) << "UL) return;\n"
    << "  ulong in_index = in_offset, tuple = 0, out_index = 0;\n";
  decode_digits(s, "item", radices, {input_strides, tuple_strides, out_strides}, {"in_index", "tuple", "out_index"});
  window_of_tuple(s, stage);
  if (shape.row_per_item)
    s << "  for (uint chunk = 0; chunk < " << chunks << "u; ++chunk, v += " << lanes << ", out_index += "
      << lanes * lane_stride << "UL) {\n";
  else
    s << "  {\n    const uint chunk = (uint)(item % " << chunks << "UL);\n";
  s << "    " << vector_type << " sum = 0.0;\n"
    << "    for (int c = 0; c < cells; ++c) sum = fma((" << vector_type << ")(m[c]), " << load << ", sum);\n";
  if (lanes == 1) {
    s << "    out[out_index] = accumulate ? out[out_index] + sum : sum;\n";
  } else {
    s << "    const uint valid = min(" << lanes << "u, " << radix << "u - chunk * " << lanes << "u);\n"
      << "    const double lane_sums[" << lanes << "] = {";
    for (std::uint64_t lane = 0; lane < lanes; ++lane) s << (lane ? ", " : "") << "sum.s" << "01234567"[lane];
    s << "};\n"
      << "    for (uint lane = 0; lane < valid; ++lane) {\n"
      << "      __global double* target = out + out_index + (ulong)lane * " << lane_stride << "UL;\n"
      << "      *target = accumulate ? *target + lane_sums[lane] : lane_sums[lane];\n    }\n";
  }
  s << "  }\n}\n\n";
}

void stage_kernel(std::ostringstream& s, const FactoredStage& stage, std::size_t k, const StageShape& shape) {
  if (stage.vector_digit)
    vector_stage_kernel(s, stage, k, shape);
  else
    scalar_stage_kernel(s, stage, k);
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
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return q_strides[i] > q_strides[j]; });
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

std::uint64_t StageShape::lanes(std::uint64_t radix) const {
  if (!row_per_item) return 1;
  return radix >= 8 ? 8 : radix >= 4 ? 4 : 2;
}

StageShape stage_shape_for(unsigned native_double_width) {
  StageShape shape;
  shape.row_per_item = native_double_width > 1;
  shape.states_in_q_order = shape.row_per_item;
  return shape;
}

std::uint64_t stage_work_items(const FactoredStage& stage, const StageShape& shape) {
  if (!stage.vector_digit) return stage.output_size;
  const std::uint64_t radix = stage.output[*stage.vector_digit].radix, lanes = shape.lanes(radix);
  const std::uint64_t rows = stage.output_size / radix;
  return shape.row_per_item ? rows : rows * ((radix + lanes - 1) / lanes);
}

std::uint64_t choose_work_items(const Abstraction& abstraction, const StageShape& shape) {
  const std::size_t states = abstraction.states.size();
  return runs_of_states(abstraction, shape) ? states / abstraction.states.count(abstraction.states.dims() - 1) : states;
}

std::string factored_program_source(const Abstraction& abstraction, const FactoredPlan& plan,
                                    const StageShape& shape) {
  std::ostringstream s;
  s << "// Generated by amytiss: the factored sweep of one problem (see src/core/host/factored_plan.hpp)\n"
    << "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n\n";
  for (std::size_t k = 0; k < plan.stages.size(); ++k) stage_kernel(s, plan.stages[k], k, shape);
  choose_inputs_kernel(s, abstraction, plan, shape);
  return s.str();
}

}  // namespace amytiss::detail
