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

// The cache read: a buffer of kCacheReadBytes (in a CPU core's L2, a GPU's L1 or L2) read in
// vectors of 8 doubles, kCacheReads per work-item into four independent sums, consecutive
// work-items at consecutive vectors, each read 9 vectors further on (the compiler cannot keep a
// value); one sum stored per work-item.
constexpr std::size_t kCacheReadBytes = std::size_t(128) << 10;
constexpr std::size_t kCacheReadItems = std::size_t(1) << 16;
constexpr int kCacheReads = 256;
constexpr std::size_t kCacheReadVector = 8;

const char* const kCopySource =
    "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n"
    "__kernel void copy_doubles(__global const double* from, __global double* to) {\n"
    "  const size_t i = get_global_id(0);\n"
    "  to[i] = from[i];\n"
    "}\n"
    "__kernel void read_cached(__global const double* from, __global double* sums, uint mask, uint reads) {\n"
    "  const uint i = (uint)get_global_id(0);\n"
    "  double8 a = 0.0, b = 0.0, c = 0.0, d = 0.0;\n"
    "  for (uint r = 0; r < reads; r += 4) {\n"
    "    a += vload8((i + r * 9) & mask, from);\n"
    "    b += vload8((i + r * 9 + 9) & mask, from);\n"
    "    c += vload8((i + r * 9 + 18) & mask, from);\n"
    "    d += vload8((i + r * 9 + 27) & mask, from);\n"
    "  }\n"
    "  const double8 sum = (a + b) + (c + d);\n"
    "  sums[i] = sum.s0 + sum.s1 + sum.s2 + sum.s3 + sum.s4 + sum.s5 + sum.s6 + sum.s7;\n"
    "}\n";

std::string cache_file_path(const DeviceInfo& device, const std::string& dir) {
  const std::string material = device.label() + "\n" + device_string(device.device, CL_DRIVER_VERSION);
  return dir + "/bandwidths-" + hex16(fnv1a64(material)) + ".txt";
}

// The file holds both figures, the copy's buffer bytes and the device's label (checked on reading).
bool read_cached(const std::string& path, const DeviceInfo& device, DeviceBandwidth& bandwidth, std::size_t& bytes) {
  std::ifstream file(path);
  std::string label;
  if (!(file >> bandwidth.bytes_per_second >> bandwidth.cache_bytes_per_second >> bytes) ||
      !std::getline(file >> std::ws, label))
    return false;
  return label == device.label() && bandwidth.bytes_per_second > 0 && bandwidth.cache_bytes_per_second > 0;
}

void write_cached(const std::string& path, const DeviceInfo& device, const DeviceBandwidth& bandwidth,
                  std::size_t bytes) {
  std::error_code ignored;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ignored);
  // Written under a unique name and renamed: concurrent runs never read a partial file.
  const std::string temporary =
      path + ".tmp" + std::to_string(static_cast<unsigned long long>(SteadyClock::now().time_since_epoch().count()));
  {
    std::ofstream file(temporary);
    if (!(file << format_number(bandwidth.bytes_per_second) << ' ' << format_number(bandwidth.cache_bytes_per_second)
               << ' ' << bytes << '\n'
               << device.label() << '\n'))
      return;
  }
  std::filesystem::rename(temporary, path, ignored);
  if (ignored) std::filesystem::remove(temporary, ignored);
}

Buffer device_buffer(const DeviceSession& session, cl_mem_flags flags, std::size_t bytes) {
  cl_int error = CL_SUCCESS;
  Buffer buffer(clCreateBuffer(session.context.get(), flags, bytes, nullptr, &error));
  check(error, "clCreateBuffer");
  const double pattern = 1.0;
  check(clEnqueueFillBuffer(session.queue.get(), buffer.get(), &pattern, sizeof pattern, 0, bytes, 0, nullptr, nullptr),
        "clEnqueueFillBuffer");
  return buffer;
}

