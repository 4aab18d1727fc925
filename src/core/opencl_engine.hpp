#pragma once
// Internal interface of the OpenCL engine (not installed; tests include it through src/core).
#include <cstddef>
#include <functional>
#include <string>

#include "amytiss/abstraction.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/policy.hpp"

namespace amytiss::detail {

/// Work decomposition of the synthesis sweep. Both run the same kernel functions and give
/// bit-identical results; they differ only in how states and inputs map to work-items.
enum class SweepVariant {
  Auto,          ///< GroupPerState on GPUs, ItemPerState otherwise
  ItemPerState,  ///< one work-item per state, looping over inputs (CPU)
  GroupPerState  ///< one work-group per state, work-items over inputs, local argmax (GPU)
};

struct OpenClEngineOptions {
  SweepVariant variant = SweepVariant::Auto;
  /// Upper bound of states per chunk (stored buffers and launches); 0: chosen from device limits.
  std::size_t max_states_per_chunk = 0;
  /// Folder of the program binary cache; empty: $XDG_CACHE_HOME/amytiss/kernels or
  /// ~/.cache/amytiss/kernels; "-": no cache (always build from source).
  std::string kernel_cache_dir;
};

/// The OpenCL engine (device chosen by options.compute, see synthesize()).
Policy synthesize_opencl(const Abstraction& abstraction, const SynthesisOptions& options,
                         SynthesisReport* report, const OpenClEngineOptions& engine_options = {});

/// Label ("platform / device") of the device that `compute` selects, or "" when none matches.
std::string selected_device_label(const ComputeConfig& compute);

/// One attempt of an engine run, and the label of the CPU device a fallback would use.
using EngineAttempt = std::function<Policy(const SynthesisOptions&, SynthesisReport*)>;
using DeviceLabel = std::function<std::string(const ComputeConfig&)>;
/// SPEC section 7: a device that fails (DeviceError) is retried once on the CPU device, with a
/// warning in report->log, unless the failing device is that CPU device or `cpu` was asked for.
/// synthesize() calls it with synthesize_opencl; tests call it with failing attempts.
Policy synthesize_with_cpu_fallback(const SynthesisOptions& options, SynthesisReport* report,
                                    const EngineAttempt& attempt, const DeviceLabel& cpu_label);

/// The OpenCL C source built for a problem: generated prelude + dynamics + engine.cl.
std::string opencl_program_source(const Abstraction& abstraction, bool on_the_fly,
                                  std::size_t group_size);

/// Nominal multiply-adds of one separable contraction of the problem's window.
double contraction_multiply_adds(const Abstraction& abstraction);

}  // namespace amytiss::detail
