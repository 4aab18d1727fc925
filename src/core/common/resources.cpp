#include "amytiss/resources.hpp"

#include <cstdio>

namespace amytiss {

std::size_t peak_resident_bytes() {
  std::FILE* status = std::fopen("/proc/self/status", "r");
  if (!status) return 0;
  char line[256];
  std::size_t bytes = 0;
  while (std::fgets(line, sizeof line, status)) {
    unsigned long long kilobytes = 0;
    if (std::sscanf(line, "VmHWM: %llu kB", &kilobytes) == 1) {
      bytes = std::size_t(kilobytes) * 1024;
      break;
    }
  }
  std::fclose(status);
  return bytes;
}

}  // namespace amytiss
