#pragma once
// Internal interface of the OpenCL engine (not installed; tests include it through src/core).
// Its parts: opencl_device (devices), opencl_source (generated program), opencl_program_cache
// (building it), opencl_layout (memory layout), opencl_run (buffers and launches).
#include <cstddef>
#include <functional>
#include <optional>
#include <vector>
#include <string>

#include "amytiss/abstraction.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/policy.hpp"
#include "opencl/factored/plan.hpp"
#include "opencl/device.hpp"
#include "opencl/layout.hpp"

namespace amytiss::detail {

/// Work decomposition of the synthesis sweep. Both run the same kernel functions and give
/// bit-identical results; they differ only in how states and inputs map to work-items.
enum class SweepVariant {
  Auto,          ///< GroupPerState on GPUs, ItemPerState otherwise
  ItemPerState,  ///< one work-item per state, looping over inputs (CPU)
  GroupPerState  ///< one work-group per state, work-items over inputs, local argmax (GPU)
};

struct OpenClEngineOptions {
  SweepVariant variant = SweepVariant::Auto;  ///< of the dense sweep (compute.sweep chooses the sweep)
  /// Upper bound of states per chunk (stored buffers and launches); 0: chosen from device limits.
  std::size_t max_states_per_chunk = 0;
  /// Folder of the program binary cache; empty: $XDG_CACHE_HOME/amytiss/kernels or
  /// ~/.cache/amytiss/kernels; "-": no cache (always build from source).
  std::string kernel_cache_dir;
  /// Factored sweep: one entry per work-item (the GPU shape) even on a SIMD device (tests).
  bool factored_entry_per_item = false;
};

/// The OpenCL engine (device chosen by options.compute, see synthesize()).
Policy synthesize_opencl(const Abstraction& abstraction, const SynthesisOptions& options,
                         SynthesisReport* report, const OpenClEngineOptions& engine_options = {});

/// Several devices or ranks (compute.devices, options.communicator): the states, or the factored
/// sweep's stage entries, split over them (scale_out/team_dense.cpp, scale_out/team_factored.cpp, docs/scale_out.md).
Policy synthesize_team(const Abstraction& abstraction, const SynthesisOptions& options, SynthesisReport& report,
                       const OpenClEngineOptions& engine_options);

/// Parts of the engine that the single-device and the several-device runs share
/// (opencl/engine.cpp). The dense sweep's limit on the padded value array (ConfigError).
void check_dense_supported(const Layout& layout);
/// The factored plan when compute.sweep asks for it or it saves enough work (nullopt: dense); a
/// Sweep note says which and why.
std::optional<FactoredPlan> choose_factored(const Abstraction& abstraction, const DeviceInfo& device,
                                            const SynthesisOptions& options, SynthesisReport& report);
/// Step `step` of the policy's values from a padded value array.
void unpad(Policy& policy, unsigned step, const std::vector<std::size_t>& padded_index, const double* padded);

/// Label ("platform / device") of the device that `compute` selects, or "" when none matches.
std::string selected_device_label(const ComputeConfig& compute);

/// One attempt of an engine run, and the label of the CPU device a fallback would use.
using EngineAttempt = std::function<Policy(const SynthesisOptions&, SynthesisReport*)>;
using DeviceLabel = std::function<std::string(const ComputeConfig&)>;
/// A device that fails (DeviceError) is retried once on the CPU device, with a Warning
/// DeviceFallback note in report->notes, unless the failing device is that CPU device or `cpu`
/// was asked for (the first attempt's notes are kept).
/// synthesize() calls it with synthesize_opencl; tests call it with failing attempts.
Policy synthesize_with_cpu_fallback(const SynthesisOptions& options, SynthesisReport* report,
                                    const EngineAttempt& attempt, const DeviceLabel& cpu_label);

}  // namespace amytiss::detail
