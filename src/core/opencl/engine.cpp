// The OpenCL engine: a short sequence of named steps over the parts in opencl_device,
// opencl_source, opencl_program_cache and opencl_run. The algorithm lives in kernels/engine.cl.
#include "opencl/engine.hpp"

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "amytiss/errors.hpp"
#include "opencl/device_peak.hpp"
#include "opencl/factored/program.hpp"
#include "host/interval_iteration.hpp"
#include "opencl/device.hpp"
#include "opencl/layout.hpp"
#include "opencl/program_cache.hpp"
#include "opencl/run.hpp"
#include "opencl/source.hpp"
#include "scale_out/team.hpp"

namespace amytiss::detail {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// The factored sweep runs where it does at most this share of the dense sweep's multiply-adds:
// its stage tensors cost memory traffic and index arithmetic that the dense records do not.
constexpr double kFactoredShareLimit = 0.5;

// What the OpenCL engine cannot run, found before any device work.
void check_supported(const Abstraction& a) {
  if (!a.noise->separable())
    throw ConfigError("noise.covariance",
                      "a full (non-diagonal) covariance is supported by device: reference only; "
                      "use a diagonal covariance (n values, example: covariance: [0.75, 0.75]) or "
                      "compute.device: reference");
  if (a.states.size() >= (std::size_t(1) << 32))
    throw ConfigError("states", "the OpenCL engine supports fewer than 2^32 state cells (got " +
                                    std::to_string(a.states.size()) + ")");
}

}  // namespace

// The dense sweep's padded value array is indexed with 32 bits.
void check_dense_supported(const Layout& layout) {
  if (layout.padded_size >= (std::size_t(1) << 32))
    throw ConfigError("states", "the dense sweep supports fewer than 2^32 padded value cells (got " +
                                    std::to_string(layout.padded_size) + "); narrow the noise window "
                                    "(noise.truncation) or use dynamics expressions, whose factored sweep "
                                    "has no padding");
}

// The factored plan when the decomposition asks for it or it saves enough work; a Sweep note
// says which sweep runs and why.
std::optional<FactoredPlan> choose_factored(const Abstraction& a, const DeviceInfo& device,
                                            const SynthesisOptions& options, SynthesisReport& rep) {
  const SweepChoice decomposition = options.compute.sweep;
  // The dense sweep computes normal and uniform masses on the device; the other laws' masses come
  // from the host's NoiseModel, which only the factored sweep's tables use.
  const bool host_masses = !a.noise->device_masses();
  const std::string law = to_string(a.noise->distribution());
  if (host_masses && decomposition == SweepChoice::Dense)
    throw ConfigError("compute.sweep", "got dense, but the dense sweep computes normal and uniform noise only; " + law +
                                           " noise runs on the factored sweep (compute.sweep: auto or factored, "
                                           "with dynamics expressions) or on compute.device: reference");
  if (decomposition == SweepChoice::Dense) {
    rep.notes.push_back({NoteSeverity::Info, NoteKind::Sweep, "dense sweep (requested)"});
    return std::nullopt;
  }
  std::string reason;
  const double budget = options.compute.memory_fraction * double(device.global_memory);
  std::optional<FactoredPlan> plan = plan_factored_sweep(a, budget, double(device.max_allocation), &reason);
  if (decomposition == SweepChoice::Factored) {
    if (!plan) throw DeviceError("the factored sweep was requested but cannot run: " + reason);
    rep.notes.push_back({NoteSeverity::Info, NoteKind::Sweep, plan->describe() + " (requested)"});
    return plan;
  }
  if (!plan && host_masses)
    throw ConfigError("noise.distribution", law + " noise needs the factored sweep on OpenCL devices (the dense sweep "
                                              "computes normal and uniform noise only), which cannot run: " + reason +
                                              "; use dynamics expressions or compute.device: reference");
  if (!plan) {
    rep.notes.push_back({NoteSeverity::Info, NoteKind::Sweep, "dense sweep: the factored sweep cannot run: " + reason});
    return std::nullopt;
  }
  if (host_masses) {
    rep.notes.push_back({NoteSeverity::Info, NoteKind::Sweep, plan->describe() + " (" + law + " noise: host masses)"});
    return plan;
  }
  if (plan->multiply_adds > kFactoredShareLimit * plan->dense_multiply_adds) {
    rep.notes.push_back({NoteSeverity::Info, NoteKind::Sweep,
                         "dense sweep: the factored sweep would save too little (" + plan->describe() + ")"});
    return std::nullopt;
  }
  rep.notes.push_back({NoteSeverity::Info, NoteKind::Sweep, plan->describe()});
  return plan;
}

// The values of every state cell from a padded value array.
void unpad(double* out, const std::vector<std::size_t>& padded_index, const double* padded) {
  for (std::size_t x = 0; x < padded_index.size(); ++x) out[x] = padded[padded_index[x]];
}

void unpad(Policy& policy, unsigned step, const std::vector<std::size_t>& padded_index, const double* padded) {
  unpad(policy.values.data() + std::size_t(step) * padded_index.size(), padded_index, padded);
}

