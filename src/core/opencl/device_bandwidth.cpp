#include "opencl/device_bandwidth.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <vector>

#include "amytiss/format.hpp"
#include "amytiss/stopwatch.hpp"
#include "opencl/program_cache.hpp"

namespace amytiss::detail {
namespace {

constexpr std::size_t kLargestCopyBytes = std::size_t(128) << 20;
constexpr std::size_t kSmallestCopyBytes = std::size_t(1) << 20;
// The first copy touches the pages; the best of the others is the figure.
constexpr int kTimedCopies = 5;

const char* const kCopySource =
    "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n"
    "__kernel void copy_doubles(__global const double* from, __global double* to) {\n"
    "  const size_t i = get_global_id(0);\n"
    "  to[i] = from[i];\n"
    "}\n";

std::string cache_file_path(const DeviceInfo& device, const std::string& dir) {
  const std::string material = device.label() + "\n" + device_string(device.device, CL_DRIVER_VERSION);
  return dir + "/bandwidth-" + hex16(fnv1a64(material)) + ".txt";
}

// The file holds the figure, the buffer bytes and the device's label (checked on reading).
bool read_cached(const std::string& path, const DeviceInfo& device, double& bytes_per_second, std::size_t& bytes) {
  std::ifstream file(path);
  std::string label;
  if (!(file >> bytes_per_second >> bytes) || !std::getline(file >> std::ws, label)) return false;
  return label == device.label() && bytes_per_second > 0;
}

void write_cached(const std::string& path, const DeviceInfo& device, double bytes_per_second, std::size_t bytes) {
  std::error_code ignored;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ignored);
  // Written under a unique name and renamed: concurrent runs never read a partial file.
  const std::string temporary =
      path + ".tmp" + std::to_string(static_cast<unsigned long long>(SteadyClock::now().time_since_epoch().count()));
  {
    std::ofstream file(temporary);
    if (!(file << format_number(bytes_per_second) << ' ' << bytes << '\n' << device.label() << '\n')) return;
  }
  std::filesystem::rename(temporary, path, ignored);
  if (ignored) std::filesystem::remove(temporary, ignored);
}

double best_copy_seconds(const DeviceInfo& device, const DeviceSession& session, std::size_t bytes) {
  std::vector<EngineNote> build_notes;  // the copy kernel's build is not part of the run's story
  const Program program = build_program(session.context.get(), device, kCopySource, "-", build_notes);
  const Kernel copy = create_kernel(program.get(), "copy_doubles");
  cl_int error = CL_SUCCESS;
  Buffer from(clCreateBuffer(session.context.get(), CL_MEM_READ_ONLY, bytes, nullptr, &error));
  check(error, "clCreateBuffer");
  Buffer to(clCreateBuffer(session.context.get(), CL_MEM_WRITE_ONLY, bytes, nullptr, &error));
  check(error, "clCreateBuffer");
  const double pattern = 1.0;
  check(clEnqueueFillBuffer(session.queue.get(), from.get(), &pattern, sizeof pattern, 0, bytes, 0, nullptr, nullptr),
        "clEnqueueFillBuffer");
  cl_mem from_handle = from.get(), to_handle = to.get();
  check(clSetKernelArg(copy.get(), 0, sizeof from_handle, &from_handle), "clSetKernelArg");
  check(clSetKernelArg(copy.get(), 1, sizeof to_handle, &to_handle), "clSetKernelArg");
  const std::size_t items = bytes / sizeof(double);
  double best = 0;
  for (int copy_index = 0; copy_index <= kTimedCopies; ++copy_index) {
    check(clFinish(session.queue.get()), "clFinish");
    const auto start = SteadyClock::now();
    check(clEnqueueNDRangeKernel(session.queue.get(), copy.get(), 1, nullptr, &items, nullptr, 0, nullptr, nullptr),
          "clEnqueueNDRangeKernel");
    check(clFinish(session.queue.get()), "clFinish");
    const double seconds = seconds_since(start);
    if (copy_index > 0 && (best == 0 || seconds < best)) best = seconds;
  }
  return best;
}

}  // namespace

std::size_t copy_buffer_bytes(const DeviceInfo& device) {
  std::size_t bytes = kLargestCopyBytes;
  if (device.max_allocation > 0) bytes = std::min<std::size_t>(bytes, device.max_allocation);
  if (device.global_memory > 0) bytes = std::min<std::size_t>(bytes, device.global_memory / 8);
  bytes = std::max(bytes, kSmallestCopyBytes);
  return bytes / (1 << 20) * (1 << 20);
}

DeviceBandwidth measured_copy_bandwidth(const DeviceInfo& device, const DeviceSession& session,
                                        const std::string& cache_dir) {
  DeviceBandwidth bandwidth;
  const std::string dir = resolved_cache_dir(cache_dir);
  const std::string path = dir.empty() ? "" : cache_file_path(device, dir);
  std::size_t bytes = 0;
  std::string origin;
  if (!path.empty() && read_cached(path, device, bandwidth.bytes_per_second, bytes)) {
    origin = "cached in " + path;
  } else {
    bytes = copy_buffer_bytes(device);
    const double seconds = best_copy_seconds(device, session, bytes);
    bandwidth.bytes_per_second = seconds > 0 ? 2.0 * double(bytes) / seconds : 0.0;
    if (!path.empty() && bandwidth.bytes_per_second > 0) write_cached(path, device, bandwidth.bytes_per_second, bytes);
    origin = path.empty() ? "measured now, not cached" : "measured now, cached in " + path;
  }
  bandwidth.basis = "copy of " + format_bytes(double(bytes)) + " of doubles, bytes read + written / best of " +
                    std::to_string(kTimedCopies) + " copies; " + origin;
  return bandwidth;
}

}  // namespace amytiss::detail
