#pragma once
// Synthesis engines: the serial reference (Algorithms 1 + 3 of the paper, double precision) and
// the OpenCL engine (Algorithms 2 + 4 and on-the-fly, any OpenCL device, one or several). One
// entry point, which plans the run and carries the plan out (docs/engine.md).
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/resources.hpp"
#include "amytiss/scale_out.hpp"
#include "amytiss/synthesis_types.hpp"

namespace amytiss {

/// Plans the run (engine, devices, sweep; the reasons in report->notes) and carries it out.
/// `auto` takes the serial reference engine for problems whose planned work an OpenCL kernel
/// build would dominate, else prefers a GPU, else the CPU OpenCL device; `cpu`/`gpu` are honoured
/// or refused. A device that `auto` chose and that fails (DeviceError) is retried once on the CPU
/// device, with a Warning DeviceFallback note. Throws Cancelled; ConfigError (a configuration the
/// engines cannot run, naming its key); DeviceError (a device request this machine cannot honour,
/// its message starting with the key; no OpenCL device; or a device that fails).
Policy synthesize(const Abstraction& abstraction, const SynthesisOptions& options,
                  SynthesisReport* report = nullptr);

/// The plan synthesize() would carry out, without computing: engine, devices, sweep, the
/// reasons, and for several devices or ranks each one's part and memory and the exchange per
/// time step; one line each (amytiss_synth --dry-run). Collective over the communicator's ranks.
std::vector<std::string> describe_synthesis(const Abstraction& abstraction, const SynthesisOptions& options);

/// Memory a synthesis needs, in bytes, as the engines lay it out (docs/engine.md, "The plan").
struct MemoryEstimate {
  double policy_bytes = 0;             ///< policy arrays as in the file: float64 values of every
                                       ///< step (and upper bounds), uint32 input indices, uint8 roles
  double bytes_per_triple = 0;         ///< one stored transition record: uint32 window offset +
                                       ///< float32 cell masses of every dimension's window; 0 under
                                       ///< guarantee: system, which stores no transitions
  double stored_transition_bytes = 0;  ///< bytes_per_triple times the state-input-disturbance triples
  /// guarantee: system: the bounds engine's peak besides the policy arrays (the row bounds, their
  /// construction and the method's buffers, bounds_method's or, for auto, the dearest it may choose)
  double bounds_bytes = 0;
  std::string bounds_method;           ///< guarantee: system: the method bounds_bytes counts
  /// What the host's memory must hold: policy_bytes plus bounds_bytes (guarantee: system), or the
  /// policy arrays alone (guarantee: abstraction: the stored transitions live on the OpenCL
  /// device, whose memory the sweep's choice weighs). Compared with available_memory().
  double host_bytes = 0;
};
/// For the abstraction's compute section, or `compute` (the method and the threads it names).
MemoryEstimate estimate_memory(const Abstraction& abstraction);
MemoryEstimate estimate_memory(const Abstraction& abstraction, const ComputeConfig& compute);

/// The serial reference engine directly, whatever the configuration's compute section says; for
/// guarantee: system, the joint interval MDP's bounds on one thread (bounds_method joint: the
/// oracle's set).
Policy synthesize_reference(const Abstraction& abstraction, const ProgressCallback& progress,
                            SynthesisReport* report = nullptr);

/// OpenCL devices visible through the ICD loader, one line each: "[p.d] platform / device (type,
/// global memory, compute units)". Empty when none.
std::vector<std::string> list_opencl_devices();

}  // namespace amytiss
