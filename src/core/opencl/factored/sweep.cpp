// The factored sweep's run on one OpenCL device: mass tables (construction), then per time step
// and slice one launch per elimination stage, and the input choice from Q.
#include "opencl/factored/sweep.hpp"

#include <string>
#include <vector>

#include "amytiss/format.hpp"
#include "opencl/factored/device_parts.hpp"
#include "opencl/factored/fused_stage.hpp"
#include "opencl/factored/tables.hpp"
#include "serial/point_iteration.hpp"

namespace amytiss::detail {
namespace {

// One time step on the device: every slice's stages from values[current], the input choice into
// values[1 - current], both read back. With profile, each kernel's time is kept per stage.
class FactoredStep : public BellmanStep {
 public:
  FactoredStep(const Abstraction& a, const FactoredPlan& plan, const FactoredRunContext& run,
               FactoredKernels& kernels, FactoredBuffers& buffers, const std::vector<MassTable>& tables)
      : a_(a), plan_(plan), run_(run), kernels_(kernels), buffers_(buffers),
        group_(factored_group_size(*run.device)), seconds_(plan.stages.size() + 1, 0.0),
        multiply_adds_(plan.stages.size() + 1, 0.0), bytes_(plan.stages.size() + 1, 0.0),
        memory_bytes_(plan.stages.size() + 1, 0.0) {
    // Operand bytes: the values the kernels load (doubles), an entry stored per output; the input
    // choice loads Q and stores a value and an input per state, all of it memory traffic.
    for (std::size_t k = 0; k < plan.stages.size(); ++k) {
      const StageWork work = stage_work(a, plan, k, tables[plan.stages[k].dimension], kernels.shape);
      multiply_adds_[k] = work.multiply_adds;
      bytes_[k] = 8.0 * (work.value_loads + double(plan.stages[k].output_entries) * double(plan.slices));
      memory_bytes_[k] = work.memory_bytes;
      fused_.push_back(fuses_next(plan, k, kernels.shape));
    }
    // A fused pair is one launch (one slice): the work of both, the loads of both (the second's
    // from the first's lines of rows), the second's stores; in memory the first's input and Q.
    for (std::size_t k = 0; k + 1 < plan.stages.size(); ++k) {
      if (!fused_[k]) continue;
      multiply_adds_[k] += multiply_adds_[k + 1];
      bytes_[k] += bytes_[k + 1] - 8.0 * double(plan.stages[k].output_entries);
      memory_bytes_[k] += 8.0 * (double(plan.stages[k + 1].output_size) - double(plan.stages[k].output_size));
      multiply_adds_[k + 1] = bytes_[k + 1] = memory_bytes_[k + 1] = 0;
    }
    bytes_.back() = memory_bytes_.back() = 8.0 * double(plan.q_size) + 12.0 * double(a.states.size());
  }

  void apply(const double* in, double* out, std::uint32_t* chosen) override {
    check(clEnqueueWriteBuffer(run_.queue, buffers_.values[current_].get(), CL_FALSE, 0,
                               a_.states.size() * sizeof(double), in, 0, nullptr, nullptr),
          "clEnqueueWriteBuffer");
    apply_resident(in, out, chosen);
  }
  void apply_resident(const double*, double* out, std::uint32_t* chosen) override;
  double multiply_adds() const override { return sum(multiply_adds_); }
  double bytes() const override { return sum(bytes_); }
  double memory_bytes() const override { return sum(memory_bytes_); }

  // The profile's breakdown: every stage's and the input choice's time over `steps` steps.
  void report_breakdown(StepReporter& reporter, unsigned steps) const {
    for (std::size_t k = 0; k <= plan_.stages.size(); ++k) {
      if (k > 0 && k < plan_.stages.size() && fused_[k - 1]) continue;  // in the line of stage k - 1
      std::string name = "input choice (all steps)";
      if (k < plan_.stages.size() && fused_[k])
        name = "stages " + std::to_string(k) + "+" + std::to_string(k + 1) + " (x'" +
               std::to_string(plan_.stages[k].dimension) + " + x'" + std::to_string(plan_.stages[k + 1].dimension) +
               " fused, all steps)";
      else if (k < plan_.stages.size())
        name = "stage " + std::to_string(k) + " (x'" + std::to_string(plan_.stages[k].dimension) + ", all steps)";
      reporter.phase(PhaseKind::Breakdown, name, seconds_[k], 0, multiply_adds_[k] * steps, bytes_[k] * steps,
                     memory_bytes_[k] * steps);
    }
  }

