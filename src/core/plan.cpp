// One place decides how a synthesis runs; the reasons become notes, so that a run, its report
// and --dry-run all say the same thing.
#include "plan.hpp"


#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/resources.hpp"
#include "amytiss/format.hpp"
#include "amytiss/grid_rules.hpp"
#include "bounds/system_engine.hpp"
#include "opencl/layout.hpp"
#include "opencl/run.hpp"
#include "opencl/sweep_choice.hpp"
#include "scale_out/team_dense.hpp"
#include "scale_out/team_factored.hpp"

namespace amytiss::detail {
namespace {

// `auto` runs the serial engine when the planned work over the horizon is at most this many
// multiply-adds: the serial engine does 3e7 to 2e8 of them per second (its masses cost most on
// small windows), so it is done in about a second at worst, while building an OpenCL program
// with an empty kernel cache takes about 2 s on pocl (BENCHMARKS.md).
constexpr double kSerialMultiplyAdds = 3e7;
// Unbounded specifications iterate until the bounds meet; the plan counts this many steps.
constexpr double kPlannedUnboundedSteps = 100;

void note(SynthesisPlan& plan, const std::string& text) {
  plan.notes.push_back({NoteSeverity::Info, NoteKind::DeviceChoice, text});
}

// `auto`'s choice by the planned work: the serial engine when an OpenCL build would dominate.
bool serial_pays(const Abstraction& a, SynthesisPlan& plan) {
  const double steps = a.unbounded ? kPlannedUnboundedSteps : double(a.horizon);
  const double total = plan.multiply_adds_per_step * steps;
  const std::string work = "planned work " + format_significant(plan.multiply_adds_per_step) + " multiply-adds per step, " +
                           format_significant(total) + " in all";
  if (total <= kSerialMultiplyAdds) {
    note(plan, "device auto: the serial reference engine (" + work + ", at most " + format_significant(kSerialMultiplyAdds) +
                   ": building an OpenCL program would take longer than the synthesis)");
    return true;
  }
  note(plan, "device auto: an OpenCL device (" + work + ", above the serial engine's " +
                 format_significant(kSerialMultiplyAdds) + ")");
  return false;
}

// The grid whose eta to change: the one with the most points among those the estimate grows with
// (the row bounds grow with states x inputs x disturbances, the policy arrays with the states).
std::string memory_key(const Abstraction& a, bool rows) {
  if (!rows || (a.states.size() >= a.inputs.size() && a.states.size() >= a.disturbances.size()))
    return "states.eta";
  return a.inputs.size() >= a.disturbances.size() ? "inputs.eta" : "disturbances.eta";
}

void check_host_memory(const Abstraction& a, const SynthesisOptions& options, SynthesisPlan& plan) {
  const MemoryEstimate estimate = estimate_memory(a, options.compute);
  const HostMemory available = available_memory(options.memory_limit_bytes);
  const bool system = a.config.guarantee == Guarantee::System;
  const std::string need = format_significant(estimate.host_bytes) + " bytes (" + format_bytes(estimate.host_bytes) +
                           (system ? ": policy arrays " + format_bytes(estimate.policy_bytes) + ", bounds " +
                                         format_bytes(estimate.bounds_bytes) + " for " + estimate.bounds_method
                                   : ": policy arrays") +
                           ")";
  const std::string limit = format_significant(available.bytes) + " bytes (" + format_bytes(available.bytes) + ", " +
                            available.source + ")";
  if (estimate.host_bytes > available.bytes) {
    const std::string key = memory_key(a, system);
    throw ConfigError(key, "the run needs an estimated " + need + " of host memory, more than the " + limit +
                               " this process may use; expected a coarser grid (a larger " + key +
                               ", fewer points)" + (system ? " or fewer inputs or disturbances" : " or a shorter spec.horizon"));
  }
  note(plan, "host memory: an estimated " + need + " of " + limit);
}

void plan_bounds(const SynthesisOptions& options, EngineScope scope, SynthesisPlan& plan) {
  const char* const why = "auto or reference with guarantee: system (its interval bounds are computed on the host's cores)";
  if (scope == EngineScope::OpenClOnly || options.compute.device == DeviceKind::Cpu ||
      options.compute.device == DeviceKind::Gpu)
    throw ConfigError("compute.device", "'" + to_string(options.compute.device) + "' is not supported: expected " +
                                            why + ", e.g. device: auto");
  if (!options.compute.devices.empty() || is_scale_out(options))
    throw ConfigError("compute.devices", std::string("several devices or ranks are not supported: expected ") + why);
  plan.engine = EngineKind::Bounds;
  plan.bounds_method = options.compute.bounds_method;
  plan.bounds_serial = options.compute.device == DeviceKind::Reference;
  const std::string where = plan.bounds_serial ? "one host thread (device reference)" : "the host's cores";
  note(plan, plan.bounds_method == BoundsMethod::Auto
                 ? "guarantee: system: the interval MDP's bounds on " + where +
                       ", method auto (once the row bounds are known: whole tables where they pay, else "
                       "variable elimination, else row by row)"
                 : "guarantee: system: the interval MDP's bounds on " + where + ", method " +
                       to_string(plan.bounds_method) + " (compute.bounds_method)");
}

void plan_team(const Abstraction& a, const SynthesisOptions& options, SynthesisPlan& plan) {
  if (a.unbounded)
    throw ConfigError("spec.horizon", "infinite (interval iteration) runs on one OpenCL device or on compute.device: "
                                      "reference; several devices (compute.devices) and MPI ranks compute bounded "
                                      "horizons only (example: horizon: 16)");
  plan.engine = EngineKind::Team;
  plan.team = std::make_unique<TeamSetup>();
  Communicator& ranks = options.communicator ? *options.communicator : plan.team->solo;
  plan.team->team = std::make_unique<Team>(open_team_devices(options.compute, plan.notes), ranks);
  plan.factored = choose_sweep(a, plan.team->team->smallest_device(), options.compute, plan.notes);
}

}  // namespace

std::string to_string(EngineKind engine) {
  switch (engine) {
    case EngineKind::Reference: return "reference (serial, double precision)";
    case EngineKind::OneDevice: return "OpenCL, one device";
    case EngineKind::Team: return "OpenCL, several devices or ranks";
    case EngineKind::Bounds: return "continuous-system bounds (interval MDP on the host's cores)";
  }
  return "?";
}

bool is_scale_out(const SynthesisOptions& options) {
  return !options.compute.devices.empty() || (options.communicator && options.communicator->size() > 1);
}

bool chosen_by_engine(const SynthesisOptions& options) {
  const ComputeConfig& compute = options.compute;
  return compute.device == DeviceKind::Auto && compute.platform.empty() && compute.device_name.empty() &&
         !is_scale_out(options);
}

double planned_multiply_adds_per_step(const Abstraction& a) {
  std::size_t free_cells = 0;
  for (CellRole role : a.roles) free_cells += role == CellRole::Free;
  return double(free_cells) * double(a.inputs.size()) * double(a.disturbances.size()) * contraction_multiply_adds(a);
}

SynthesisPlan plan_synthesis(const Abstraction& a, const SynthesisOptions& options, EngineScope scope) {
  SynthesisPlan plan;
  plan.multiply_adds_per_step = planned_multiply_adds_per_step(a);
  if (a.config.spec.obstacles)
    note(plan, "footprint: " + footprint_work_text(fitted_states(a.config), a.config.spec) + " to find the cells it may touch, " +
                   "at most " + format_number(kMaxFootprintBoxTests) + " accepted");
  const bool any = scope == EngineScope::Any;
  check_host_memory(a, options, plan);
  if (a.config.guarantee == Guarantee::System) {
    plan_bounds(options, scope, plan);
    return plan;
  }
  if (any && options.compute.device == DeviceKind::Reference) {
    note(plan, "device: reference (serial, double precision)");
    return plan;
  }
  if (any && chosen_by_engine(options) && serial_pays(a, plan)) return plan;
  check_opencl_supported(a);
  if (is_scale_out(options)) {
    plan_team(a, options, plan);
  } else {
    plan.engine = EngineKind::OneDevice;
    plan.device = choose_device(options.compute, plan.notes);
    plan.may_fall_back = chosen_by_engine(options);
    plan.factored = choose_sweep(a, plan.device, options.compute, plan.notes);
  }
  if (!plan.factored) check_dense_supported(Layout(a));
  return plan;
}

std::vector<std::string> describe_plan(const Abstraction& a, SynthesisPlan& plan, const SynthesisOptions& options) {
  std::vector<std::string> lines = {"engine: " + to_string(plan.engine)};
  for (const EngineNote& note : plan.notes) lines.push_back(note.text);
  if (plan.engine == EngineKind::OneDevice && !plan.factored) {
    SynthesisReport storage;
    plan_run(a, Layout(a), plan.device, options.compute, {}, storage);
    lines.push_back("transitions: " + storage.transitions);
  }
  if (plan.engine == EngineKind::Bounds) {
    const std::string kept =
        lower_roles_text(a.states, a.config.spec, robust_cell_roles(a.states, a.config.spec, Bound::Lower)).text;
    if (!kept.empty()) lines.push_back("continuous-system bounds: " + kept);
  }
  if (plan.engine != EngineKind::Team) return lines;
  Team& team = *plan.team->team;
  lines.push_back("devices: " + team.label());
  const std::vector<std::string> split =
      plan.factored ? describe_factored_team(a, *plan.factored, team) : describe_dense_team(a, team, options.compute);
  lines.insert(lines.end(), split.begin(), split.end());
  return lines;
}

}  // namespace amytiss::detail