// The best of kTimedCopies launches of `kernel` over `items` work-items (after one untimed).
double best_launch_seconds(const DeviceSession& session, const Kernel& kernel, std::size_t items) {
  double best = 0;
  for (int launch = 0; launch <= kTimedCopies; ++launch) {
    check(clFinish(session.queue.get()), "clFinish");
    const auto start = SteadyClock::now();
    check(clEnqueueNDRangeKernel(session.queue.get(), kernel.get(), 1, nullptr, &items, nullptr, 0, nullptr, nullptr),
          "clEnqueueNDRangeKernel");
    check(clFinish(session.queue.get()), "clFinish");
    const double seconds = seconds_since(start);
    if (launch > 0 && (best == 0 || seconds < best)) best = seconds;
  }
  return best;
}

// Both figures: the copy of two `bytes` buffers (bytes read + written per second) and the cache
// read (bytes read per second).
DeviceBandwidth measure(const DeviceInfo& device, const DeviceSession& session, std::size_t bytes) {
  std::vector<EngineNote> build_notes;  // the kernels' build is not part of the run's story
  const Program program = build_program(session.context.get(), device, kCopySource, "-", build_notes);
  DeviceBandwidth bandwidth;
  {
    const Kernel copy = create_kernel(program.get(), "copy_doubles");
    const Buffer from = device_buffer(session, CL_MEM_READ_ONLY, bytes);
    const Buffer to = device_buffer(session, CL_MEM_WRITE_ONLY, bytes);
    cl_mem from_handle = from.get(), to_handle = to.get();
    check(clSetKernelArg(copy.get(), 0, sizeof from_handle, &from_handle), "clSetKernelArg");
    check(clSetKernelArg(copy.get(), 1, sizeof to_handle, &to_handle), "clSetKernelArg");
    const double seconds = best_launch_seconds(session, copy, bytes / sizeof(double));
    bandwidth.bytes_per_second = seconds > 0 ? 2.0 * double(bytes) / seconds : 0.0;
  }
  const Kernel read = create_kernel(program.get(), "read_cached");
  const Buffer from = device_buffer(session, CL_MEM_READ_ONLY, kCacheReadBytes);
  const Buffer sums = device_buffer(session, CL_MEM_WRITE_ONLY, kCacheReadItems * sizeof(double));
  cl_mem from_handle = from.get(), sums_handle = sums.get();
  const cl_uint mask = cl_uint(kCacheReadBytes / sizeof(double) / kCacheReadVector - 1), reads = kCacheReads;
  check(clSetKernelArg(read.get(), 0, sizeof from_handle, &from_handle), "clSetKernelArg");
  check(clSetKernelArg(read.get(), 1, sizeof sums_handle, &sums_handle), "clSetKernelArg");
  check(clSetKernelArg(read.get(), 2, sizeof mask, &mask), "clSetKernelArg");
  check(clSetKernelArg(read.get(), 3, sizeof reads, &reads), "clSetKernelArg");
  const double seconds = best_launch_seconds(session, read, kCacheReadItems);
  bandwidth.cache_bytes_per_second =
      seconds > 0 ? double(kCacheReadItems) * kCacheReads * kCacheReadVector * sizeof(double) / seconds : 0.0;
  return bandwidth;
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
  const std::string dir = resolved_cache_dir(cache_dir);
  const std::string path = dir.empty() ? "" : cache_file_path(device, dir);
  std::size_t bytes = 0;
  std::string origin;
  DeviceBandwidth bandwidth;
  if (!path.empty() && read_cached(path, device, bandwidth, bytes)) {
    origin = "cached in " + path;
  } else {
    bytes = copy_buffer_bytes(device);
    bandwidth = measure(device, session, bytes);
    if (!path.empty() && bandwidth.bytes_per_second > 0 && bandwidth.cache_bytes_per_second > 0)
      write_cached(path, device, bandwidth, bytes);
    origin = path.empty() ? "measured now, not cached" : "measured now, cached in " + path;
  }
  bandwidth.basis = "copy of " + format_bytes(double(bytes)) + " of doubles, bytes read + written / best of " +
                    std::to_string(kTimedCopies) + " copies; " + origin;
  bandwidth.cache_basis = "reads of a " + format_bytes(double(kCacheReadBytes)) + " buffer, " +
                          std::to_string(kCacheReads) + " vectors of 8 doubles per work-item, bytes read / best of " +
                          std::to_string(kTimedCopies) + " launches";
  return bandwidth;
}

}  // namespace amytiss::detail
