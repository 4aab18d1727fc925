#pragma once
// The factored sweep on an OpenCL device (internal): its generated program and its run.
#include <functional>
#include <string>

#include "amytiss/engine.hpp"
#include "amytiss/policy.hpp"
#include "factored_plan.hpp"
#include "opencl_device.hpp"


namespace amytiss::detail {

/// Cells after the end of every value and stage tensor buffer: a vector stage's last chunk of a
/// row may read that far past it.
constexpr std::size_t kTensorSlack = 8;

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

/// The backward recursion V_{T_d} -> V_0 with the factored sweep. Fills report->phases
/// (construction, one per step; with profile, also one per stage over all steps) and notes.
Policy run_factored_sweep(const Abstraction& abstraction, const FactoredPlan& plan,
                          const FactoredRunContext& run, SynthesisReport& report);

}  // namespace amytiss::detail
