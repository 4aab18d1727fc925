#pragma once
// Settings of the OpenCL engines that the configuration does not expose (tests and benchmarks).
#include <cstddef>
#include <optional>
#include <string>

namespace amytiss::detail {

/// Work decomposition of the dense sweep. Both run the same kernel functions and give
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
  /// Factored sweep: the double vector width its kernels are generated for; 0: the device's
  /// native width. 1 takes one entry per work-item (the GPU shape) even on a SIMD device; 4 the
  /// row kernels of an AVX2 CPU on an AVX-512 one (tests).
  unsigned factored_vector_width = 0;
  /// Factored sweep: stage outputs above this many bytes are stored past the caches where their
  /// lines align; unset: the default of the row kernels (StageShape), 0: every aligned one (tests).
  std::optional<double> factored_stream_bytes;
};

}  // namespace amytiss::detail