 private:
  static double sum(const std::vector<double>& values) {
    double total = 0;
    for (double value : values) total += value;
    return total;
  }
  void launch(cl_kernel kernel, std::size_t entries, std::size_t timing_slot) {
    const auto start = SteadyClock::now();
    launch_range(run_.queue, kernel, 0, entries, group_);
    if (run_.profile) {
      check(clFinish(run_.queue), "clFinish(factored sweep)");
      seconds_[timing_slot] += seconds_since(start);
    }
  }

  const Abstraction& a_;
  const FactoredPlan& plan_;
  const FactoredRunContext& run_;
  FactoredKernels& kernels_;
  FactoredBuffers& buffers_;
  std::size_t group_;
  std::vector<double> seconds_, multiply_adds_, bytes_, memory_bytes_;
  std::vector<bool> fused_;  ///< per stage: its kernel also computes the next (fused_stage.hpp)
  int current_ = 0;
};

void FactoredStep::apply_resident(const double*, double* out, std::uint32_t* chosen) {
  const std::size_t n_states = a_.states.size(), last_stage = plan_.stages.size() - 1;
  for (std::size_t slice = 0; slice < plan_.slices; ++slice) {
    for (std::size_t k = 0; k < plan_.stages.size(); ++k) {
      if (k > 0 && fused_[k - 1]) continue;  // computed by stage k - 1's kernel
      const FactoredStage& stage = plan_.stages[k];
      cl_mem in = k == 0 ? buffers_.values[current_].get() : buffers_.stage_tensors[(k - 1) % 2].get();
      cl_mem stage_out = k == last_stage || fused_[k] ? buffers_.q.get() : buffers_.stage_tensors[k % 2].get();
      // The first stage reads the slice out of V; the last contracts the slice's cells only.
      cl_kernel kernel = kernels_.stages[k].get();
      set_stage_arguments(kernel, in, stage_out, buffers_.tables[stage.dimension],
                          stage_placement(a_, plan_, k, slice));
      if (fused_[k]) set_fused_arguments(kernel, buffers_.tables[plan_.stages[k + 1].dimension]);
      launch(kernel, stage_work_items(stage, kernels_.shape), k);
    }
  }
  set_choose_arguments(kernels_.choose.get(), buffers_, 1 - current_);
  launch(kernels_.choose.get(), choose_work_items(a_, kernels_.shape), plan_.stages.size());
  check(clEnqueueReadBuffer(run_.queue, buffers_.best_input.get(), CL_FALSE, 0, n_states * sizeof(cl_uint), chosen, 0,
                            nullptr, nullptr),
        "clEnqueueReadBuffer");
  check(clEnqueueReadBuffer(run_.queue, buffers_.values[1 - current_].get(), CL_FALSE, 0, n_states * sizeof(double),
                            out, 0, nullptr, nullptr),
        "clEnqueueReadBuffer");
  check(clFinish(run_.queue), "clFinish(factored sweep)");
  current_ = 1 - current_;
}

}  // namespace

Policy run_factored_sweep(const Abstraction& a, const FactoredPlan& plan, const FactoredRunContext& run,
                          StepReporter& reporter) {
  SynthesisReport& report = reporter.report();
  auto phase_start = SteadyClock::now();
  FactoredKernels kernels = build_factored_kernels(a, plan, *run.device, run.context, run.kernel_cache_dir,
                                                   run.shape, report.notes);
  reporter.phase(PhaseKind::KernelBuild, "kernel build", seconds_since(phase_start));
  reporter.reached(Phase::Setup);

  // Construction: the kept masses of every dimension, once.
  phase_start = SteadyClock::now();
  const std::vector<MassTable> tables = factored_mass_tables(a, plan);
  FactoredBuffers buffers =
      allocate_factored_buffers(a, plan, tables, run.context, run.device->is_cpu(), kernels.shape);
  report.device_bytes = buffers.device_bytes;
  report.notes.push_back(
      {NoteSeverity::Info, NoteKind::DeviceMemory, "device memory: " + format_bytes(double(buffers.device_bytes))});
  const double construction_seconds = seconds_since(phase_start);
  reporter.phase(PhaseKind::Construction, "construction", construction_seconds,
                 double(a.pairs()) / std::max(construction_seconds, 1e-9));
  reporter.reached(Phase::Construction);

  FactoredStep step(a, plan, run, kernels, buffers, tables);
  Policy policy = run_abstraction_backward(a, step, reporter);
  if (run.profile && !a.unbounded) step.report_breakdown(reporter, a.horizon);
  return policy;
}

}  // namespace amytiss::detail
