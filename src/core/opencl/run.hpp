#pragma once
// One run of the synthesis kernels on a device: where the transitions live (stored or on the
// fly), how the sweep maps to work-items, the device buffers, the construction launches, one
// sweep step and its read-back. opencl/engine.cpp and scale_out/team_dense.cpp
// string these together.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/synthesis_types.hpp"
#include "opencl/device.hpp"
#include "opencl/engine_options.hpp"
#include "opencl/layout.hpp"

namespace amytiss::detail {

/// Storage of the transitions and decomposition of the sweep.
struct RunPlan {
  bool on_the_fly = false;
  SweepVariant variant = SweepVariant::ItemPerState;
  std::size_t group_size = 1;        ///< work-items per group of synthesize_group (a power of 2)
  std::size_t states_per_chunk = 1;  ///< states per stored-record buffer and per launch
  std::size_t records_per_state = 1; ///< inputs x disturbances
  std::size_t slice_first = 0;       ///< the states this device sweeps: [slice_first, slice_end)
  std::size_t slice_end = 0;
};
/// Stored when the records fit compute.memory_fraction of the device memory and its
/// allocation limit (or as requested), the sweep variant from the device type; notes say why.
/// With several devices, `slice` is this device's states (default: all of them).
/// A request for stored transitions that do not fit is a ConfigError naming compute.transitions.
RunPlan plan_run(const Abstraction& abstraction, const Layout& layout, const DeviceInfo& device,
                 const ComputeConfig& compute, const OpenClEngineOptions& engine_options,
                 SynthesisReport& report, std::size_t slice_first = 0, std::size_t slice_end = SIZE_MAX);

/// The states of one chunk and their transition records (one-element buffers on the fly).
struct Chunk {
  std::size_t first = 0, count = 0;
  Buffer starts, masses;
};
/// Device buffers of a run and the host's view of the padded value array.
struct RunBuffers {
  Buffer roles;
  Buffer values[2];  ///< padded value arrays V_{k+1} and V_k, swapped every step
  Buffer best_input;
  std::vector<Chunk> chunks;
  std::vector<std::size_t> padded_index;  ///< state cell -> its place in the padded array
  std::vector<double> terminal;           ///< padded V_{T_d}
  std::size_t free_states = 0;
  std::size_t device_bytes = 0;
};
/// Allocates and fills the buffers (values start at V_{T_d}); notes the chunking and the memory.
RunBuffers allocate_buffers(const Abstraction& abstraction, const Layout& layout, const RunPlan& plan,
                            cl_context context, SynthesisReport& report);

/// Launches the construction kernel over every chunk's triples and waits for it (wait false:
/// only enqueues).
void construct_transitions(cl_command_queue queue, cl_kernel construct, const RunPlan& plan, RunBuffers& buffers,
                           bool wait = true);

/// Enqueues the sweep kernel over every chunk from values[current] into values[1 - current].
void enqueue_sweep(cl_command_queue queue, cl_kernel sweep, const RunPlan& plan, RunBuffers& buffers, int current);

/// One step of the backward recursion: sweep kernel over every chunk from values[current] into
/// values[1 - current], then reads back the best inputs into `input_index` (one per state) and
/// the padded new values into `padded_values`, and waits.
void sweep_step(cl_command_queue queue, cl_kernel sweep, const RunPlan& plan, RunBuffers& buffers, int current,
                std::uint32_t* input_index, std::vector<double>& padded_values);

/// The values of every state cell (out, states.size()) from a padded value array.
void unpad(double* out, const std::vector<std::size_t>& padded_index, const double* padded);

}  // namespace amytiss::detail
