// The OpenCL engine: device choice, program generation, stored / on-the-fly construction and the
// synthesis sweep. The algorithm lives in kernels/engine.cl; this file only plans and launches.
#include "opencl_engine.hpp"

#include <CL/cl.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "amytiss/errors.hpp"

namespace amytiss {
namespace detail {
const char* embedded_source(const std::string& name);

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

const char* cl_error_name(cl_int code) {
  switch (code) {
    case CL_DEVICE_NOT_FOUND: return "CL_DEVICE_NOT_FOUND";
    case CL_DEVICE_NOT_AVAILABLE: return "CL_DEVICE_NOT_AVAILABLE";
    case CL_MEM_OBJECT_ALLOCATION_FAILURE: return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
    case CL_OUT_OF_RESOURCES: return "CL_OUT_OF_RESOURCES";
    case CL_OUT_OF_HOST_MEMORY: return "CL_OUT_OF_HOST_MEMORY";
    case CL_BUILD_PROGRAM_FAILURE: return "CL_BUILD_PROGRAM_FAILURE";
    case CL_INVALID_VALUE: return "CL_INVALID_VALUE";
    case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_WORK_ITEM_SIZE: return "CL_INVALID_WORK_ITEM_SIZE";
    case CL_INVALID_GLOBAL_WORK_SIZE: return "CL_INVALID_GLOBAL_WORK_SIZE";
    case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
    case CL_INVALID_KERNEL_NAME: return "CL_INVALID_KERNEL_NAME";
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
    default: return "OpenCL error";
  }
}

void check(cl_int code, const char* call) {
  if (code != CL_SUCCESS)
    throw DeviceError(std::string(call) + " failed: " + cl_error_name(code) + " (" +
                      std::to_string(code) + ")");
}

template <typename T, cl_int (*Release)(T)>
struct ClHandle {
  T handle = nullptr;
  ClHandle() = default;
  explicit ClHandle(T h) : handle(h) {}
  ClHandle(const ClHandle&) = delete;
  ClHandle& operator=(const ClHandle&) = delete;
  ClHandle(ClHandle&& other) noexcept : handle(other.handle) { other.handle = nullptr; }
  ClHandle& operator=(ClHandle&& other) noexcept {
    std::swap(handle, other.handle);
    return *this;
  }
  ~ClHandle() {
    if (handle) Release(handle);
  }
  T get() const { return handle; }
};
using Context = ClHandle<cl_context, clReleaseContext>;
using Queue = ClHandle<cl_command_queue, clReleaseCommandQueue>;
using Program = ClHandle<cl_program, clReleaseProgram>;
using Kernel = ClHandle<cl_kernel, clReleaseKernel>;
using Buffer = ClHandle<cl_mem, clReleaseMemObject>;

// A string property through clGet*Info (query size, then text); "?" when the query fails.
template <typename Object, typename Info>
std::string info_string(cl_int (*get_info)(Object, Info, std::size_t, void*, std::size_t*), Object object,
                        Info what) {
  std::size_t size = 0;
  if (get_info(object, what, 0, nullptr, &size) != CL_SUCCESS) return "?";
  std::string text(size, '\0');
  get_info(object, what, size, text.data(), nullptr);
  while (!text.empty() && text.back() == '\0') text.pop_back();
  return text;
}
std::string platform_string(cl_platform_id platform, cl_platform_info what) {
  return info_string(clGetPlatformInfo, platform, what);
}
std::string device_string(cl_device_id device, cl_device_info what) {
  return info_string(clGetDeviceInfo, device, what);
}
template <typename T>
T device_value(cl_device_id device, cl_device_info what) {
  T value{};
  clGetDeviceInfo(device, what, sizeof(T), &value, nullptr);
  return value;
}

struct DeviceInfo {
  std::size_t platform_index = 0, device_index = 0;
  cl_platform_id platform = nullptr;
  cl_device_id device = nullptr;
  std::string platform_name, device_name;
  cl_device_type type = 0;
  std::uint64_t global_memory = 0, max_allocation = 0;
  cl_uint compute_units = 0;
  std::size_t max_work_group = 1;
  bool fp64 = false;
  bool is_gpu() const { return (type & CL_DEVICE_TYPE_GPU) != 0; }
  bool is_cpu() const { return (type & CL_DEVICE_TYPE_CPU) != 0; }
  std::string label() const { return platform_name + " / " + device_name; }
  std::string type_name() const {
    return is_gpu() ? "GPU" : is_cpu() ? "CPU" : (type & CL_DEVICE_TYPE_ACCELERATOR) ? "accelerator" : "other";
  }
};

std::vector<DeviceInfo> enumerate_devices() {
  std::vector<DeviceInfo> devices;
  cl_uint platform_count = 0;
  if (clGetPlatformIDs(0, nullptr, &platform_count) != CL_SUCCESS || platform_count == 0)
    return devices;
  std::vector<cl_platform_id> platforms(platform_count);
  clGetPlatformIDs(platform_count, platforms.data(), nullptr);
  for (std::size_t p = 0; p < platforms.size(); ++p) {
    cl_uint device_count = 0;
    if (clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, 0, nullptr, &device_count) != CL_SUCCESS)
      continue;
    std::vector<cl_device_id> ids(device_count);
    clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, device_count, ids.data(), nullptr);
    for (std::size_t d = 0; d < ids.size(); ++d) {
      DeviceInfo info;
      info.platform_index = p;
      info.device_index = d;
      info.platform = platforms[p];
      info.device = ids[d];
      info.platform_name = platform_string(platforms[p], CL_PLATFORM_NAME);
      info.device_name = device_string(ids[d], CL_DEVICE_NAME);
      info.type = device_value<cl_device_type>(ids[d], CL_DEVICE_TYPE);
      info.global_memory = device_value<cl_ulong>(ids[d], CL_DEVICE_GLOBAL_MEM_SIZE);
      info.max_allocation = device_value<cl_ulong>(ids[d], CL_DEVICE_MAX_MEM_ALLOC_SIZE);
      info.compute_units = device_value<cl_uint>(ids[d], CL_DEVICE_MAX_COMPUTE_UNITS);
      info.max_work_group = device_value<std::size_t>(ids[d], CL_DEVICE_MAX_WORK_GROUP_SIZE);
      info.fp64 = device_string(ids[d], CL_DEVICE_EXTENSIONS).find("cl_khr_fp64") != std::string::npos;
      devices.push_back(info);
    }
  }
  return devices;
}


