#pragma once
// What a synthesis run takes and gives besides the policy: its options, its progress while it
// runs, and its report (phases with their times, notes about the choices made).
#include <algorithm>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/scale_out.hpp"

namespace amytiss {

/// Phases of a synthesis, in order; names (to_string) as published in PolicyStatus.phase and the
/// Synthesize action's feedback: "setup", "construction", "synthesis", "done".
enum class Phase { Setup, Construction, Synthesis, Done };
std::string to_string(Phase phase);

/// Progress of a running synthesis, reported after set-up, after construction and after each
/// time step (the last one with Phase::Done) or interval iteration.
struct Progress {
  Phase phase = Phase::Setup;
  unsigned steps_done = 0;    ///< time steps (unbounded: interval iterations) finished
  unsigned steps_total = 0;   ///< the horizon; 0 when unknown (unbounded specifications)
  std::string device;         ///< device name, or "reference"
  double elapsed_s = 0;       ///< seconds since synthesize() started
  double remaining_s = -1;    ///< estimate in seconds, < 0 when unknown
  /// With `refine` (docs/refinement.md): the round running (1-based) and the most rounds; 0 and 0
  /// for a synthesis on one grid. steps_done, elapsed_s and remaining_s are the round's.
  unsigned round = 0;
  unsigned max_rounds = 0;
  /// Share of the steps done, in percent (0 when the total is unknown; never above 100).
  double percent() const { return steps_total ? 100.0 * std::min(steps_done, steps_total) / steps_total : 0.0; }
};
/// Return false to cancel (synthesize() then throws Cancelled).
using ProgressCallback = std::function<bool(const Progress&)>;

/// What a phase report measures.
enum class PhaseKind {
  DeviceSetup,   ///< devices found, contexts and queues made
  KernelBuild,   ///< OpenCL programs built or loaded from the binary cache
  Construction,  ///< transitions (or mass tables) computed before the time steps
  Step,          ///< one time step of the backward recursion
  Breakdown,     ///< a share of the steps' time (one kernel, the exchanges): already in the steps
  Other          ///< a phase of its own (unbounded: graph analysis, interval iteration, certification)
};

/// Timing and memory of one phase (for --profile and BENCHMARKS.md).
struct PhaseReport {
  std::string name;            ///< for people: "device setup", "kernel build", "step 15", ...
  double seconds = 0;
  double pairs_per_second = 0; ///< state-input pairs processed per second (0 if not applicable)
  double multiply_adds = 0;    ///< multiply-adds done in the phase (0 if not counted)
  /// Operand bytes of the phase's kernels: values and records they load, entries they store (an
  /// upper bound of the memory traffic: caches serve much of it). 0 if not counted.
  double bytes = 0;
  /// Memory bytes the phase cannot avoid: its input and output tensors read and written once
  /// (factored stages). 0 if not counted: the roofline then takes the operand bytes.
  double memory_bytes = 0;
  PhaseKind kind = PhaseKind::Other;
  /// Set up (device setup, kernel build): not part of the compute time.
  bool is_setup() const { return kind == PhaseKind::DeviceSetup || kind == PhaseKind::KernelBuild; }
  /// A breakdown of the steps' time (with profile): already counted in the steps.
  bool is_breakdown() const { return kind == PhaseKind::Breakdown; }
};

/// How much an engine note matters: Info is a fact about the run (storage chosen, memory used);
/// Warning says the run differs from what was asked (another device, on-the-fly storage).
enum class NoteSeverity { Info, Warning };
/// What an engine note is about.
enum class NoteKind {
  DeviceChoice,    ///< which engine and device were chosen, or skipped and why
  DeviceFallback,  ///< a device other than the one asked for runs the synthesis
  Transitions,     ///< transition storage (stored or on the fly) and why
  Sweep,           ///< work decomposition of the synthesis sweep
  Chunking,        ///< states split into chunks (allocation limits)
  DeviceMemory,    ///< device memory allocated
  KernelBuild,     ///< program built from source or loaded from the binary cache
  Convergence,     ///< unbounded specifications: end components, iterations, the gap reached
  Refinement       ///< refine: each round's cells, gap and time, and why the rounds ended
};
std::string to_string(NoteSeverity severity);
std::string to_string(NoteKind kind);
struct EngineNote {
  NoteSeverity severity = NoteSeverity::Info;
  NoteKind kind = NoteKind::DeviceChoice;
  std::string text;  ///< a sentence for people, without a severity prefix
};

struct SynthesisReport {
  std::string device;                 ///< "reference" or "<platform> / <device>"
  std::string transitions;            ///< "stored" or "on_the_fly", with the reason
  std::vector<PhaseReport> phases;
  std::size_t device_bytes = 0;       ///< peak device memory allocated by the engine
  /// The device's double-precision multiply-add peak (0: unknown) and how it was derived.
  double peak_multiply_adds_per_second = 0;
  std::string peak_basis;
  /// With profile on an OpenCL device: its copy bandwidth in bytes (read + written) per second,
  /// measured by a copy kernel in the device setup (or cached from an earlier run), and how.
  /// 0 otherwise.
  double measured_bandwidth_bytes_per_second = 0;
  std::string bandwidth_basis;
  /// With profile on an OpenCL device: bytes read per second from a buffer in cache (a core's
  /// L2 on a CPU), and how. 0 otherwise.
  double measured_cache_bytes_per_second = 0;
  std::string cache_basis;
  std::size_t host_peak_bytes = 0;    ///< peak resident set of the process (VmHWM)
  std::vector<EngineNote> notes;      ///< engine and device choice, fallback, storage, chunking, ...
  /// Several devices or ranks (docs/scale_out.md): seconds spent exchanging the parts between
  /// them (device read-backs, MPI, writes back), and the bytes one time step exchanges (every
  /// part of every exchanged array once). 0 for one device.
  double exchange_seconds = 0;
  double exchange_bytes_per_step = 0;
};

struct SynthesisOptions {
  ComputeConfig compute;              ///< device, transitions, selection, memory fraction
  ProgressCallback progress;          ///< may be empty
  bool profile = false;               ///< finish each kernel before timing (slower, exact phases)
  /// The ranks of an MPI run (docs/scale_out.md); null: this process alone. With several ranks
  /// or compute.devices, the OpenCL engine splits the work and every rank returns the whole policy.
  Communicator* communicator = nullptr;
  /// The host memory the run may take, in bytes; 0: what available_memory() finds (the least of
  /// MemAvailable, the cgroup's limit and RLIMIT_AS). The plan refuses a run whose estimate
  /// (estimate_memory()) exceeds it, before anything is allocated.
  double memory_limit_bytes = 0;
};

}  // namespace amytiss
