#pragma once
// The synthesis plan (docs/engine.md, "The plan"): one decision, before any computing, of the
// engine (serial reference, one OpenCL device, a team of devices and ranks), the devices, the
// sweep (dense or factored, with the factored plan only when chosen) and whether a failing device
// may be retried on the CPU device, with the reasons as notes. synthesize(), --dry-run,
// single-device and team runs all carry out this plan.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/synthesis_types.hpp"
#include "opencl/device.hpp"
#include "factored/factored_plan.hpp"
#include "scale_out/team.hpp"

namespace amytiss::detail {

enum class EngineKind {
  Reference,  ///< the serial engine on the host
  OneDevice,  ///< the OpenCL engine on one device
  Team,       ///< the OpenCL engine on several devices or ranks
  Bounds      ///< continuous-system bounds (guarantee: system): the interval MDP on the host's cores
};
std::string to_string(EngineKind engine);

/// The devices of a team run with their sessions open, and the ranks (this process alone when
/// the options name no communicator).
struct TeamSetup {
  SoloCommunicator solo;
  std::unique_ptr<Team> team;
};

struct SynthesisPlan {
  EngineKind engine = EngineKind::Reference;
  DeviceInfo device;                     ///< OneDevice: the device
  std::unique_ptr<TeamSetup> team;       ///< Team: devices and ranks
  std::optional<FactoredPlan> factored;  ///< OpenCL engines: the factored sweep when chosen, else dense
  double multiply_adds_per_step = 0;     ///< the planned work: the dense sweep's multiply-adds per time step
  bool may_fall_back = false;            ///< a failing device may be retried on the CPU device
  /// Bounds: the method asked for (compute.bounds_method; auto: chosen once the row bounds are
  /// known, docs/engine.md) and whether on one thread (device reference) or the host's.
  BoundsMethod bounds_method = BoundsMethod::Auto;
  bool bounds_serial = false;
  std::vector<EngineNote> notes;         ///< the engine, devices and sweep chosen, and why
};

/// Whether the engine may choose the device (and retry a failing one on the CPU device): `auto`
/// without a platform, a device name, a list of devices or several ranks.
bool chosen_by_engine(const SynthesisOptions& options);
/// Whether the options ask for more than one device or rank.
bool is_scale_out(const SynthesisOptions& options);
/// The dense sweep's multiply-adds of one time step: free cells x inputs x disturbances x the
/// window contraction's multiply-adds.
double planned_multiply_adds_per_step(const Abstraction& abstraction);

/// Which engines a plan may choose: any, or the OpenCL engines only (tests of the OpenCL engine).
enum class EngineScope { Any, OpenClOnly };

/// The plan for `abstraction` under `options`. `auto` (chosen by the engine) takes the serial
/// engine when the planned work is small enough that an OpenCL kernel build would dominate, else
/// the first GPU, else the CPU device; an explicit kind is honoured or refused. A request that
/// cannot be honoured is a ConfigError naming its key; DeviceError when no OpenCL device answers.
/// guarantee: system takes the Bounds engine (auto: the host's threads; reference: one thread;
/// the method from compute.bounds_method) and refuses an OpenCL device or several devices with a
/// ConfigError.
/// Opens a team's devices (collective over the ranks).
SynthesisPlan plan_synthesis(const Abstraction& abstraction, const SynthesisOptions& options,
                             EngineScope scope = EngineScope::Any);

/// The plan in lines for people (amytiss_synth --dry-run): engine, devices, sweep, the reasons,
/// and a team's split, memory per device and exchange per step. Collective over the ranks.
std::vector<std::string> describe_plan(const Abstraction& abstraction, SynthesisPlan& plan,
                                       const SynthesisOptions& options);

}  // namespace amytiss::detail