// --- Program binary cache. Building from source costs ~35-50 ms on pocl even when pocl's own
// cache holds the compiled kernels (its front end still runs); loading our own copy of the
// program binary costs ~5 ms. The key hashes everything the binary depends on; any failure to
// read, write or load an entry silently falls back to building from source.
std::uint64_t fnv1a(const std::string& text, std::uint64_t hash) {
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 1099511628211ULL;
  }
  return hash;
}

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
  char name[40];
  std::snprintf(name, sizeof name, "%016llx%016llx.bin",
                static_cast<unsigned long long>(fnv1a(material, 14695981039346656037ULL)),
                static_cast<unsigned long long>(fnv1a(material, 0x9e3779b97f4a7c15ULL)));
  return dir + "/" + name;
}

std::string resolved_cache_dir(const std::string& requested) {
  if (requested == "-") return "";
  return requested.empty() ? default_kernel_cache_dir() : requested;
}

Program load_cached_program(cl_context context, const DeviceInfo& device, const std::string& source,
                            const std::string& requested_dir, std::vector<std::string>& log) {
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
  log.push_back("kernel build: program binary from cache " + path);
  return program;
}

void store_cached_program(cl_program program, const DeviceInfo& device, const std::string& source,
                          const std::string& requested_dir, std::vector<std::string>& log) {
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
  log.push_back("kernel build: compiled from source, program binary cached in " + path);
}

