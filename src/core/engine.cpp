// The public entry points of the engines: each plans (plan.hpp) and carries the plan out
// (execute.hpp), or reads the OpenCL layout and devices.
#include "amytiss/engine.hpp"

#include "amytiss/format.hpp"
#include "amytiss/run_id.hpp"
#include "bounds/memory_estimate.hpp"
#include "bounds/system_engine.hpp"
#include "execute.hpp"
#include "serial/reference_engine.hpp"
#include "opencl/device.hpp"
#include "opencl/layout.hpp"
#include "plan.hpp"

namespace amytiss {

Policy synthesize(const Abstraction& abstraction, const SynthesisOptions& options, SynthesisReport* report) {
  auto attempt = [&abstraction](const SynthesisOptions& attempt_options, SynthesisReport* attempt_report) {
    detail::SynthesisPlan plan = detail::plan_synthesis(abstraction, attempt_options);
    return detail::carry_out(abstraction, plan, attempt_options, {}, *attempt_report);
  };
  Policy policy = detail::synthesize_with_cpu_fallback(options, report, attempt, detail::selected_device_label);
  policy.run_id = new_run_id();
  return policy;
}

std::vector<std::string> describe_synthesis(const Abstraction& abstraction, const SynthesisOptions& options) {
  detail::SynthesisPlan plan = detail::plan_synthesis(abstraction, options);
  return detail::describe_plan(abstraction, plan, options);
}

MemoryEstimate estimate_memory(const Abstraction& abstraction) { return estimate_memory(abstraction, abstraction.config.compute); }

MemoryEstimate estimate_memory(const Abstraction& abstraction, const ComputeConfig& compute) {
  const double cells = double(abstraction.states.size());
  const double horizon = double(abstraction.horizon);
  MemoryEstimate estimate;
  estimate.policy_bytes = (horizon + 1) * cells * sizeof(double) + horizon * cells * sizeof(std::uint32_t) +
                          cells * sizeof(std::uint8_t);
  // Upper bounds: one per cell for a stationary policy, one per value under guarantee: system.
  const bool system = abstraction.config.guarantee == Guarantee::System;
  if (abstraction.unbounded)
    estimate.policy_bytes += cells * sizeof(double);
  else if (system)
    estimate.policy_bytes += (horizon + 1) * cells * sizeof(double);
  estimate.host_bytes = estimate.policy_bytes;
  if (system) {  // the bounds store no transitions, only per-dimension intervals
    const unsigned threads = detail::bounds_threads(compute.device == DeviceKind::Reference);
    const detail::BoundsMemory bounds = detail::estimate_bounds_memory(abstraction, compute.bounds_method, threads);
    estimate.bounds_bytes = bounds.peak();
    estimate.bounds_method = bounds.method;
    estimate.host_bytes += estimate.bounds_bytes;
    return estimate;
  }
  estimate.bytes_per_triple = double(detail::Layout(abstraction).record_bytes());
  estimate.stored_transition_bytes = estimate.bytes_per_triple * double(abstraction.triples());
  return estimate;
}

Policy synthesize_reference(const Abstraction& abstraction, const ProgressCallback& progress,
                            SynthesisReport* report) {
  SynthesisReport local_report;
  SynthesisReport& rep = report ? *report : local_report;
  rep.phases.clear();
  if (abstraction.config.guarantee == Guarantee::System) {
    SynthesisOptions options;
    options.compute.device = DeviceKind::Reference;
    options.compute.bounds_method = BoundsMethod::Joint;
    options.progress = progress;
    detail::SynthesisPlan plan = detail::plan_synthesis(abstraction, options);
    return detail::carry_out(abstraction, plan, options, {}, rep);
  }
  return detail::run_reference(abstraction, progress, rep);
}

std::vector<std::string> list_opencl_devices() {
  std::vector<std::string> lines;
  for (const auto& info : detail::enumerate_devices()) {
    lines.push_back("[" + std::to_string(info.platform_index) + "." + std::to_string(info.device_index) + "] " +
                    info.label() + " (" + info.type_name() + ", " + format_bytes(double(info.global_memory)) + ", " +
                    std::to_string(info.compute_units) + " compute units" +
                    (info.fp64 ? "" : ", no double precision: unusable") + ")");
  }
  return lines;
}

}  // namespace amytiss
