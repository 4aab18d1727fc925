// Devices: enumeration through the ICD loader and the choice that compute.* makes.
#include "opencl/device.hpp"

#include <algorithm>
#include <cctype>

#include "amytiss/errors.hpp"

namespace amytiss {
namespace detail {

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


namespace {

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
template <typename T>
T device_value(cl_device_id device, cl_device_info what) {
  T value{};
  clGetDeviceInfo(device, what, sizeof(T), &value, nullptr);
  return value;
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


}  // namespace

std::string platform_string(cl_platform_id platform, cl_platform_info what) {
  return info_string(clGetPlatformInfo, platform, what);
}
std::string device_string(cl_device_id device, cl_device_info what) {
  return info_string(clGetDeviceInfo, device, what);
}

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
      info.native_double_width = device_value<cl_uint>(ids[d], CL_DEVICE_NATIVE_VECTOR_WIDTH_DOUBLE);
      info.max_clock_mhz = device_value<cl_uint>(ids[d], CL_DEVICE_MAX_CLOCK_FREQUENCY);
      devices.push_back(info);
    }
  }
  return devices;
}


std::vector<DeviceInfo> with_double_precision(const std::vector<DeviceInfo>& devices, std::vector<EngineNote>& notes) {
  std::vector<DeviceInfo> usable;
  for (const DeviceInfo& info : devices) {
    if (info.fp64)
      usable.push_back(info);
    else
      notes.push_back({NoteSeverity::Info, NoteKind::DeviceChoice,
                       "skipping " + info.label() + ": no double precision (cl_khr_fp64)"});
  }
  return usable;
}

DeviceInfo select_device(const std::vector<DeviceInfo>& usable, const DeviceSelector& selector,
                         const std::string& text) {
  std::size_t seen = 0;
  for (const DeviceInfo& info : usable) {
    const bool kind_matches = selector.kind == DeviceSelector::Kind::Gpu   ? info.is_gpu()
                              : selector.kind == DeviceSelector::Kind::Cpu ? info.is_cpu()
                                                                           : info.platform_index == selector.platform;
    if (!kind_matches) continue;
    if (selector.kind == DeviceSelector::Kind::Index ? info.device_index == selector.index : seen++ == selector.index)
      return info;
  }
  std::string present;
  for (const DeviceInfo& info : usable)
    present += "\n  [" + std::to_string(info.platform_index) + "." + std::to_string(info.device_index) + "] " +
               info.label() + " (" + info.type_name() + ")";
  throw DeviceError("compute.devices: entry '" + text + "' matches no OpenCL device with double precision (example: "
                    "devices: [cpu:0]); devices:" + (present.empty() ? std::string(" none") : present));
}

DeviceInfo choose_device(const ComputeConfig& compute, std::vector<EngineNote>& notes) {
  std::vector<DeviceInfo> all = enumerate_devices();
  if (all.empty())
    throw DeviceError("no OpenCL device found (no ICD platform answered); install pocl "
                      "(Debian: pocl-opencl-icd) or use compute.device: reference");
  std::vector<DeviceInfo> selected;
  for (const DeviceInfo& info : all)
    if (selector_matches(compute.platform, info.platform_index, info.platform_name) &&
        selector_matches(compute.device_name, info.device_index, info.device_name))
      selected.push_back(info);
  const std::vector<DeviceInfo> candidates = with_double_precision(selected, notes);
  if (candidates.empty() && compute.platform.empty() && compute.device_name.empty())
    throw DeviceError("no OpenCL device with double precision found (amytiss_synth --list-devices shows the devices); "
                      "use compute.device: reference");
  if (candidates.empty())
    throw DeviceError(std::string(compute.platform.empty() ? "compute.device_name" : "compute.platform") +
                      ": no OpenCL device with double precision matches compute.platform '" + compute.platform +
                          "' and compute.device_name '" + compute.device_name +
                          "' (example: platform: 0; amytiss_synth --list-devices shows the devices)");
  auto first_of = [&](bool gpu) -> const DeviceInfo* {
    for (const DeviceInfo& info : candidates)
      if (gpu ? info.is_gpu() : info.is_cpu()) return &info;
    return nullptr;
  };
  const DeviceInfo* gpu = first_of(true);
  const DeviceInfo* cpu = first_of(false);
  // An explicit kind is honoured or refused, never replaced by another device.
  auto refuse = [&](const std::string& kind) -> DeviceError {
    std::string present;
    for (const DeviceInfo& info : all) present += "\n  " + info.label() + " (" + info.type_name() + ")";
    return DeviceError("compute.device: got " + kind + ", but no OpenCL " + kind +
                       " device with double precision matches (example: device: auto); devices present:" + present);
  };
  switch (compute.device) {
    case DeviceKind::Gpu:
      if (!gpu) throw refuse("gpu");
      notes.push_back({NoteSeverity::Info, NoteKind::DeviceChoice, "device gpu: " + gpu->label()});
      return *gpu;
    case DeviceKind::Cpu:
      if (!cpu) throw refuse("cpu");
      notes.push_back({NoteSeverity::Info, NoteKind::DeviceChoice, "device cpu: " + cpu->label()});
      return *cpu;
    default: {
      const DeviceInfo& chosen = gpu ? *gpu : cpu ? *cpu : candidates.front();
      notes.push_back({NoteSeverity::Info, NoteKind::DeviceChoice,
                       std::string("device auto: ") + (gpu ? "chose GPU " : "no OpenCL GPU found, using ") +
                           chosen.label()});
      return chosen;
    }
  }
}

DeviceSession open_session(const DeviceInfo& device) {
  cl_int error = CL_SUCCESS;
  const cl_context_properties properties[] = {CL_CONTEXT_PLATFORM,
                                              reinterpret_cast<cl_context_properties>(device.platform), 0};
  DeviceSession session;
  session.context = Context(clCreateContext(properties, 1, &device.device, nullptr, nullptr, &error));
  check(error, "clCreateContext");
  session.queue = Queue(clCreateCommandQueue(session.context.get(), device.device, 0, &error));
  check(error, "clCreateCommandQueue");
  return session;
}

Kernel create_kernel(cl_program program, const char* name) {
  cl_int error = CL_SUCCESS;
  Kernel kernel(clCreateKernel(program, name, &error));
  check(error, (std::string("clCreateKernel(") + name + ")").c_str());
  return kernel;
}

std::string selected_device_label(const ComputeConfig& compute) {
  std::vector<EngineNote> ignored_notes;
  try {
    return choose_device(compute, ignored_notes).label();
  } catch (const DeviceError&) {
    return "";
  } catch (const ConfigError&) {
    return "";
  }
}

}  // namespace detail

}  // namespace amytiss
