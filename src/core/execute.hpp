#pragma once
// Carrying out a synthesis plan (plan.hpp), and the retry of a failing device on the CPU device.
#include <functional>
#include <string>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/synthesis_types.hpp"
#include "opencl/engine_options.hpp"
#include "plan.hpp"

namespace amytiss::detail {

/// Runs the planned engine; report gets the plan's notes first, then the run's phases and notes.
Policy carry_out(const Abstraction& abstraction, SynthesisPlan& plan, const SynthesisOptions& options,
                 const OpenClEngineOptions& engine_options, SynthesisReport& report);

/// Plans with the OpenCL engines only (one device or a team, as the options say) and carries the
/// plan out: the OpenCL engine whatever the problem's size (tests, benchmarks).
Policy synthesize_opencl(const Abstraction& abstraction, const SynthesisOptions& options, SynthesisReport* report,
                         const OpenClEngineOptions& engine_options = {});

/// One attempt of an engine run, and the label of the CPU device a fallback would use.
using EngineAttempt = std::function<Policy(const SynthesisOptions&, SynthesisReport*)>;
using DeviceLabel = std::function<std::string(const ComputeConfig&)>;
/// A device that fails (DeviceError) is retried once on the CPU device, with a Warning
/// DeviceFallback note in report->notes, when the engine chose it (chosen_by_engine) and it is
/// not that CPU device (the first attempt's notes are kept). synthesize() calls it with
/// plan_synthesis + carry_out; tests call it with failing attempts.
Policy synthesize_with_cpu_fallback(const SynthesisOptions& options, SynthesisReport* report,
                                    const EngineAttempt& attempt, const DeviceLabel& cpu_label);

}  // namespace amytiss::detail
