#pragma once
// The factored sweep on one OpenCL device (internal): mass tables, then per time step and slice
// one launch per elimination stage, and the input choice from Q; run by the backward driver.
#include <string>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "solve/backward_driver.hpp"
#include "opencl/device.hpp"
#include "factored/factored_plan.hpp"
#include "opencl/factored/program.hpp"

namespace amytiss::detail {

/// What the factored run needs of the engine around it: an open device and its settings.
struct FactoredRunContext {
  const DeviceInfo* device = nullptr;
  cl_context context = nullptr;
  cl_command_queue queue = nullptr;
  std::string kernel_cache_dir;  ///< see build_program
  StageShape shape;              ///< of the kernels (factored_stage_shape)
  bool profile = false;          ///< finish every kernel before its clock stops
};

/// The backward recursion V_{T_d} -> V_0 (or interval iteration) with the factored sweep.
/// Reports the kernel build, construction and every step; with profile, also one breakdown per
/// stage over all steps.
Policy run_factored_sweep(const Abstraction& abstraction, const FactoredPlan& plan, const FactoredRunContext& run,
                          StepReporter& reporter);

}  // namespace amytiss::detail