std::string lower(std::string text) {
  for (char& c : text) c = char(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// A selector is empty (any), a 0-based index, or a case-insensitive substring of the name.
bool selector_matches(const std::string& selector, std::size_t index, const std::string& name) {
  if (selector.empty()) return true;
  if (std::all_of(selector.begin(), selector.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }))
    return std::stoul(selector) == index;
  return lower(name).find(lower(selector)) != std::string::npos;
}

DeviceInfo choose_device(const ComputeConfig& compute, std::vector<std::string>& log) {
  std::vector<DeviceInfo> all = enumerate_devices();
  if (all.empty())
    throw DeviceError("no OpenCL device found (no ICD platform answered); install pocl "
                      "(Debian: pocl-opencl-icd) or use compute.device: reference");
  std::vector<DeviceInfo> candidates;
  for (const DeviceInfo& info : all) {
    if (!selector_matches(compute.platform, info.platform_index, info.platform_name)) continue;
    if (!selector_matches(compute.device_name, info.device_index, info.device_name)) continue;
    if (!info.fp64) {
      log.push_back("skipping " + info.label() + ": no double precision (cl_khr_fp64)");
      continue;
    }
    candidates.push_back(info);
  }
  if (candidates.empty())
    throw DeviceError("no OpenCL device with double precision matches compute.platform '" +
                      compute.platform + "' and compute.device_name '" + compute.device_name +
                      "' (amytiss_synth --list-devices shows the devices)");
  auto first_of = [&](bool gpu) -> const DeviceInfo* {
    for (const DeviceInfo& info : candidates)
      if (gpu ? info.is_gpu() : info.is_cpu()) return &info;
    return nullptr;
  };
  const DeviceInfo* gpu = first_of(true);
  const DeviceInfo* cpu = first_of(false);
  const DeviceInfo* fallback = cpu ? cpu : &candidates.front();
  switch (compute.device) {
    case DeviceKind::Gpu:
      if (gpu) return *gpu;
      log.push_back("warning: device gpu requested but no OpenCL GPU found; falling back to " +
                    fallback->label());
      return *fallback;
    case DeviceKind::Cpu:
      if (cpu) return *cpu;
      log.push_back("warning: device cpu requested but no OpenCL CPU device found; using " +
                    candidates.front().label());
      return candidates.front();
    default:
      if (gpu) {
        log.push_back("device auto: chose GPU " + gpu->label());
        return *gpu;
      }
      log.push_back("device auto: no OpenCL GPU found, using " + fallback->label());
      return *fallback;
  }
}

std::string number(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  std::string out(text);
  if (out.find_first_of(".eEn") == std::string::npos) out += ".0";
  return out;
}

template <typename T, typename F>
std::string constant_array(const char* type, const char* name, const std::vector<T>& values,
                           F format) {
  std::string text = std::string("__constant ") + type + " " + name + "[" +
                     std::to_string(std::max<std::size_t>(1, values.size())) + "] = {";
  if (values.empty()) text += format(T{});
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + format(values[i]);
  return text + "};\n";
}
std::string int_text(long long value) { return std::to_string(value); }

// Layout numbers of a problem shared by the prelude and the host.
struct Layout {
  std::vector<long long> half, width, mass_offset, padded_count, padded_stride, whole;
  long long mass_record = 0;
  std::size_t padded_size = 1;
  explicit Layout(const Abstraction& a) {
    const std::size_t dims = a.states.dims();
    const auto& h = a.noise->window_half_cells();
    half.resize(dims);
    width.resize(dims);
    mass_offset.resize(dims);
    padded_count.resize(dims);
    padded_stride.resize(dims);
    whole.resize(dims);
    for (std::size_t i = 0; i < dims; ++i) {
      const long long count = static_cast<long long>(a.states.count(i));
      whole[i] = a.noise->whole_grid_dims()[i] ? 1 : 0;
      // A whole-grid window is the dimension itself: no padding, n cells from index 0 (padding
      // by n - 1 on each side would make the value array (3n - 2)^d: 2^28 cells for StocHy 14-d).
      // Otherwise the window never needs more than the grid: h <= n - 1 bounds the padding.
      half[i] = whole[i] ? 0 : std::min<long long>(h[i], count - 1);
      width[i] = whole[i] ? count : 2 * half[i] + 1;
      mass_offset[i] = mass_record;
      mass_record += width[i];
      padded_count[i] = count + 2 * half[i];
    }
    for (std::size_t i = dims; i-- > 0;) {
      padded_stride[i] = static_cast<long long>(padded_size);
      padded_size *= static_cast<std::size_t>(padded_count[i]);
    }
  }
  std::size_t padded_offset(const Grid& states, std::size_t flat) const {
    std::size_t offset = 0;
    for (std::size_t i = states.dims(); i-- > 0;) {
      const std::size_t k = flat % states.count(i);
      flat /= states.count(i);
      offset += (k + static_cast<std::size_t>(half[i])) * static_cast<std::size_t>(padded_stride[i]);
    }
    return offset;
  }
};

// The separable contraction, generated with literal trip counts and offsets, nested outermost =
// dimension 0. Values are double; masses float, converted once. For a window narrower than
// kUnrollLimit in the last dimension, the last two dimensions are contracted as weighted rows:
// rows of the last dimension are accumulated with their dimension d-2 mass into double4 vectors
// (two independent sets, even and odd rows, to keep the FMA latency chains short), and the
// result is dotted once with the last dimension's masses. Lanes beyond the window carry mass 0
// (the value buffer has kValueSlack extra zero cells, so the over-read stays in bounds).
constexpr long long kUnrollLimit = 64;
// Zero cells after the padded values: the last vector of a window row may read up to 3 beyond it.
constexpr std::size_t kValueSlack = 4;
std::string contraction_source(const Layout& layout, const std::string& name,
                               const std::string& mass_space) {
  const std::size_t dims = layout.width.size();
  std::ostringstream s;
  s << "double " << name << "(__global const double* v, " << mass_space << " const float* m) {\n";
  const long long inner_width = layout.width[dims - 1], inner_offset = layout.mass_offset[dims - 1];
  const bool rows = inner_width <= kUnrollLimit;
  const std::size_t outer_levels = rows ? (dims >= 2 ? dims - 2 : 0) : dims - 1;
  const long long vectors = (inner_width + 3) / 4;
  if (rows) {
    for (long long k = 0; k < vectors; ++k) {
      s << "  const double4 inner_mass" << k << " = ";
      if (4 * k + 4 <= inner_width) {
        s << "convert_double4(vload4(0, m + " << inner_offset + 4 * k << "));\n";
      } else {
        s << "(double4)(";
        for (long long lane = 0; lane < 4; ++lane) {
          const long long j = 4 * k + lane;
          s << (lane ? ", " : "") << (j < inner_width ? "(double)m[" + std::to_string(inner_offset + j) + "]" : "0.0");
        }
        s << ");\n";
      }
    }
  }
  // Opens the outer loops (scalar FMA chains, zero-mass rows skipped).
  std::string pointer = "v";
  for (std::size_t i = 0; i < outer_levels; ++i) {
    const std::string indent(2 * (i + 1), ' '), a = "a" + std::to_string(i);
    s << indent << "double acc" << i << " = 0.0;\n";
    s << indent << "for (int " << a << " = 0; " << a << " < " << layout.width[i] << "; ++" << a << ") {\n";
    s << indent << "  const double mass" << i << " = m[" << layout.mass_offset[i] << " + " << a << "];\n";
    s << indent << "  if (mass" << i << " == 0.0) continue;\n";
    s << indent << "  __global const double* v" << i << " = " << pointer << " + " << a << " * "
      << layout.padded_stride[i] << ";\n";
    pointer = "v" + std::to_string(i);
  }
  const std::string indent(2 * (outer_levels + 1), ' ');
  if (rows) {
    // The weighted rows of dimension d-2 (a single row of weight 1 when dims == 1).
    auto row_load = [&](const std::string& row_pointer, long long k) {
      return "vload4(" + std::to_string(k) + ", " + row_pointer + ")";
    };
    std::vector<std::string> summed(vectors);
    if (dims == 1) {
      for (long long k = 0; k < vectors; ++k) summed[k] = row_load(pointer, k);
    } else {
      const std::size_t r = dims - 2;
      const long long row_width = layout.width[r], row_offset = layout.mass_offset[r],
                      row_stride = layout.padded_stride[r];
      const bool two_sets = row_width >= 2;
      for (long long k = 0; k < vectors; ++k) {
        s << indent << "double4 even" << k << " = 0.0;\n";
        if (two_sets) s << indent << "double4 odd" << k << " = 0.0;\n";
      }
      auto accumulate = [&](const std::string& set, const std::string& row) {
        s << indent << "  {\n" << indent << "    const double weight = m[" << row_offset << " + " << row << "];\n"
          << indent << "    __global const double* row = " << pointer << " + (" << row << ") * " << row_stride << ";\n";
        for (long long k = 0; k < vectors; ++k)
          s << indent << "    " << set << k << " = fma((double4)(weight), " << row_load("row", k) << ", " << set << k
            << ");\n";
        s << indent << "  }\n";
      };
      if (two_sets) {
        s << indent << "for (int r = 0; r + 1 < " << row_width << "; r += 2) {\n";
        accumulate("even", "r");
        accumulate("odd", "r + 1");
        s << indent << "}\n";
      }
      if (row_width % 2) {
        s << indent << "{\n" << indent << "  const int r = " << row_width - 1 << ";\n";
        accumulate("even", "r");
        s << indent << "}\n";
      }
      for (long long k = 0; k < vectors; ++k)
        summed[k] = two_sets ? "(even" + std::to_string(k) + " + odd" + std::to_string(k) + ")" : "even" + std::to_string(k);
    }
    std::vector<std::string> terms;
    for (long long k = 0; k < vectors; ++k) terms.push_back("inner_mass" + std::to_string(k) + " * " + summed[k]);
    while (terms.size() > 1) {
      std::vector<std::string> paired;
      for (std::size_t t = 0; t + 1 < terms.size(); t += 2) paired.push_back("(" + terms[t] + " + " + terms[t + 1] + ")");
      if (terms.size() % 2) paired.push_back(terms.back());
      terms = paired;
    }
    s << indent << "const double4 lanes = " << terms.front() << ";\n";
    s << indent << "const double2 halves = lanes.lo + lanes.hi;\n";
    s << indent << "const double rows = halves.x + halves.y;\n";
  } else {
    s << indent << "double rows = 0.0;\n";
    s << indent << "for (int j = 0; j < " << inner_width << "; ++j)\n";
    s << indent << "  rows = fma((double)m[" << inner_offset << " + j], " << pointer << "[j], rows);\n";
  }
  if (outer_levels == 0) {
    s << "  return rows;\n}\n";
    return s.str();
  }
  s << indent << "acc" << outer_levels - 1 << " = fma(mass" << outer_levels - 1 << ", rows, acc" << outer_levels - 1
    << ");\n";
  for (std::size_t i = outer_levels; i-- > 0;) {
    const std::string close_indent(2 * (i + 1), ' ');
    s << close_indent << "}\n";
    if (i > 0) s << close_indent << "acc" << i - 1 << " = fma(mass" << i - 1 << ", acc" << i << ", acc" << i - 1 << ");\n";
  }
  s << "  return acc0;\n}\n";
  return s.str();
}

std::vector<long long> counts_of(const Grid& grid) {
  std::vector<long long> counts;
  for (std::size_t i = 0; i < grid.dims(); ++i) counts.push_back(static_cast<long long>(grid.count(i)));
  return counts;
}

}  // namespace

