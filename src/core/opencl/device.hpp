#pragma once
// OpenCL plumbing shared by the engine's parts: owning handles, error checks and the devices
// visible through the ICD loader, with the choice among them that compute.device/platform/
// device_name make.
#include <CL/cl.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/synthesis_types.hpp"

namespace amytiss::detail {

/// Name of an OpenCL error code ("CL_OUT_OF_RESOURCES"), or "OpenCL error".
const char* cl_error_name(cl_int code);
/// Throws DeviceError "<call> failed: <name> (<code>)" unless code is CL_SUCCESS.
void check(cl_int code, const char* call);

/// Owning handle of an OpenCL object, released with Release.
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

/// The kernel `name` of a built program; DeviceError naming it when it is missing.
Kernel create_kernel(cl_program program, const char* name);

/// A string property of a platform or a device; "?" when the query fails.
std::string platform_string(cl_platform_id platform, cl_platform_info what);
std::string device_string(cl_device_id device, cl_device_info what);

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
  cl_uint native_double_width = 1;  ///< CL_DEVICE_NATIVE_VECTOR_WIDTH_DOUBLE: 1 on SIMT GPUs
  cl_uint max_clock_mhz = 0;        ///< CL_DEVICE_MAX_CLOCK_FREQUENCY
  bool is_gpu() const { return (type & CL_DEVICE_TYPE_GPU) != 0; }
  bool is_cpu() const { return (type & CL_DEVICE_TYPE_CPU) != 0; }
  std::string label() const { return platform_name + " / " + device_name; }
  std::string type_name() const {
    return is_gpu() ? "GPU" : is_cpu() ? "CPU" : (type & CL_DEVICE_TYPE_ACCELERATOR) ? "accelerator" : "other";
  }
};

/// Every device of every platform, in platform then device order.
std::vector<DeviceInfo> enumerate_devices();

/// The devices with double precision (post states and windows are computed in double); each
/// one without is skipped with a DeviceChoice note.
std::vector<DeviceInfo> with_double_precision(const std::vector<DeviceInfo>& devices, std::vector<EngineNote>& notes);

/// The device that a compute.devices entry (`text`, parsed as `selector`) names among `usable`:
/// the N-th GPU or CPU device, or platform P's device D. ConfigError naming the devices when none.
DeviceInfo select_device(const std::vector<DeviceInfo>& usable, const DeviceSelector& selector,
                         const std::string& text);

/// The device that `compute` selects (auto: the first GPU, else the first CPU device; cpu / gpu
/// missing: another device, with a warning note). Devices without double precision are skipped
/// with a note. Throws DeviceError when no device matches.
DeviceInfo choose_device(const ComputeConfig& compute, std::vector<EngineNote>& notes);

/// Label ("platform / device") of the device that `compute` selects, or "" when none matches.
std::string selected_device_label(const ComputeConfig& compute);

/// A context and an in-order command queue on one device.
struct DeviceSession {
  Context context;
  Queue queue;
};
DeviceSession open_session(const DeviceInfo& device);

}  // namespace amytiss::detail
