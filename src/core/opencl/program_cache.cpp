#include "opencl/program_cache.hpp"

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "amytiss/errors.hpp"
#include "amytiss/format.hpp"

namespace amytiss::detail {
namespace {

// The key hashes everything the binary depends on: device, driver, platform and source.
constexpr std::uint64_t kSecondHashBasis = 0x9e3779b97f4a7c15ULL;

std::string default_kernel_cache_dir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/amytiss/kernels";
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/amytiss/kernels";
  return "";
}

std::string cache_entry_path(const DeviceInfo& device, const std::string& source, const std::string& dir) {
  const std::string material = device_string(device.device, CL_DEVICE_VERSION) + "\n" +
                               device_string(device.device, CL_DRIVER_VERSION) + "\n" +
                               platform_string(device.platform, CL_PLATFORM_VERSION) + "\n" +
                               device.label() + "\n" + source;
  return dir + "/" + hex16(fnv1a64(material)) + hex16(fnv1a64(material, kSecondHashBasis)) + ".bin";
}

Program load_cached_program(cl_context context, const DeviceInfo& device, const std::string& source,
                            const std::string& requested_dir, std::vector<EngineNote>& notes) {
  const std::string dir = resolved_cache_dir(requested_dir);
  if (dir.empty()) return Program();
  const std::string path = cache_entry_path(device, source, dir);
  std::ifstream file(path, std::ios::binary);
  if (!file) return Program();
  const std::vector<unsigned char> binary((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (binary.empty()) return Program();
  const unsigned char* data = binary.data();
  const std::size_t size = binary.size();
  cl_int status = CL_SUCCESS, error = CL_SUCCESS;
  Program program(clCreateProgramWithBinary(context, 1, &device.device, &size, &data, &status, &error));
  if (error != CL_SUCCESS || status != CL_SUCCESS) return Program();
  if (clBuildProgram(program.get(), 1, &device.device, "", nullptr, nullptr) != CL_SUCCESS) return Program();
  notes.push_back({NoteSeverity::Info, NoteKind::KernelBuild, "kernel build: program binary from cache " + path});
  return program;
}

void store_cached_program(cl_program program, const DeviceInfo& device, const std::string& source,
                          const std::string& requested_dir, std::vector<EngineNote>& notes) {
  const std::string dir = resolved_cache_dir(requested_dir);
  if (dir.empty()) return;
  std::size_t size = 0;
  if (clGetProgramInfo(program, CL_PROGRAM_BINARY_SIZES, sizeof size, &size, nullptr) != CL_SUCCESS || size == 0)
    return;
  std::vector<unsigned char> binary(size);
  unsigned char* data = binary.data();
  if (clGetProgramInfo(program, CL_PROGRAM_BINARIES, sizeof data, &data, nullptr) != CL_SUCCESS) return;
  std::error_code ignored;
  std::filesystem::create_directories(dir, ignored);
  const std::string path = cache_entry_path(device, source, dir);
  // Written under a unique name and renamed: concurrent runs never see a partial entry.
  const std::string temporary = path + ".tmp" + std::to_string(static_cast<unsigned long long>(
                                                    std::chrono::steady_clock::now().time_since_epoch().count()));
  {
    std::ofstream file(temporary, std::ios::binary);
    if (!file.write(reinterpret_cast<const char*>(binary.data()), std::streamsize(size))) {
      std::filesystem::remove(temporary, ignored);
      return;
    }
  }
  std::filesystem::rename(temporary, path, ignored);
  if (ignored) {
    std::filesystem::remove(temporary, ignored);
    return;
  }
  notes.push_back({NoteSeverity::Info, NoteKind::KernelBuild,
                   "kernel build: compiled from source, program binary cached in " + path});
}

Program build_from_source(cl_context context, const DeviceInfo& device, const std::string& source) {
  cl_int error = CL_SUCCESS;
  const char* source_text = source.c_str();
  const std::size_t source_length = source.size();
  Program program(clCreateProgramWithSource(context, 1, &source_text, &source_length, &error));
  check(error, "clCreateProgramWithSource");
  error = clBuildProgram(program.get(), 1, &device.device, "", nullptr, nullptr);
  if (error != CL_SUCCESS) {
    std::size_t log_size = 0;
    clGetProgramBuildInfo(program.get(), device.device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &log_size);
    std::string build_log(log_size, '\0');
    clGetProgramBuildInfo(program.get(), device.device, CL_PROGRAM_BUILD_LOG, log_size, build_log.data(), nullptr);
    throw DeviceError("OpenCL kernel build failed on " + device.label() + " (" + cl_error_name(error) +
                      "); compiler log:\n" + build_log);
  }
  return program;
}

}  // namespace

std::string resolved_cache_dir(const std::string& requested) {
  if (requested == "-") return "";
  return requested.empty() ? default_kernel_cache_dir() : requested;
}

Program build_program(cl_context context, const DeviceInfo& device, const std::string& source,
                      const std::string& cache_dir, std::vector<EngineNote>& notes) {
  Program program = load_cached_program(context, device, source, cache_dir, notes);
  if (program.get()) return program;
  program = build_from_source(context, device, source);
  store_cached_program(program.get(), device, source, cache_dir, notes);
  return program;
}

}  // namespace amytiss::detail