double contraction_multiply_adds(const Abstraction& abstraction) {
  const Layout layout(abstraction);
  double total = 0, product = 1;
  for (long long width : layout.width) {
    product *= double(width);
    total += product;
  }
  return total;
}

std::string opencl_program_source(const Abstraction& a, bool on_the_fly, std::size_t group_size) {
  const Layout layout(a);
  const NoiseModel& noise = *a.noise;
  std::ostringstream s;
  s << "// Generated by amytiss from the validated configuration\n"
    << "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n"
    // Post states and windows must match the C++ reference bit for bit: no fused double math.
    << "#pragma OPENCL FP_CONTRACT OFF\n"
    << "#define STATE_DIMS " << a.states.dims() << "\n"
    << "#define INPUT_DIMS " << a.inputs.dims() << "\n"
    << "#define DIST_DIMS " << a.disturbances.dims() << "\n"
    << "#define N_STATES " << a.states.size() << "u\n"
    << "#define N_INPUTS " << a.inputs.size() << "u\n"
    << "#define N_DISTS " << a.disturbances.size() << "u\n"
    << "#define MASS_RECORD " << layout.mass_record << "\n"
    << "#define BOUNDS_CAPACITY " << (*std::max_element(layout.width.begin(), layout.width.end()) + 1 + 7) / 8 * 8 << "\n"
    << "#define MULTIPLICATIVE " << (noise.type() == NoiseType::Multiplicative ? 1 : 0) << "\n"
    << "#define UNIFORM " << (noise.distribution() == Distribution::Uniform ? 1 : 0) << "\n"
    << "#define TRUNCATION_NONE " << (a.config.noise.truncation == Truncation::None ? 1 : 0) << "\n"
    << "#define ON_THE_FLY " << (on_the_fly ? 1 : 0) << "\n"
    << "#define GROUP_SIZE " << group_size << "\n";
  std::vector<long long> keep_half;
  for (std::int64_t h : noise.window_half_cells())
    keep_half.push_back(std::min<std::int64_t>(h, std::int64_t(1) << 40));
  auto real = [](double v) { return number(v); };
  auto integer = [](long long v) { return int_text(v); };
  s << constant_array("double", "STATE_LB", a.states.lb(), real)
    << constant_array("double", "STATE_ETA", a.states.eta(), real)
    << constant_array("int", "STATE_COUNT", counts_of(a.states), integer)
    << constant_array("int", "HALF_CELLS", layout.half, integer)
    << constant_array("int", "WHOLE_DIM", layout.whole, integer)
    << constant_array("long", "KEEP_HALF", keep_half, integer)
    << constant_array("int", "WIDTH", layout.width, integer)
    << constant_array("int", "MASS_OFFSET", layout.mass_offset, integer)
    << constant_array("int", "PADDED_STRIDE", layout.padded_stride, integer)
    << constant_array("double", "INPUT_LB", a.inputs.lb(), real)
    << constant_array("double", "INPUT_ETA", a.inputs.eta(), real)
    << constant_array("int", "INPUT_COUNT", counts_of(a.inputs), integer)
    << constant_array("double", "DIST_LB", a.disturbances.lb(), real)
    << constant_array("double", "DIST_ETA", a.disturbances.eta(), real)
    << constant_array("int", "DIST_COUNT", counts_of(a.disturbances), integer)
    << constant_array("double", "NOISE_SCALE", noise.base_scale(), real);
  s << contraction_source(layout, "contract_global", "__global")
    << contraction_source(layout, "contract_private", "");
  s << a.dynamics->opencl_source() << "\n";
  s << embedded_source("engine.cl");
  return s.str();
}

