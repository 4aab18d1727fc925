// synthesize(): dispatch to the reference or the OpenCL engine, with the CPU fallback of
// docs/engine.md (a failing device is retried once on the CPU device).
#include "amytiss/engine.hpp"

#include "amytiss/errors.hpp"
#include "opencl/engine.hpp"

namespace amytiss {

namespace detail {

Policy synthesize_with_cpu_fallback(const SynthesisOptions& options, SynthesisReport* report,
                                    const EngineAttempt& attempt, const DeviceLabel& cpu_label) {
  SynthesisReport local_report;
  SynthesisReport& first_report = report ? *report : local_report;
  try {
    return attempt(options, &first_report);
  } catch (const DeviceError& failure) {
    // Only `auto` without a platform or device selection may run elsewhere than asked.
    // Several devices or ranks run as asked or fail together.
    const bool chosen_by_engine = options.compute.device == DeviceKind::Auto && options.compute.platform.empty() &&
                                  options.compute.device_name.empty() && options.compute.devices.empty() &&
                                  !(options.communicator && options.communicator->size() > 1);
    if (!chosen_by_engine) throw;
    ComputeConfig on_cpu = options.compute;
    on_cpu.device = DeviceKind::Cpu;
    on_cpu.platform.clear();
    on_cpu.device_name.clear();
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

}  // namespace detail

namespace {

Policy synthesize_on_device(const Abstraction& abstraction, const SynthesisOptions& options,
                            SynthesisReport* report) {
  if (options.compute.device == DeviceKind::Reference) {
    if (report) report->notes.push_back({NoteSeverity::Info, NoteKind::DeviceChoice, "device: reference (serial, double precision)"});
    return synthesize_reference(abstraction, options.progress, report);
  }
  return detail::synthesize_with_cpu_fallback(
      options, report,
      [&abstraction](const SynthesisOptions& attempt_options, SynthesisReport* attempt_report) {
        return detail::synthesize_opencl(abstraction, attempt_options, attempt_report);
      },
      detail::selected_device_label);
}

}  // namespace

Policy synthesize(const Abstraction& abstraction, const SynthesisOptions& options,
                  SynthesisReport* report) {
  Policy policy = synthesize_on_device(abstraction, options, report);
  policy.run_id = new_run_id();
  return policy;
}

}  // namespace amytiss
