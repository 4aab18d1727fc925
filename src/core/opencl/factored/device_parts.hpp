#pragma once
// The pieces of the factored sweep on an OpenCL device that one device and a team of devices
// share (internal): kernels, buffers, where each stage reads and writes, and the launches.
#include <cstdint>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/synthesis_types.hpp"
#include "opencl/device.hpp"
#include "factored/factored_plan.hpp"
#include "common/host_memory.hpp"
#include "opencl/engine_options.hpp"
#include "opencl/factored/program.hpp"

namespace amytiss::detail {

/// A mass table on the device (opencl/factored/tables.hpp): first kept cell, kept cells, masses.
struct DeviceTable {
  Buffer first, count, masses;
};
struct MassTable;
/// What stage k does in one time step, all slices together, with `shape`'s kernels.
struct StageWork {
  double multiply_adds = 0;
  /// Values its kernels load: a value per multiply-add, except where a pair of rows loads each
  /// value once for both (row_kernel.hpp).
  double value_loads = 0;
  /// Its input read once per slice (at most as often as values are loaded) and its output written
  /// once per slice, in bytes.
  double memory_bytes = 0;
};
StageWork stage_work(const Abstraction& abstraction, const FactoredPlan& plan, std::size_t k, const MassTable& table,
                     const StageShape& shape);
/// Where stage k of slice `slice` reads and writes: the input's offset (first stage of a slice
/// reads the slice out of V), the block [lo, hi) of the contracted dimension that the input holds
/// (the last stage contracts the slice's cells only), and whether to add to the output (later
/// slices of the last stage accumulate into Q, in slice order).
struct StagePlacement {
  cl_ulong in_offset = 0;
  cl_uint lo = 0, hi = 0, accumulate = 0;
};
StagePlacement stage_placement(const Abstraction& abstraction, const FactoredPlan& plan, std::size_t k,
                               std::size_t slice);
/// Arguments of a stage kernel: input and output tensors, the contracted dimension's table, the
/// placement.
void set_stage_arguments(cl_kernel kernel, cl_mem in, cl_mem out, const DeviceTable& table,
                         const StagePlacement& placement);
/// The further arguments of a stage kernel fused with the next stage: that stage's table.
void set_fused_arguments(cl_kernel kernel, const DeviceTable& next_table);

/// The shape `device` wants, or (options.factored_vector_width > 0) the shape of a device of that
/// native double vector width (1: the SIMT shape); options.factored_stream_bytes where set.
StageShape factored_stage_shape(const DeviceInfo& device, const OpenClEngineOptions& options);
/// A device's program of the plan (stage kernels, choose_inputs) in `shape`; a note says which.
struct FactoredKernels {
  StageShape shape;
  Program program;
  std::vector<Kernel> stages;
  Kernel choose;
};
FactoredKernels build_factored_kernels(const Abstraction& abstraction, const FactoredPlan& plan,
                                       const DeviceInfo& device, cl_context context, const std::string& cache_dir,
                                       const StageShape& shape, std::vector<EngineNote>& notes);

/// A device's buffers of the factored sweep: mass tables, roles, V (both arrays start at V_{T_d}),
/// best inputs, Q and the two stage tensors.
struct FactoredBuffers {
  std::vector<HostBlock> host_blocks;  // released after the buffers over them (declared first)
  std::vector<DeviceTable> tables;
  Buffer roles, values[2], best_input, q, stage_tensors[2];
  std::size_t device_bytes = 0;
};
/// `cpu_device`: Q and the stage tensors live in HostBlocks (common/host_memory.hpp). The two
/// stage tensors hold what the kernels of `shape` write (not the tensor of a fused stage).
FactoredBuffers allocate_factored_buffers(const Abstraction& abstraction, const FactoredPlan& plan,
                                          const std::vector<MassTable>& tables, cl_context context, bool cpu_device,
                                          const StageShape& shape);
/// V_{T_d} per state, then kTensorSlack zero cells.
std::vector<double> factored_terminal_values(const Abstraction& abstraction);

/// Work-items [first, end) of a kernel in launches of at most kFactoredMaxLaunchItems, groups of
/// `group`. The last group may run past `end` (a team's other device's range, which the exchange
/// overwrites; on one device, entries past the tensor's end that no one reads).
void launch_range(cl_command_queue queue, cl_kernel kernel, std::uint64_t first, std::uint64_t end, std::size_t group);
/// The group size of the factored kernels on `device`.
std::size_t factored_group_size(const DeviceInfo& device);
/// Arguments of choose_inputs: Q, the new values, the best inputs, the roles.
void set_choose_arguments(cl_kernel kernel, FactoredBuffers& buffers, int output);

}  // namespace amytiss::detail
