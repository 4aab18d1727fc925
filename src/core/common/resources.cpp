#include "amytiss/resources.hpp"

#include <sys/resource.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <cstdlib>
#include <limits>

namespace amytiss {
namespace {

// The value in kB of `key` in a /proc file of "Key: value kB" lines, in bytes; 0 if absent.
double proc_kilobytes(const char* path, const char* key) {
  std::FILE* file = std::fopen(path, "r");
  if (!file) return 0;
  char line[256];
  double bytes = 0;
  const std::size_t length = std::strlen(key);
  while (std::fgets(line, sizeof line, file)) {
    unsigned long long kilobytes = 0;
    if (std::strncmp(line, key, length) == 0 && line[length] == ':' &&
        std::sscanf(line + length + 1, " %llu", &kilobytes) == 1) {
      bytes = double(kilobytes) * 1024;
      break;
    }
  }
  std::fclose(file);
  return bytes;
}

// A cgroup limit file's number of bytes; infinity for "max", an absent file or a v1 "no limit"
// (a value near 2^63).
double limit_file(const std::string& path) {
  std::ifstream file(path);
  std::string text;
  if (!(file >> text) || text == "max") return std::numeric_limits<double>::infinity();
  char* end = nullptr;
  const double bytes = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || bytes <= 0 || bytes >= 0x1p62) return std::numeric_limits<double>::infinity();
  return bytes;
}

// This process's cgroup limit: the v2 group ("0::path") or the v1 memory controller's group,
// read under /sys/fs/cgroup (inside a cgroup namespace the group is the mount's root).
void cgroup_limit(HostMemory& memory) {
  std::ifstream groups("/proc/self/cgroup");
  for (std::string line; std::getline(groups, line);) {
    const std::size_t first = line.find(':'), second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string controllers = line.substr(first + 1, second - first - 1), path = line.substr(second + 1);
    std::string candidates[2], source;
    if (controllers.empty()) {
      candidates[0] = "/sys/fs/cgroup" + path + "/memory.max";
      candidates[1] = "/sys/fs/cgroup/memory.max";
      source = "cgroup memory.max";
    } else if (("," + controllers + ",").find(",memory,") != std::string::npos) {
      candidates[0] = "/sys/fs/cgroup/memory" + path + "/memory.limit_in_bytes";
      candidates[1] = "/sys/fs/cgroup/memory/memory.limit_in_bytes";
      source = "cgroup memory.limit_in_bytes";
    } else {
      continue;
    }
    for (const std::string& candidate : candidates) {
      if (!std::ifstream(candidate)) continue;
      const double limit = limit_file(candidate);
      if (limit < memory.bytes) memory = {limit, source};
      break;
    }
  }
}

}  // namespace

std::size_t peak_resident_bytes() { return std::size_t(proc_kilobytes("/proc/self/status", "VmHWM")); }

std::size_t resident_bytes() { return std::size_t(proc_kilobytes("/proc/self/status", "VmRSS")); }

HostMemory available_memory() {
  HostMemory memory{std::numeric_limits<double>::infinity(), "no limit known"};
  const double free_bytes = proc_kilobytes("/proc/meminfo", "MemAvailable");
  if (free_bytes > 0) memory = {free_bytes, "MemAvailable"};
  cgroup_limit(memory);
  rlimit address_space{};
  if (getrlimit(RLIMIT_AS, &address_space) == 0 && address_space.rlim_cur != RLIM_INFINITY) {
    const double left = double(address_space.rlim_cur) - proc_kilobytes("/proc/self/status", "VmSize");
    if (left < memory.bytes) memory = {left > 0 ? left : 0, "RLIMIT_AS"};
  }
  return memory;
}

HostMemory available_memory(double limit_bytes) {
  if (limit_bytes > 0) return {limit_bytes, "a limit of the caller"};
  return available_memory();
}

}  // namespace amytiss
