#pragma once
// The factored sweep on an OpenCL device (internal): its generated program and its run.
#include <functional>
#include <vector>
#include <string>

#include "amytiss/engine.hpp"
#include "amytiss/policy.hpp"
#include "opencl/factored/plan.hpp"
#include "opencl/device.hpp"


namespace amytiss::detail {

/// Cells after the end of every value and stage tensor buffer: a vector stage's last chunk of a
/// row may read that far past it.
constexpr std::size_t kTensorSlack = 8;

/// Launches of the factored sweep: at most this many work-items each (watchdogs, and 32-bit
/// work-item limits of some drivers), in groups of kFactoredGroupSize (or the device's maximum).
constexpr std::size_t kFactoredMaxLaunchItems = std::size_t(1) << 30;
constexpr std::size_t kFactoredGroupSize = 64;

/// How a stage with a vector digit maps to work-items. SIMD devices (CPUs: native double vector
/// width > 1) take a row of the vector digit per work-item in explicit vectors; SIMT devices
/// (GPUs: width 1) one entry per work-item with the vector digit fastest, so that neighbouring
/// work-items read neighbouring values. Same sums in the same order either way.
struct StageShape {
  bool row_per_item = true;
  /// Entries per vector: 8, 4 or 2 by the digit's radix for rows, 1 for entries.
  std::uint64_t lanes(std::uint64_t radix) const;
};
StageShape stage_shape_for(unsigned native_double_width);

/// Work-items of a stage's launch.
std::uint64_t stage_work_items(const FactoredStage& stage, const StageShape& shape);

/// OpenCL C of the plan: kernels stage0..stage{d-1} (one elimination each) and choose_inputs.
std::string factored_program_source(const Abstraction& abstraction, const FactoredPlan& plan,
                                    const StageShape& shape);

/// What the factored run needs of the engine around it: an open device, and how to report.
struct FactoredRunContext {
  const DeviceInfo* device = nullptr;
  cl_context context = nullptr;
  cl_command_queue queue = nullptr;
  std::string kernel_cache_dir;  ///< see build_program
  bool entry_per_item = false;   ///< the SIMT shape whatever the device (tests)
  bool profile = false;          ///< finish every kernel before its clock stops
  /// Called after construction and after each time step (phase, steps done, seconds left or -1);
  /// throws Cancelled to stop.
  std::function<void(Phase, unsigned, double)> progress;
};

/// A mass table on the device (opencl/factored/tables.hpp): first kept cell, kept cells, masses.
struct DeviceTable {
  Buffer first, count, masses;
};
struct MassTable;
/// Multiply-adds stage `stage` does over all slices of one time step.
double stage_multiply_adds(const FactoredStage& stage, const MassTable& table, std::size_t slices);
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

/// A device's program of the plan (stage kernels, choose_inputs) in the shape the device wants
/// (entry_per_item: the SIMT shape whatever the device); a note says which shape.
struct FactoredKernels {
  StageShape shape;
  Program program;
  std::vector<Kernel> stages;
  Kernel choose;
};
FactoredKernels build_factored_kernels(const Abstraction& abstraction, const FactoredPlan& plan,
                                       const DeviceInfo& device, cl_context context, const std::string& cache_dir,
                                       bool entry_per_item, std::vector<EngineNote>& notes);

/// A device's buffers of the factored sweep: mass tables, roles, V (both arrays start at V_{T_d}),
/// best inputs, Q and the two stage tensors.
struct FactoredBuffers {
  std::vector<DeviceTable> tables;
  Buffer roles, values[2], best_input, q, stage_tensors[2];
  std::size_t device_bytes = 0;
};
FactoredBuffers allocate_factored_buffers(const Abstraction& abstraction, const FactoredPlan& plan,
                                          const std::vector<MassTable>& tables, cl_context context);
/// V_{T_d} per state, then kTensorSlack zero cells.
std::vector<double> factored_terminal_values(const Abstraction& abstraction);

/// The backward recursion V_{T_d} -> V_0 with the factored sweep. Fills report->phases
/// (construction, one per step; with profile, also one per stage over all steps) and notes.
Policy run_factored_sweep(const Abstraction& abstraction, const FactoredPlan& plan,
                          const FactoredRunContext& run, SynthesisReport& report);

}  // namespace amytiss::detail
