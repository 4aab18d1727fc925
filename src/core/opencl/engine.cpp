// The OpenCL engine on one device: a short sequence of named steps over the parts in
// opencl/device, source, program_cache and run; the algorithm lives in kernels/engine.cl.
#include "opencl/engine.hpp"

#include <string>
#include <vector>

#include "opencl/device_bandwidth.hpp"
#include "opencl/device_peak.hpp"
#include "opencl/factored/device_parts.hpp"
#include "opencl/factored/sweep.hpp"
#include "opencl/layout.hpp"
#include "opencl/program_cache.hpp"
#include "opencl/run.hpp"
#include "opencl/source.hpp"
#include "serial/point_iteration.hpp"

namespace amytiss::detail {
namespace {

// Masses stored as float: values differ from the double ones by up to about 1e-7.
constexpr double kFloatMassResolution = 1e-6;

// The dense sweep's time step: the sweep kernel over every chunk from values[current] into
// values[1 - current], read back and unpadded.
class DenseStep : public BellmanStep {
 public:
  DenseStep(const Abstraction& a, const Layout& layout, const RunPlan& plan, RunBuffers& buffers,
            cl_command_queue queue, cl_kernel sweep)
      : plan_(plan), buffers_(buffers), queue_(queue), sweep_(sweep), padded_in_(layout.padded_size, 0.0),
        padded_out_(layout.padded_size) {
    multiply_adds_ = double(buffers.free_states) * double(plan.records_per_state) * contraction_multiply_adds(a);
    // Each multiply-add loads a double of V; stored records are streamed once per step; each
    // state stores its value and input.
    const double record_bytes = plan.on_the_fly ? 0.0
                                                : double(buffers.free_states) * double(plan.records_per_state) *
                                                      double(layout.record_bytes());
    bytes_ = 8.0 * multiply_adds_ + record_bytes + 12.0 * double(a.states.size());
  }
  void apply(const double* in, double* out, std::uint32_t* chosen) override {
    for (std::size_t x = 0; x < buffers_.padded_index.size(); ++x) padded_in_[buffers_.padded_index[x]] = in[x];
    check(clEnqueueWriteBuffer(queue_, buffers_.values[current_].get(), CL_TRUE, 0, padded_in_.size() * sizeof(double),
                               padded_in_.data(), 0, nullptr, nullptr),
          "clEnqueueWriteBuffer");
    apply_resident(in, out, chosen);
  }
  void apply_resident(const double*, double* out, std::uint32_t* chosen) override {
    sweep_step(queue_, sweep_, plan_, buffers_, current_, chosen, padded_out_);
    current_ = 1 - current_;
    unpad(out, buffers_.padded_index, padded_out_.data());
  }
  double multiply_adds() const override { return multiply_adds_; }
  double bytes() const override { return bytes_; }
  double resolution() const override { return kFloatMassResolution; }

 private:
  const RunPlan& plan_;
  RunBuffers& buffers_;
  cl_command_queue queue_;
  cl_kernel sweep_;
  std::vector<double> padded_in_, padded_out_;
  int current_ = 0;
  double multiply_adds_ = 0, bytes_ = 0;
};

Policy run_dense(const Abstraction& a, const DeviceInfo& device, DeviceSession& session,
                 const SynthesisOptions& options, const OpenClEngineOptions& engine_options, StepReporter& reporter) {
  SynthesisReport& rep = reporter.report();
  const Layout layout(a);
  const RunPlan plan = plan_run(a, layout, device, options.compute, engine_options, rep);

  auto phase_start = SteadyClock::now();
  const Program program = build_program(session.context.get(), device,
                                        opencl_program_source(a, plan.on_the_fly, plan.group_size),
                                        engine_options.kernel_cache_dir, rep.notes);
  const Kernel construct = create_kernel(program.get(), "construct");
  const Kernel sweep = create_kernel(
      program.get(), plan.variant == SweepVariant::GroupPerState ? "synthesize_group" : "synthesize_item");
  reporter.phase(PhaseKind::KernelBuild, "kernel build", seconds_since(phase_start));
  reporter.reached(Phase::Setup);

  RunBuffers buffers = allocate_buffers(a, layout, plan, session.context.get(), rep);
  // Construction (Algorithm 2 of the paper); on the fly, the sweep computes records as it goes.
  phase_start = SteadyClock::now();
  if (!plan.on_the_fly) construct_transitions(session.queue.get(), construct.get(), plan, buffers);
  const double construction_seconds = seconds_since(phase_start);
  reporter.phase(PhaseKind::Construction, "construction", construction_seconds,
                 plan.on_the_fly ? 0.0 : double(a.pairs()) / std::max(construction_seconds, 1e-9));
  reporter.reached(Phase::Construction);

  // Synthesis (Algorithm 4), V_{T_d} -> V_0, one padded step at a time back to the host.
  DenseStep step(a, layout, plan, buffers, session.queue.get(), sweep.get());
  return run_abstraction_backward(a, step, reporter);
}

}  // namespace

Policy run_on_device(const Abstraction& a, const DeviceInfo& device, const std::optional<FactoredPlan>& factored,
                     const SynthesisOptions& options, const OpenClEngineOptions& engine_options,
                     StepReporter& reporter) {
  SynthesisReport& rep = reporter.report();
  const auto phase_start = SteadyClock::now();
  reporter.set_device(device.label());
  const DevicePeak peak = double_fma_peak(device.is_gpu(), device.is_cpu(), device.label(), device.compute_units,
                                          device.max_clock_mhz, device.native_double_width);
  rep.peak_multiply_adds_per_second = peak.multiply_adds_per_second;
  rep.peak_basis = peak.basis;
  DeviceSession session = open_session(device);
  if (options.profile) {  // the roofline's bandwidth; its cost stays out of unprofiled runs
    const DeviceBandwidth bandwidth = measured_copy_bandwidth(device, session, engine_options.kernel_cache_dir);
    rep.measured_bandwidth_bytes_per_second = bandwidth.bytes_per_second;
    rep.bandwidth_basis = bandwidth.basis;
    rep.measured_cache_bytes_per_second = bandwidth.cache_bytes_per_second;
    rep.cache_basis = bandwidth.cache_basis;
  }
  reporter.phase(PhaseKind::DeviceSetup, "device setup", seconds_since(phase_start));
  if (!factored) return run_dense(a, device, session, options, engine_options, reporter);
  rep.transitions = "factored: per-dimension mass tables (the transitions setting applies to the dense sweep)";
  const FactoredRunContext run{&device, session.context.get(), session.queue.get(), engine_options.kernel_cache_dir,
                               factored_stage_shape(device, engine_options), options.profile};
  return run_factored_sweep(a, *factored, run, reporter);
}

}  // namespace amytiss::detail
