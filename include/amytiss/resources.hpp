#pragma once
// What this process uses of the machine.
#include <cstddef>

namespace amytiss {

/// Peak resident set size of this process in bytes (VmHWM), 0 if unknown.
std::size_t peak_resident_bytes();

}  // namespace amytiss
