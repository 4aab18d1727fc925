// OpenCL C of the factored sweep: one kernel per elimination stage, with the plan's radices and
// strides as literals (the compiler turns the digit decoding into multiply-shifts), and the
// kernel that takes min over disturbances and max over inputs from Q.
#include "factored_program.hpp"

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

void stage_kernel(std::ostringstream& s, const FactoredStage& stage, std::size_t k) {
  std::vector<std::uint64_t> radices;
  for (const TensorDigit& digit : stage.output) radices.push_back(digit.radix);
  s << "__kernel void stage" << k
    << "(__global const double* in, __global double* out, __global const uint* first,\n"
       "    __global const uint* count, __global const double* masses, ulong in_offset, uint block_first,\n"
       "    uint block_end, uint accumulate) {\n"
       "  const ulong entry = get_global_id(0);\n"
    << "  if (entry >= " << stage.output_size << "UL) return;\n"
    << "  ulong in_index = in_offset, tuple = 0;\n";
  decode_digits(s, "entry", radices, {stage.input_stride, stage.tuple_stride}, {"in_index", "tuple"});
  // The kept cells of this tuple's window that lie in the block of the contracted dimension held
  // by the input ([block_first, block_end): all of it, except in the last stage of a slice).
  s << "  const uint kept_first = first[tuple];\n"
       "  const uint lo = max(kept_first, block_first);\n"
       "  const uint hi = min(kept_first + count[tuple], block_end);\n"
    << "  __global const double* m = masses + tuple * " << stage.width << "UL + (lo - kept_first);\n"
    << "  __global const double* v = in + in_index + (ulong)(lo - block_first) * " << stage.contracted_stride
    << "UL;\n"
    << "  double sum = 0.0;\n"
    << "  for (int c = 0; c < (int)hi - (int)lo; ++c) sum = fma(m[c], v[(ulong)c * " << stage.contracted_stride
    << "UL], sum);\n"
    << "  out[entry] = accumulate ? out[entry] + sum : sum;\n}\n\n";
}

void choose_inputs_kernel(std::ostringstream& s, const Abstraction& a, const FactoredPlan& plan) {
  // Q's stride of each state, input and disturbance digit.
  auto strides_of_space = [&](FactorVariable::Space space, const Grid& grid) {
    std::vector<std::uint64_t> radices, strides;
    for (std::size_t v = 0; v < plan.variables.size(); ++v) {
      if (plan.variables[v].space != space) continue;
      radices.push_back(grid.count(plan.variables[v].index));
      strides.push_back(plan.q_stride[v]);
    }
    return std::make_pair(radices, strides);
  };
  const auto [state_radices, state_strides] = strides_of_space(FactorVariable::Space::State, a.states);
  const auto [input_radices, input_strides] = strides_of_space(FactorVariable::Space::Input, a.inputs);
  const auto [dist_radices, dist_strides] =
      strides_of_space(FactorVariable::Space::Disturbance, a.disturbances);
  s << "// max over inputs of min over disturbances of Q; ties: the lowest input index.\n"
       "__kernel void choose_inputs(__global const double* q, __global double* v_next,\n"
       "    __global uint* best_input, __global const uchar* roles) {\n"
       "  const uint state = get_global_id(0);\n"
    << "  if (state >= " << a.states.size() << "u) return;\n"
    << "  const uchar role = roles[state];\n"
    << "  if (role != " << int(CellRole::Free) << ") {\n"
    << "    v_next[state] = role == " << int(CellRole::FixedOne) << " ? 1.0 : 0.0;\n"
    << "    best_input[state] = 0;\n    return;\n  }\n"
    << "  ulong state_offset = 0;\n";
  s << "  {\n";
  decode_digits(s, "state", state_radices, {state_strides}, {"state_offset"});
  s << "  }\n  double best = -1.0;\n  uint best_index = 0;\n"
    << "  for (uint input = 0; input < " << a.inputs.size() << "u; ++input) {\n"
    << "    ulong input_offset = state_offset;\n    {\n";
  decode_digits(s, "input", input_radices, {input_strides}, {"input_offset"});
  s << "    }\n    double worst = INFINITY;\n"
    << "    for (uint disturbance = 0; disturbance < " << a.disturbances.size() << "u; ++disturbance) {\n"
    << "      ulong offset = input_offset;\n      {\n";
  decode_digits(s, "disturbance", dist_radices, {dist_strides}, {"offset"});
  s << "      }\n      worst = fmin(worst, q[offset]);\n    }\n"
    << "    if (worst > best) {\n      best = worst;\n      best_index = input;\n    }\n  }\n"
    // Exact masses sum to at most 1; the excess of a rounded sum is rounding, not probability.
    << "  v_next[state] = fmin(best, 1.0);\n  best_input[state] = best_index;\n}\n";
}

}  // namespace

std::string factored_program_source(const Abstraction& abstraction, const FactoredPlan& plan) {
  std::ostringstream s;
  s << "// Generated by amytiss: the factored sweep of one problem (see src/core/factored_plan.hpp)\n"
    << "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n\n";
  for (std::size_t k = 0; k < plan.stages.size(); ++k) stage_kernel(s, plan.stages[k], k);
  choose_inputs_kernel(s, abstraction, plan);
  return s.str();
}

}  // namespace amytiss::detail
