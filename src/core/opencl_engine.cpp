// The OpenCL engine: a short sequence of named steps over the parts in opencl_device,
// opencl_source, opencl_program_cache and opencl_run. The algorithm lives in kernels/engine.cl.
#include "opencl_engine.hpp"

#include <chrono>
#include <string>
#include <vector>

#include "amytiss/errors.hpp"
#include "opencl_device.hpp"
#include "opencl_layout.hpp"
#include "opencl_program_cache.hpp"
#include "opencl_run.hpp"
#include "opencl_source.hpp"

namespace amytiss::detail {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// What the OpenCL engine cannot run, found before any device work.
void check_supported(const Abstraction& a, const Layout& layout) {
  if (!a.noise->separable())
    throw ConfigError("noise.covariance",
                      "a full (non-diagonal) covariance is supported by device: reference only; "
                      "use a diagonal covariance (n values, example: covariance: [0.75, 0.75]) or "
                      "compute.device: reference");
  if (a.states.size() >= (std::size_t(1) << 32) || layout.padded_size >= (std::size_t(1) << 32))
    throw ConfigError("states", "the OpenCL engine supports fewer than 2^32 state cells (got " +
                                    std::to_string(a.states.size()) + ")");
}

Kernel create_kernel(cl_program program, const char* name) {
  cl_int error = CL_SUCCESS;
  Kernel kernel(clCreateKernel(program, name, &error));
  check(error, (std::string("clCreateKernel(") + name + ")").c_str());
  return kernel;
}

// The policy before the sweep: grids, roles, provenance, V_{T_d} and room for every step.
Policy empty_policy(const Abstraction& a, const std::string& device_label) {
  Policy policy;
  policy.states = a.states;
  policy.inputs = a.inputs;
  policy.horizon = a.horizon;
  policy.roles = a.roles;
  policy.computed_by = device_label;
  policy.config_hash = config_hash(a.config);
  policy.values.assign((std::size_t(a.horizon) + 1) * a.states.size(), 0.0);
  policy.input_index.assign(std::size_t(a.horizon) * a.states.size(), 0);
  return policy;
}

// Step `step` of the policy's values from a padded value array.
void unpad(Policy& policy, unsigned step, const std::vector<std::size_t>& padded_index, const double* padded) {
  double* out = policy.values.data() + std::size_t(step) * padded_index.size();
  for (std::size_t x = 0; x < padded_index.size(); ++x) out[x] = padded[padded_index[x]];
}

}  // namespace

Policy synthesize_opencl(const Abstraction& a, const SynthesisOptions& options, SynthesisReport* report,
                         const OpenClEngineOptions& engine_options) {
  const auto start = Clock::now();
  SynthesisReport local_report;
  SynthesisReport& rep = report ? *report : local_report;
  const Layout layout(a);
  check_supported(a, layout);

  auto phase_start = Clock::now();
  const DeviceInfo device = choose_device(options.compute, rep.notes);
  rep.device = device.label();
  DeviceSession session = open_session(device);
  rep.phases.push_back({"device setup", seconds_since(phase_start), 0, 0});

  auto report_progress = [&](Phase phase, unsigned done, double remaining) {
    if (options.progress && !options.progress({phase, done, a.horizon, device.label(), seconds_since(start), remaining}))
      throw Cancelled();
  };

  const RunPlan plan = plan_run(a, layout, device, options, engine_options, rep);

  phase_start = Clock::now();
  const Program program = build_program(session.context.get(), device,
                                        opencl_program_source(a, plan.on_the_fly, plan.group_size),
                                        engine_options.kernel_cache_dir, rep.notes);
  const Kernel construct = create_kernel(program.get(), "construct");
  const Kernel sweep = create_kernel(
      program.get(), plan.variant == SweepVariant::GroupPerState ? "synthesize_group" : "synthesize_item");
  rep.phases.push_back({"kernel build", seconds_since(phase_start), 0, 0});
  report_progress(Phase::Setup, 0, -1);

  RunBuffers buffers = allocate_buffers(a, layout, plan, session.context.get(), rep);

  // Construction (Algorithm 2 of the paper); on the fly, the sweep computes records as it goes.
  phase_start = Clock::now();
  if (!plan.on_the_fly) construct_transitions(session.queue.get(), construct.get(), plan, buffers);
  const double construction_seconds = seconds_since(phase_start);
  rep.phases.push_back({"construction", construction_seconds,
                        plan.on_the_fly ? 0.0 : double(a.pairs()) / std::max(construction_seconds, 1e-9), 0});
  report_progress(Phase::Construction, 0, -1);

  // Synthesis (Algorithm 4), V_{T_d} -> V_0, one padded step at a time back to the host.
  Policy policy = empty_policy(a, device.label());
  unpad(policy, a.horizon, buffers.padded_index, buffers.terminal.data());
  std::vector<double> step_values(layout.padded_size);
  const double multiply_adds_per_step =
      double(buffers.free_states) * double(plan.records_per_state) * contraction_multiply_adds(a);
  const auto synthesis_start = Clock::now();
  int current = 0;
  for (unsigned step = a.horizon; step-- > 0;) {
    phase_start = Clock::now();
    sweep_step(session.queue.get(), sweep.get(), plan, buffers, current,
               policy.input_index.data() + std::size_t(step) * a.states.size(), step_values);
    current = 1 - current;
    const double seconds = seconds_since(phase_start);
    unpad(policy, step, buffers.padded_index, step_values.data());
    rep.phases.push_back({"step " + std::to_string(step), seconds, double(a.pairs()) / std::max(seconds, 1e-9),
                          multiply_adds_per_step});
    const unsigned done = a.horizon - step;
    const double remaining = seconds_since(synthesis_start) / done * (a.horizon - done);
    report_progress(done == a.horizon ? Phase::Done : Phase::Synthesis, done, remaining);
  }

  rep.host_peak_bytes = peak_resident_bytes();
  return policy;
}

}  // namespace amytiss::detail