Policy synthesize_opencl(const Abstraction& a, const SynthesisOptions& options,
                         SynthesisReport* report, const OpenClEngineOptions& engine_options) {
  const auto start = Clock::now();
  SynthesisReport local_report;
  SynthesisReport& rep = report ? *report : local_report;

  if (!a.noise->separable())
    throw ConfigError("noise.covariance",
                      "a full (non-diagonal) covariance is supported by device: reference only; "
                      "use a diagonal covariance (n values, example: covariance: [0.75, 0.75]) or "
                      "compute.device: reference");
  const std::size_t n_states = a.states.size(), n_inputs = a.inputs.size(),
                    n_dists = a.disturbances.size();
  const Layout layout(a);
  if (n_states >= (std::size_t(1) << 32) || layout.padded_size >= (std::size_t(1) << 32))
    throw ConfigError("states", "the OpenCL engine supports fewer than 2^32 state cells (got " +
                                    std::to_string(n_states) + ")");

  // --- device set-up
  auto phase_start = Clock::now();
  const DeviceInfo device = choose_device(options.compute, rep.log);
  rep.device = device.label();
  cl_int error = CL_SUCCESS;
  const cl_context_properties properties[] = {CL_CONTEXT_PLATFORM,
                                              reinterpret_cast<cl_context_properties>(device.platform), 0};
  Context context(clCreateContext(properties, 1, &device.device, nullptr, nullptr, &error));
  check(error, "clCreateContext");
  Queue queue(clCreateCommandQueue(context.get(), device.device, 0, &error));
  check(error, "clCreateCommandQueue");
  rep.phases.push_back({"device setup", seconds_since(phase_start), 0, 0});

  auto report_progress = [&](const std::string& phase, unsigned done, double remaining) {
    if (!options.progress) return;
    Progress progress;
    progress.phase = phase;
    progress.steps_done = done;
    progress.steps_total = a.horizon;
    progress.device = device.label();
    progress.elapsed_s = seconds_since(start);
    progress.remaining_s = remaining;
    if (!options.progress(progress)) throw Cancelled();
  };

  // --- memory plan: stored when the records fit the budget, else on the fly
  const std::size_t record_bytes = sizeof(cl_uint) + sizeof(float) * std::size_t(layout.mass_record);
  const std::size_t records_per_state = n_inputs * n_dists;
  const std::size_t value_cells = layout.padded_size + kValueSlack;
  const std::size_t base_bytes = 2 * value_cells * sizeof(double) + n_states * (1 + sizeof(cl_uint));
  const double budget = options.compute.memory_fraction * double(device.global_memory);
  const double stored_bytes = double(n_states) * double(records_per_state) * double(record_bytes);
  const std::size_t max_states_by_allocation = std::max<std::size_t>(
      1, std::size_t(device.max_allocation / (records_per_state * sizeof(float) * std::size_t(layout.mass_record))));
  const bool fits = double(base_bytes) + stored_bytes <= budget && max_states_by_allocation >= 1 &&
                    records_per_state * sizeof(float) * std::size_t(layout.mass_record) <= device.max_allocation;
  const auto mib = [](double bytes) { return std::to_string(std::llround(bytes / 1048576.0)) + " MiB"; };
  bool on_the_fly = false;
  const std::string estimate = "stored transitions need " + mib(stored_bytes) + ", budget " +
                               mib(budget) + " (memory_fraction " + number(options.compute.memory_fraction) +
                               " of " + mib(double(device.global_memory)) + ")";
  switch (options.compute.transitions) {
    case TransitionStorage::OnTheFly:
      on_the_fly = true;
      rep.transitions = "on_the_fly (requested; " + estimate + ")";
      break;
    case TransitionStorage::Stored:
      on_the_fly = !fits;
      rep.transitions = fits ? "stored (requested; " + estimate + ")"
                             : "on_the_fly (stored requested but does not fit: " + estimate + ")";
      if (!fits) rep.log.push_back("warning: " + rep.transitions);
      break;
    default:
      on_the_fly = !fits;
      rep.transitions = (fits ? "stored (auto: " : "on_the_fly (auto: ") + estimate + ")";
      break;
  }
  rep.log.push_back("transitions: " + rep.transitions);

  SweepVariant variant = engine_options.variant;
  if (variant == SweepVariant::Auto)
    variant = device.is_gpu() ? SweepVariant::GroupPerState : SweepVariant::ItemPerState;
  std::size_t group_size = 1;
  while (group_size < std::min<std::size_t>(n_inputs, 128)) group_size *= 2;
  group_size = std::min(group_size, std::max<std::size_t>(1, device.max_work_group));
  rep.log.push_back(std::string("sweep: ") +
                    (variant == SweepVariant::GroupPerState
                         ? "one work-group of " + std::to_string(group_size) + " per state"
                         : std::string("one work-item per state")));

  // --- kernel build
  phase_start = Clock::now();
  const std::string source = opencl_program_source(a, on_the_fly, group_size);
  Program program = load_cached_program(context.get(), device, source, engine_options.kernel_cache_dir, rep.log);
  if (!program.get()) {
    const char* source_text = source.c_str();
    const std::size_t source_length = source.size();
    program = Program(clCreateProgramWithSource(context.get(), 1, &source_text, &source_length, &error));
    check(error, "clCreateProgramWithSource");
    error = clBuildProgram(program.get(), 1, &device.device, "", nullptr, nullptr);
    if (error != CL_SUCCESS) {
      std::size_t log_size = 0;
      clGetProgramBuildInfo(program.get(), device.device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &log_size);
      std::string build_log(log_size, '\0');
      clGetProgramBuildInfo(program.get(), device.device, CL_PROGRAM_BUILD_LOG, log_size,
                            build_log.data(), nullptr);
      throw DeviceError("OpenCL kernel build failed on " + device.label() + " (" +
                        cl_error_name(error) + "); compiler log:\n" + build_log);
    }
    store_cached_program(program.get(), device, source, engine_options.kernel_cache_dir, rep.log);
  }
  Kernel construct(clCreateKernel(program.get(), "construct", &error));
  check(error, "clCreateKernel(construct)");
  const char* sweep_name = variant == SweepVariant::GroupPerState ? "synthesize_group" : "synthesize_item";
  Kernel sweep(clCreateKernel(program.get(), sweep_name, &error));
  check(error, "clCreateKernel(synthesize)");
  rep.phases.push_back({"kernel build", seconds_since(phase_start), 0, 0});
  report_progress("setup", 0, -1);

  // --- buffers
  std::size_t device_bytes = 0;
  auto make_buffer = [&](cl_mem_flags flags, std::size_t bytes, void* host) {
    Buffer buffer(clCreateBuffer(context.get(), flags, std::max<std::size_t>(bytes, 4), host, &error));
    check(error, "clCreateBuffer");
    device_bytes += bytes;
    return buffer;
  };
  std::vector<cl_uchar> roles(n_states);
  std::vector<double> terminal(value_cells, 0.0);
  std::vector<std::size_t> padded_index(n_states);  // cell -> its place in the padded array
  std::size_t free_states = 0;
  for (std::size_t x = 0; x < n_states; ++x) {
    roles[x] = static_cast<cl_uchar>(a.roles[x]);
    free_states += a.roles[x] == CellRole::Free;
    const double value = a.roles[x] == CellRole::FixedOne ? 1.0
                         : a.roles[x] == CellRole::FixedZero ? 0.0
                                                             : a.terminal_value(CellRole::Free);
    padded_index[x] = layout.padded_offset(a.states, x);
    terminal[padded_index[x]] = value;
  }
  Buffer roles_buffer = make_buffer(CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, n_states, roles.data());
  Buffer values[2] = {
      make_buffer(CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, value_cells * sizeof(double), terminal.data()),
      make_buffer(CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, value_cells * sizeof(double), terminal.data())};
  Buffer best_input = make_buffer(CL_MEM_READ_WRITE, n_states * sizeof(cl_uint), nullptr);

  // Chunks of states: bounded by the allocation limit (stored) and by a launch size that keeps
  // every launch short (on the fly, and GPUs with watchdogs).
  std::size_t states_per_chunk = on_the_fly ? std::max<std::size_t>(1, (std::size_t(1) << 24) / records_per_state)
                                            : max_states_by_allocation;
  if (variant == SweepVariant::GroupPerState) states_per_chunk = std::min<std::size_t>(states_per_chunk, 1 << 20);
  if (engine_options.max_states_per_chunk)
    states_per_chunk = std::min(states_per_chunk, engine_options.max_states_per_chunk);
  states_per_chunk = std::min(states_per_chunk, n_states);
  struct Chunk {
    std::size_t first = 0, count = 0;
    Buffer starts, masses;
  };
  std::vector<Chunk> chunks;
  for (std::size_t first = 0; first < n_states; first += states_per_chunk) {
    Chunk chunk;
    chunk.first = first;
    chunk.count = std::min(states_per_chunk, n_states - first);
    const std::size_t records = on_the_fly ? 1 : chunk.count * records_per_state;
    chunk.starts = make_buffer(CL_MEM_READ_WRITE, records * sizeof(cl_uint), nullptr);
    chunk.masses = make_buffer(CL_MEM_READ_WRITE, records * sizeof(float) * std::size_t(layout.mass_record), nullptr);
    chunks.push_back(std::move(chunk));
  }
  if (chunks.size() > 1)
    rep.log.push_back("split into " + std::to_string(chunks.size()) + " chunks of up to " +
                      std::to_string(states_per_chunk) + " states");
  rep.device_bytes = device_bytes;
  rep.log.push_back("device memory: " + mib(double(device_bytes)));

  // Construction: 64 triples per work-group. Sweep (ItemPerState): 16 states per work-group, so
  // that pocl's threads can balance groups of unequal cost (fixed cells are free of work):
  // robot reach-avoid has 106 groups instead of 27, ~5% faster sweep than 64 (BENCHMARKS.md).
  const std::size_t construct_group = 64, item_group = 16;
  auto round_up = [](std::size_t value, std::size_t multiple) { return (value + multiple - 1) / multiple * multiple; };

  // --- construction (Algorithm 2)
  phase_start = Clock::now();
  if (!on_the_fly) {
    for (Chunk& chunk : chunks) {
      const cl_ulong triple_begin = cl_ulong(chunk.first) * records_per_state;
      const cl_ulong triple_count = cl_ulong(chunk.count) * records_per_state;
      check(clSetKernelArg(construct.get(), 0, sizeof(cl_ulong), &triple_begin), "clSetKernelArg");
      check(clSetKernelArg(construct.get(), 1, sizeof(cl_ulong), &triple_count), "clSetKernelArg");
      check(clSetKernelArg(construct.get(), 2, sizeof(cl_mem), &chunk.starts.handle), "clSetKernelArg");
      check(clSetKernelArg(construct.get(), 3, sizeof(cl_mem), &chunk.masses.handle), "clSetKernelArg");
      const std::size_t global = round_up(std::size_t(triple_count), construct_group);
      check(clEnqueueNDRangeKernel(queue.get(), construct.get(), 1, nullptr, &global, &construct_group, 0,
                                   nullptr, nullptr),
            "clEnqueueNDRangeKernel(construct)");
    }
    check(clFinish(queue.get()), "clFinish(construct)");
  }
  {
    const double seconds = seconds_since(phase_start);
    rep.phases.push_back({"construction", seconds,
                          on_the_fly ? 0.0 : double(a.pairs()) / std::max(seconds, 1e-9), 0});
  }
  report_progress("construction", 0, -1);

  // --- synthesis (Algorithm 4), V_{T_d} -> V_0
  Policy policy;
  policy.states = a.states;
  policy.inputs = a.inputs;
  policy.horizon = a.horizon;
  policy.roles = a.roles;
  policy.computed_by = device.label();
  policy.config_hash = config_hash(a.config);
  policy.values.assign((std::size_t(a.horizon) + 1) * n_states, 0.0);
  policy.input_index.assign(std::size_t(a.horizon) * n_states, 0);
  // One padded step at a time comes back to the host and is unpadded into the policy at once.
  std::vector<double> step_values(layout.padded_size);
  auto unpad = [&](unsigned step, const double* padded) {
    double* out = policy.values.data() + std::size_t(step) * n_states;
    for (std::size_t x = 0; x < n_states; ++x) out[x] = padded[padded_index[x]];
  };
  unpad(a.horizon, terminal.data());

  const double multiply_adds_per_step =
      double(free_states) * double(records_per_state) * contraction_multiply_adds(a);
  const auto synthesis_start = Clock::now();
  int current = 0;
  for (unsigned step = a.horizon; step-- > 0;) {
    phase_start = Clock::now();
    for (Chunk& chunk : chunks) {
      const cl_uint state_begin = cl_uint(chunk.first), state_count = cl_uint(chunk.count);
      cl_kernel k = sweep.get();
      check(clSetKernelArg(k, 0, sizeof(cl_mem), &values[current].handle), "clSetKernelArg");
      check(clSetKernelArg(k, 1, sizeof(cl_mem), &values[1 - current].handle), "clSetKernelArg");
      check(clSetKernelArg(k, 2, sizeof(cl_mem), &best_input.handle), "clSetKernelArg");
      check(clSetKernelArg(k, 3, sizeof(cl_mem), &roles_buffer.handle), "clSetKernelArg");
      check(clSetKernelArg(k, 4, sizeof(cl_uint), &state_begin), "clSetKernelArg");
      check(clSetKernelArg(k, 5, sizeof(cl_uint), &state_count), "clSetKernelArg");
      check(clSetKernelArg(k, 6, sizeof(cl_mem), &chunk.starts.handle), "clSetKernelArg");
      check(clSetKernelArg(k, 7, sizeof(cl_mem), &chunk.masses.handle), "clSetKernelArg");
      std::size_t global = 0, local = 0;
      if (variant == SweepVariant::GroupPerState) {
        local = group_size;
        global = chunk.count * group_size;
      } else {
        local = item_group;
        global = round_up(chunk.count, item_group);
      }
      check(clEnqueueNDRangeKernel(queue.get(), k, 1, nullptr, &global, &local, 0, nullptr, nullptr),
            "clEnqueueNDRangeKernel(synthesize)");
    }
    check(clEnqueueReadBuffer(queue.get(), best_input.get(), CL_FALSE, 0, n_states * sizeof(cl_uint),
                              policy.input_index.data() + std::size_t(step) * n_states, 0, nullptr, nullptr),
          "clEnqueueReadBuffer");
    check(clEnqueueReadBuffer(queue.get(), values[1 - current].get(), CL_FALSE, 0,
                              layout.padded_size * sizeof(double),
                              step_values.data(), 0, nullptr, nullptr),
          "clEnqueueReadBuffer");
    check(clFinish(queue.get()), "clFinish(synthesize)");
    current = 1 - current;
    const double seconds = seconds_since(phase_start);
    unpad(step, step_values.data());
    rep.phases.push_back({"step " + std::to_string(step), seconds,
                          double(a.pairs()) / std::max(seconds, 1e-9), multiply_adds_per_step});
    const unsigned done = a.horizon - step;
    const double remaining = seconds_since(synthesis_start) / done * (a.horizon - done);
    report_progress(done == a.horizon ? "done" : "synthesis", done, remaining);
  }

  rep.host_peak_bytes = peak_resident_bytes();
  return policy;
}

std::string selected_device_label(const ComputeConfig& compute) {
  std::vector<std::string> ignored_log;
  try {
    return choose_device(compute, ignored_log).label();
  } catch (const DeviceError&) {
    return "";
  }
}

}  // namespace detail

std::vector<std::string> list_opencl_devices() {
  std::vector<std::string> lines;
  for (const auto& info : detail::enumerate_devices()) {
    lines.push_back("[" + std::to_string(info.platform_index) + "." + std::to_string(info.device_index) +
                    "] " + info.label() + " (" + info.type_name() + ", " +
                    std::to_string(info.global_memory / 1048576) + " MiB, " +
                    std::to_string(info.compute_units) + " compute units" +
                    (info.fp64 ? "" : ", no double precision: unusable") + ")");
  }
  return lines;
}

}  // namespace amytiss
