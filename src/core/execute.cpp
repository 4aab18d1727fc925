#include "execute.hpp"

#include "amytiss/errors.hpp"
#include "solve/backward_driver.hpp"
#include "serial/reference_engine.hpp"
#include "bounds/system_engine.hpp"
#include "opencl/engine.hpp"
#include "scale_out/team_dense.hpp"
#include "scale_out/team_factored.hpp"

namespace amytiss::detail {
namespace {

Policy run_team(const Abstraction& a, SynthesisPlan& plan, const SynthesisOptions& options,
                const OpenClEngineOptions& engine_options, StepReporter& reporter) {
  const auto start = SteadyClock::now();
  Team& team = *plan.team->team;
  reporter.set_device(team.label());
  // The devices were opened while planning; their set-up is the plan's.
  reporter.phase(PhaseKind::DeviceSetup, "device setup", seconds_since(start));
  if (!plan.factored) return run_dense_team(a, team, options.compute, engine_options, reporter);
  reporter.report().transitions = "factored: per-dimension mass tables on every device";
  return run_factored_team(a, *plan.factored, team, engine_options, reporter);
}

}  // namespace

Policy carry_out(const Abstraction& a, SynthesisPlan& plan, const SynthesisOptions& options,
                 const OpenClEngineOptions& engine_options, SynthesisReport& report) {
  report.notes.insert(report.notes.end(), plan.notes.begin(), plan.notes.end());
  if (plan.engine == EngineKind::Reference) return run_reference(a, options.progress, report);
  StepReporter reporter(a, options.progress, report);
  if (plan.engine == EngineKind::Bounds) return run_system_bounds(a, plan.bounds_method, plan.bounds_serial, reporter);
  if (plan.engine == EngineKind::Team) return run_team(a, plan, options, engine_options, reporter);
  return run_on_device(a, plan.device, plan.factored, options, engine_options, reporter);
}

Policy synthesize_opencl(const Abstraction& a, const SynthesisOptions& options, SynthesisReport* report,
                         const OpenClEngineOptions& engine_options) {
  SynthesisReport local_report;
  SynthesisPlan plan = plan_synthesis(a, options, EngineScope::OpenClOnly);
  return carry_out(a, plan, options, engine_options, report ? *report : local_report);
}

Policy synthesize_with_cpu_fallback(const SynthesisOptions& options, SynthesisReport* report,
                                    const EngineAttempt& attempt, const DeviceLabel& cpu_label) {
  SynthesisReport local_report;
  SynthesisReport& first_report = report ? *report : local_report;
  try {
    return attempt(options, &first_report);
  } catch (const DeviceError& failure) {
    // Several devices or ranks, or a device the request named, run as asked or fail together.
    if (!chosen_by_engine(options)) throw;
    ComputeConfig on_cpu = options.compute;
    on_cpu.device = DeviceKind::Cpu;
    const std::string fallback_device = cpu_label(on_cpu);
    // Running the device that just failed again would only fail again.
    if (fallback_device.empty() || fallback_device == first_report.device) throw;
    SynthesisReport retry_report;
    retry_report.notes = first_report.notes;
    retry_report.notes.push_back({NoteSeverity::Warning, NoteKind::DeviceFallback,
                                  (first_report.device.empty() ? std::string("the device") : first_report.device) +
                                      " failed (" + failure.what() + "); falling back to the CPU device " +
                                      fallback_device});
    SynthesisOptions retry_options = options;
    retry_options.compute = on_cpu;
    Policy policy = attempt(retry_options, &retry_report);
    first_report = std::move(retry_report);
    return policy;
  }
}

}  // namespace amytiss::detail
