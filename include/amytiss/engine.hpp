#pragma once
// Synthesis engines: the serial reference (Algorithms 1 + 3 of the paper, double precision) and
// the OpenCL engine (Algorithms 2 + 4 and on-the-fly, any OpenCL device). One entry point.
#include <functional>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/scale_out.hpp"

namespace amytiss {

/// Progress of a running synthesis, reported after set-up, after construction and after each
/// time step.
/// Phases of a synthesis, in order; names (to_string) as published in PolicyStatus.phase and the
/// Synthesize action's feedback: "setup", "construction", "synthesis", "done".
enum class Phase { Setup, Construction, Synthesis, Done };
std::string to_string(Phase phase);

struct Progress {
  Phase phase = Phase::Setup;
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
  /// Operand bytes of the phase's kernels: values and records they load, entries they store (an
  /// upper bound of the memory traffic: caches serve much of it). 0 if not counted.
  double bytes = 0;
  /// A breakdown of the steps' time by kernel (with profile): already counted in the steps.
  bool breakdown = false;
};
/// How much an engine note matters: Info is a fact about the run (storage chosen, memory used);
/// Warning says the run differs from what was asked (another device, on-the-fly storage).
enum class NoteSeverity { Info, Warning };
/// What an engine note is about.
enum class NoteKind {
  DeviceChoice,    ///< which device was chosen, or skipped and why
  DeviceFallback,  ///< a device other than the one asked for runs the synthesis
  Transitions,     ///< transition storage (stored or on the fly) and why
  Sweep,           ///< work decomposition of the synthesis sweep
  Chunking,        ///< states split into chunks (allocation limits)
  DeviceMemory,    ///< device memory allocated
  KernelBuild      ///< program built from source or loaded from the binary cache
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
  std::size_t host_peak_bytes = 0;    ///< peak resident set of the process (VmHWM)
  std::vector<EngineNote> notes;      ///< device choice and fallback, storage, chunking, ...
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
};

/// Runs the engine named by options.compute.device. `auto` prefers a GPU, else the CPU OpenCL
/// device, else throws DeviceError; `cpu`/`gpu` that are missing use another OpenCL device, and
/// a device that fails (DeviceError) is retried once on the CPU device, each with a Warning
/// DeviceFallback note in report->notes (docs/engine.md). Throws Cancelled, DeviceError,
/// ConfigError.
Policy synthesize(const Abstraction& abstraction, const SynthesisOptions& options,
                  SynthesisReport* report = nullptr);

/// The work split of a synthesis over several devices or ranks (compute.devices, communicator),
/// without computing: the sweep, each device's part and memory, the exchange per time step; one
/// line each (amytiss_synth --dry-run). Collective over the communicator's ranks.
std::vector<std::string> describe_scale_out(const Abstraction& abstraction, const SynthesisOptions& options);

/// Memory a synthesis needs, in bytes, as the OpenCL engine lays it out (docs/engine.md).
struct MemoryEstimate {
  double policy_bytes = 0;             ///< policy arrays as in the file: float64 values of every
                                       ///< step, uint32 input indices, uint8 roles
  double bytes_per_triple = 0;         ///< one stored transition record: uint32 window offset +
                                       ///< float32 cell masses of every dimension's window
  double stored_transition_bytes = 0;  ///< bytes_per_triple times the state-input-disturbance triples
};
MemoryEstimate estimate_memory(const Abstraction& abstraction);

/// The serial reference engine directly.
Policy synthesize_reference(const Abstraction& abstraction, const ProgressCallback& progress,
                            SynthesisReport* report = nullptr);

/// OpenCL devices visible through the ICD loader, one line each: "[p.d] platform / device (type,
/// global memory MiB, compute units)". Empty when none.
std::vector<std::string> list_opencl_devices();

/// Peak resident set size of this process in bytes (VmHWM), 0 if unknown.
std::size_t peak_resident_bytes();

}  // namespace amytiss
