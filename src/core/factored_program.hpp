#pragma once
// The factored sweep on an OpenCL device (internal): its generated program and its run.
#include <functional>
#include <string>

#include "amytiss/engine.hpp"
#include "amytiss/policy.hpp"
#include "factored_plan.hpp"
#include "opencl_device.hpp"


namespace amytiss::detail {

/// OpenCL C of the plan: kernels stage0..stage{d-1} (one elimination each) and choose_inputs.
std::string factored_program_source(const Abstraction& abstraction, const FactoredPlan& plan);

/// What the factored run needs of the engine around it: an open device, and how to report.
struct FactoredRunContext {
  const DeviceInfo* device = nullptr;
  cl_context context = nullptr;
  cl_command_queue queue = nullptr;
  std::string kernel_cache_dir;  ///< see build_program
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
