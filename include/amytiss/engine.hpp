#pragma once
// Synthesis engines: the serial reference (Algorithms 1 + 3 of the paper, double precision) and
// the OpenCL engine (Algorithms 2 + 4 and on-the-fly, any OpenCL device). One entry point.
#include <functional>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"

namespace amytiss {

/// Progress of a running synthesis, reported after set-up, after construction and after each
/// time step.
struct Progress {
  std::string phase;          ///< "setup", "construction", "synthesis", "done"
  unsigned steps_done = 0;    ///< time steps of the backward recursion finished
  unsigned steps_total = 0;   ///< the horizon
  std::string device;         ///< device name, or "reference"
  double elapsed_s = 0;       ///< since synthesize() started
  double remaining_s = -1;    ///< estimate, < 0 when unknown
  double percent() const { return steps_total ? 100.0 * steps_done / steps_total : 0.0; }
};
/// Return false to cancel (synthesize() then throws Cancelled).
using ProgressCallback = std::function<bool(const Progress&)>;

/// Timing and memory of one phase (for --profile and BENCHMARKS.md).
struct PhaseReport {
  std::string name;            ///< "device setup", "kernel build", "construction", "step 15", ...
  double seconds = 0;
  double pairs_per_second = 0; ///< state-input pairs processed per second (0 if not applicable)
  double multiply_adds = 0;    ///< multiply-adds done in the phase (0 if not counted)
};
struct SynthesisReport {
  std::string device;                 ///< "reference" or "<platform> / <device>"
  std::string transitions;            ///< "stored" or "on_the_fly", with the reason
  std::vector<PhaseReport> phases;
  std::size_t device_bytes = 0;       ///< peak device memory allocated by the engine
  std::size_t host_peak_bytes = 0;    ///< peak resident set of the process (VmHWM)
  std::vector<std::string> log;       ///< notes: device fallback reason, chunking, ...
};

struct SynthesisOptions {
  ComputeConfig compute;              ///< device, transitions, selection, memory fraction
  ProgressCallback progress;          ///< may be empty
  bool profile = false;               ///< finish each kernel before timing (slower, exact phases)
};

/// Runs the engine named by options.compute.device. `auto` prefers a GPU, else the CPU OpenCL
/// device, else throws DeviceError; `cpu`/`gpu` that are missing fall back to the CPU device with a
/// note in report->log (SPEC section 7). Throws Cancelled, DeviceError, ConfigError.
Policy synthesize(const Abstraction& abstraction, const SynthesisOptions& options,
                  SynthesisReport* report = nullptr);

/// The serial reference engine directly.
Policy synthesize_reference(const Abstraction& abstraction, const ProgressCallback& progress,
                            SynthesisReport* report = nullptr);

/// OpenCL devices visible through the ICD loader, one line each: "[p.d] platform / device (type,
/// global memory MiB, compute units)". Empty when none.
std::vector<std::string> list_opencl_devices();

/// Peak resident set size of this process in bytes (VmHWM), 0 if unknown.
std::size_t peak_resident_bytes();

}  // namespace amytiss