Policy synthesize_opencl(const Abstraction& a, const SynthesisOptions& options, SynthesisReport* report,
                         const OpenClEngineOptions& engine_options) {
  const auto start = Clock::now();
  SynthesisReport local_report;
  SynthesisReport& rep = report ? *report : local_report;
  const Layout layout(a);
  check_supported(a);
  if (is_scale_out(options)) {
    if (a.unbounded)
      throw ConfigError("spec.horizon", "infinite (interval iteration) runs on one OpenCL device or on compute.device: "
                                        "reference; several devices (compute.devices) and MPI ranks compute bounded "
                                        "horizons only (example: horizon: 16)");
    return synthesize_team(a, options, rep, engine_options);
  }

  auto phase_start = Clock::now();
  const DeviceInfo device = choose_device(options.compute, rep.notes);
  rep.device = device.label();
  const DevicePeak peak = double_fma_peak(device.is_gpu(), device.is_cpu(), device.label(), device.compute_units,
                                          device.max_clock_mhz, device.native_double_width);
  rep.peak_multiply_adds_per_second = peak.multiply_adds_per_second;
  rep.peak_basis = peak.basis;
  DeviceSession session = open_session(device);
  rep.phases.push_back({"device setup", seconds_since(phase_start), 0, 0});

  auto report_progress = [&](Phase phase, unsigned done, double remaining) {
    if (options.progress && !options.progress({phase, done, a.horizon, device.label(), seconds_since(start), remaining}))
      throw Cancelled();
  };

  if (const auto factored = choose_factored(a, device, options, rep)) {
    rep.transitions = "factored: per-dimension mass tables (the transitions setting applies to the dense sweep)";
    FactoredRunContext run{&device,          session.context.get(),
                           session.queue.get(), engine_options.kernel_cache_dir,
                           engine_options.factored_entry_per_item, options.profile,
                           report_progress};
    Policy policy = run_factored_sweep(a, *factored, run, rep);
    rep.host_peak_bytes = peak_resident_bytes();
    return policy;
  }
  check_dense_supported(layout);
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
  // Each multiply-add loads a double of V; stored records are streamed once per step; each state
  // stores its value and input.
  const double record_bytes_per_step =
      plan.on_the_fly ? 0.0 : double(buffers.free_states) * double(plan.records_per_state) * double(layout.record_bytes());
  const double bytes_per_step = 8.0 * multiply_adds_per_step + record_bytes_per_step + 12.0 * double(a.states.size());
  int current = 0;
  // One Bellman step from values[current] (uploaded from host_in unless it is null: the previous
  // step's output is already there) into values[1 - current], unpadded into host_out.
  std::vector<double> padded_in(layout.padded_size, 0.0);
  auto bellman = [&](const double* host_in, double* host_out, std::uint32_t* chosen) {
    if (host_in) {
      for (std::size_t x = 0; x < buffers.padded_index.size(); ++x) padded_in[buffers.padded_index[x]] = host_in[x];
      check(clEnqueueWriteBuffer(session.queue.get(), buffers.values[current].get(), CL_TRUE, 0,
                                 padded_in.size() * sizeof(double), padded_in.data(), 0, nullptr, nullptr),
            "clEnqueueWriteBuffer");
    }
    sweep_step(session.queue.get(), sweep.get(), plan, buffers, current, chosen, step_values);
    current = 1 - current;
    unpad(host_out, buffers.padded_index, step_values.data());
  };
  if (a.unbounded) {
    // Masses stored as float: values differ from the double ones by up to about 1e-7.
    constexpr double kFloatMassResolution = 1e-6;
    FunctionStep step(bellman, multiply_adds_per_step, bytes_per_step, kFloatMassResolution);
    ReferenceStep host(a);
    UnboundedRun run{device.label(), [&](unsigned iterations, double) { report_progress(Phase::Synthesis, iterations, -1); }};
    Policy stationary = solve_unbounded(a, step, host, run, rep);
    rep.host_peak_bytes = peak_resident_bytes();
    return stationary;
  }
  const auto synthesis_start = Clock::now();
  for (unsigned step = a.horizon; step-- > 0;) {
    phase_start = Clock::now();
    bellman(nullptr, policy.values.data() + std::size_t(step) * a.states.size(),
            policy.input_index.data() + std::size_t(step) * a.states.size());
    const double seconds = seconds_since(phase_start);
    rep.phases.push_back({"step " + std::to_string(step), seconds, double(a.pairs()) / std::max(seconds, 1e-9),
                          multiply_adds_per_step, bytes_per_step});
    const unsigned done = a.horizon - step;
    const double remaining = seconds_since(synthesis_start) / done * (a.horizon - done);
    report_progress(done == a.horizon ? Phase::Done : Phase::Synthesis, done, remaining);
  }

  rep.host_peak_bytes = peak_resident_bytes();
  return policy;
}

}  // namespace amytiss::detail
