// libFuzzer entry point for the expression parser and configuration validation (see
// fuzz_one_input.hpp). Built and run by scripts/fuzz.
#include "fuzz_one_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  amytiss::fuzz_one_input(data, size);
  return 0;
}
