// Several devices or ranks: the devices opened, the team formed, the sweep chosen for the
// smallest device of every rank, then the dense or the factored sweep over the team.
#include <algorithm>
#include <chrono>
#include <optional>

#include "amytiss/errors.hpp"
#include "opencl/factored/plan.hpp"
#include "opencl/engine.hpp"
#include "opencl/layout.hpp"
#include "scale_out/team.hpp"

namespace amytiss {
namespace detail {
namespace {

using Clock = std::chrono::steady_clock;

// The sweep and its plan must be the same on every rank and fit every device: they are chosen
// for the least memory and the least allocation limit of any device of any rank.
DeviceInfo smallest_device(Team& team) {
  DeviceInfo smallest = team.devices().front().info;
  for (const TeamDevice& device : team.devices()) {
    smallest.global_memory = std::min(smallest.global_memory, device.info.global_memory);
    smallest.max_allocation = std::min(smallest.max_allocation, device.info.max_allocation);
  }
  auto least = [&](std::uint64_t value) {
    const std::vector<double> all = team.communicator().allgather_value(double(value));
    return std::uint64_t(*std::min_element(all.begin(), all.end()));
  };
  smallest.global_memory = least(smallest.global_memory);
  smallest.max_allocation = least(smallest.max_allocation);
  return smallest;
}

std::string team_label(Team& team) {
  std::string label;
  for (const TeamDevice& device : team.devices()) label += (label.empty() ? "" : " + ") + device.info.label();
  const int ranks = team.communicator().size();
  return ranks > 1 ? std::to_string(ranks) + " ranks, rank " + std::to_string(team.communicator().rank()) + ": " + label
                   : label;
}

Team open_team(const SynthesisOptions& options, Communicator& solo, std::vector<EngineNote>& notes) {
  return Team(open_team_devices(options.compute, notes), options.communicator ? *options.communicator : solo);
}

}  // namespace

Policy synthesize_team(const Abstraction& a, const SynthesisOptions& options, SynthesisReport& rep,
                       const OpenClEngineOptions& engine_options) {
  const auto start = Clock::now();
  SoloCommunicator solo;
  Team team = open_team(options, solo, rep.notes);
  rep.device = team_label(team);
  rep.phases.push_back({"device setup", std::chrono::duration<double>(Clock::now() - start).count(), 0, 0});
  const TeamProgress progress = [&](Phase phase, unsigned done, double remaining) {
    if (options.progress && !options.progress({phase, done, a.horizon, rep.device,
                                               std::chrono::duration<double>(Clock::now() - start).count(), remaining}))
      throw Cancelled();
  };
  const DeviceInfo smallest = smallest_device(team);
  Policy policy;
  if (const auto factored = choose_factored(a, smallest, options, rep)) {
    rep.transitions = "factored: per-dimension mass tables on every device";
    policy = run_factored_team(a, *factored, team, engine_options, rep, progress);
  } else {
    check_dense_supported(Layout(a));
    policy = run_dense_team(a, team, options, engine_options, rep, progress);
  }
  policy.computed_by = rep.device;
  rep.host_peak_bytes = peak_resident_bytes();
  return policy;
}

}  // namespace detail

std::vector<std::string> describe_scale_out(const Abstraction& a, const SynthesisOptions& options) {
  using namespace detail;
  if (options.compute.device == DeviceKind::Reference)
    throw ConfigError("compute.device",
                      "reference runs on the host alone; a plan of devices needs an OpenCL device "
                      "(example: device: auto)");
  SynthesisReport rep;
  SoloCommunicator solo;
  Team team = open_team(options, solo, rep.notes);
  std::vector<std::string> lines = {"devices: " + team_label(team)};
  const DeviceInfo smallest = smallest_device(team);
  const std::optional<FactoredPlan> factored = choose_factored(a, smallest, options, rep);
  for (const EngineNote& note : rep.notes)
    if (note.kind == NoteKind::Sweep) lines.push_back(note.text);
  std::vector<std::string> plan;
  if (factored) {
    plan = describe_factored_team(a, *factored, team);
  } else {
    check_dense_supported(Layout(a));
    plan = describe_dense_team(a, team, options, {});
  }
  lines.insert(lines.end(), plan.begin(), plan.end());
  return lines;
}

}  // namespace amytiss
