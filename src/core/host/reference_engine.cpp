// The serial reference engine: the paper's Algorithms 1 + 3 written plainly, in double precision.
// It is the oracle the OpenCL engine is tested against, so clarity wins over speed here.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "host/bellman_step.hpp"
#include "host/interval_iteration.hpp"

namespace amytiss {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

Policy synthesize_reference(const Abstraction& abstraction, const ProgressCallback& progress,
                            SynthesisReport* report) {
  const auto start = Clock::now();
  const Grid& states = abstraction.states;
  const std::size_t state_count = states.size();
  const unsigned horizon = abstraction.horizon;

  Policy policy;
  policy.states = states;
  policy.inputs = abstraction.inputs;
  policy.horizon = horizon;
  policy.roles = abstraction.roles;
  policy.computed_by = "reference";
  policy.config_hash = config_hash(abstraction.config);
  policy.values.assign(std::size_t(horizon + 1) * state_count, 0.0);
  policy.input_index.assign(std::size_t(horizon) * state_count, 0);

  for (std::size_t cell = 0; cell < state_count; ++cell)
    policy.values[std::size_t(horizon) * state_count + cell] = abstraction.terminal_value(abstraction.roles[cell]);

  if (report) {
    report->device = "reference";
    report->transitions = "on_the_fly (the reference engine computes each transition when it needs it)";
    report->phases.clear();
  }
  if (progress) {
    Progress setup{Phase::Setup, 0, horizon, "reference", seconds_since(start), -1};
    if (!progress(setup)) throw Cancelled();
  }

  detail::ReferenceStep bellman(abstraction);
  if (abstraction.unbounded) {
    SynthesisReport local_report;
    SynthesisReport& rep = report ? *report : local_report;
    detail::UnboundedRun run{"reference", [&](unsigned iterations, double gap) {
                               if (progress && !progress({Phase::Synthesis, iterations, 0, "reference",
                                                          seconds_since(start), -1}))
                                 throw Cancelled();
                               (void)gap;
                             }};
    Policy stationary = detail::solve_unbounded(abstraction, bellman, bellman, run, rep);
    rep.host_peak_bytes = peak_resident_bytes();
    return stationary;
  }
  for (unsigned step = horizon; step-- > 0;) {
    const auto step_start = Clock::now();
    bellman.apply(&policy.values[std::size_t(step + 1) * state_count], &policy.values[std::size_t(step) * state_count],
                  &policy.input_index[std::size_t(step) * state_count]);
    const double multiply_adds = bellman.multiply_adds();

    const double step_seconds = seconds_since(step_start);
    if (report) {
      PhaseReport phase;
      phase.name = "step " + std::to_string(step);
      phase.seconds = step_seconds;
      phase.pairs_per_second = step_seconds > 0 ? double(abstraction.pairs()) / step_seconds : 0.0;
      phase.multiply_adds = multiply_adds;
      report->phases.push_back(phase);
    }
    if (progress) {
      const unsigned done = horizon - step;
      const double elapsed = seconds_since(start);
      Progress update{Phase::Synthesis, done, horizon, "reference", elapsed,
                      elapsed / double(done) * double(horizon - done)};
      if (!progress(update)) throw Cancelled();
    }
  }

  if (report) report->host_peak_bytes = peak_resident_bytes();
  return policy;
}

std::size_t peak_resident_bytes() {
  std::FILE* status = std::fopen("/proc/self/status", "r");
  if (!status) return 0;
  char line[256];
  std::size_t bytes = 0;
  while (std::fgets(line, sizeof line, status)) {
    unsigned long long kilobytes = 0;
    if (std::sscanf(line, "VmHWM: %llu kB", &kilobytes) == 1) {
      bytes = std::size_t(kilobytes) * 1024;
      break;
    }
  }
  std::fclose(status);
  return bytes;
}

}  // namespace amytiss
