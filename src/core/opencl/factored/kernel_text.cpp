#include "opencl/factored/kernel_text.hpp"

namespace amytiss::detail {

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

std::string kernel_head(std::size_t k, bool fused) {
  return "__kernel void stage" + std::to_string(k) +
         "(__global const double* in, __global double* out, __global const uint* first,\n"
         "    __global const uint* count, __global const double* masses, ulong in_offset, uint block_first,\n"
         "    uint block_end, uint accumulate" +
         (fused ? ",\n    __global const uint* next_first, __global const uint* next_count,\n"
                  "    __global const double* next_masses"
                : "") +
         ") {\n";
}

void window_of_tuple(std::ostringstream& s, const FactoredStage& stage, const std::string& suffix,
                     const std::string& indent) {
  const std::string& x = suffix;
  s << indent << "const uint kept_first" << x << " = first[tuple" << x << "];\n"
    << indent << "const uint lo" << x << " = max(kept_first" << x << ", block_first);\n"
    << indent << "const uint hi" << x << " = max(lo" << x << ", min(kept_first" << x << " + count[tuple" << x
    << "], block_end));\n"
    << indent << "const int cells" << x << " = (int)hi" << x << " - (int)lo" << x << ";\n"
    << indent << "__global const double* m" << x << " = masses + tuple" << x << " * " << stage.width << "UL + (lo" << x
    << " - kept_first" << x << ");\n";
}

}  // namespace amytiss::detail
