#pragma once
// What this process uses of the machine, and what it may use: every host memory budget of the
// engines is compared with available_memory() (docs/engine.md, "The plan").
#include <cstddef>
#include <string>

namespace amytiss {

/// Peak resident set size of this process in bytes (VmHWM), 0 if unknown.
std::size_t peak_resident_bytes();
/// Resident set size of this process now in bytes (VmRSS), 0 if unknown.
std::size_t resident_bytes();

/// Memory this process may still take, and what limits it.
struct HostMemory {
  double bytes = 0;    ///< the least of the limits found (infinity when none is known)
  std::string source;  ///< which one: "MemAvailable", "cgroup memory.max", "RLIMIT_AS", ...
};
/// The least of MemAvailable (/proc/meminfo), the cgroup's limit (cgroup v2 memory.max, v1
/// memory.limit_in_bytes) and RLIMIT_AS less the address space already mapped.
HostMemory available_memory();
/// `limit_bytes` > 0: that ("a limit of the caller", for tests and embedding programs); else
/// available_memory().
HostMemory available_memory(double limit_bytes);

}  // namespace amytiss
