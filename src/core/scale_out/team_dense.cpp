// The dense sweep over several devices and ranks: contiguous slices of the states, each device
// constructing and sweeping its own, the new values exchanged after every step. Every state's
// value comes from the same kernel code over the same whole V as on one device: bit-identical.
#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "amytiss/format.hpp"
#include "opencl/layout.hpp"
#include "opencl/program_cache.hpp"
#include "opencl/source.hpp"
#include "scale_out/team.hpp"

namespace amytiss::detail {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

struct Member {
  RunPlan plan;
  Program program;
  Kernel construct, sweep;
  RunBuffers buffers;
};

// The padded value array's split: each slice's states own the padded cells from their first
// state's cell up to the next slice's first (padding cells in between are zero everywhere).
Split padded_split(const Split& states, const std::vector<std::size_t>& padded_index, std::size_t padded_size) {
  return states.mapped([&](std::uint64_t state) -> std::uint64_t {
    return state < padded_index.size() ? padded_index[state] : padded_size;
  });
}

double exchange_bytes_per_step(const Abstraction& a, const Layout& layout) {
  return 8.0 * double(layout.padded_size) + 4.0 * double(a.states.size());
}

}  // namespace

Policy run_dense_team(const Abstraction& a, Team& team, const SynthesisOptions& options,
                      const OpenClEngineOptions& engine_options, SynthesisReport& rep, const TeamProgress& progress) {
  const Layout layout(a);
  const std::size_t n_states = a.states.size();
  const Split states = team.split(n_states);
  std::vector<TeamDevice>& devices = team.devices();
  for (const std::string& line : team.describe(states, "states"))
    rep.notes.push_back({NoteSeverity::Info, NoteKind::Sweep, line});

  auto phase_start = Clock::now();
  std::vector<Member> members(devices.size());
  std::size_t device_bytes = 0, stored_devices = 0;
  for (std::size_t i = 0; i < devices.size(); ++i) {
    Member& m = members[i];
    const DeviceInfo& info = devices[i].info;
    m.plan = plan_run(a, layout, info, options, engine_options, rep, states.devices[i].begin, states.devices[i].end);
    stored_devices += !m.plan.on_the_fly;
    m.program = build_program(devices[i].session.context.get(), info,
                              opencl_program_source(a, m.plan.on_the_fly, m.plan.group_size),
                              engine_options.kernel_cache_dir, rep.notes);
    m.construct = create_kernel(m.program.get(), "construct");
    m.sweep = create_kernel(m.program.get(),
                            m.plan.variant == SweepVariant::GroupPerState ? "synthesize_group" : "synthesize_item");
  }
  rep.phases.push_back({"kernel build", seconds_since(phase_start), 0, 0});
  if (progress) progress(Phase::Setup, 0, -1);
  for (std::size_t i = 0; i < devices.size(); ++i) {
    members[i].buffers = allocate_buffers(a, layout, members[i].plan, devices[i].session.context.get(), rep);
    device_bytes = std::max(device_bytes, members[i].buffers.device_bytes);
  }
  rep.device_bytes = device_bytes;
  rep.transitions = "stored on " + std::to_string(stored_devices) + " of " + std::to_string(devices.size()) +
                    " devices of this rank, each its slice's records (the others on the fly)";

  phase_start = Clock::now();
  for (std::size_t i = 0; i < devices.size(); ++i)
    if (!members[i].plan.on_the_fly)
      construct_transitions(devices[i].session.queue.get(), members[i].construct.get(), members[i].plan,
                            members[i].buffers, false);
  for (TeamDevice& device : devices) check(clFinish(device.session.queue.get()), "clFinish(construct)");
  const double construction_seconds = seconds_since(phase_start);
  rep.phases.push_back(
      {"construction", construction_seconds, double(a.pairs()) / std::max(construction_seconds, 1e-9), 0});
  if (progress) progress(Phase::Construction, 0, -1);

  std::string label;
  for (const TeamDevice& device : devices) label += (label.empty() ? "" : " + ") + device.info.label();
  Policy policy = empty_policy(a, label);
  const std::vector<std::size_t>& padded_index = members.front().buffers.padded_index;
  std::vector<double> host_values = members.front().buffers.terminal;
  unpad(policy, a.horizon, padded_index, host_values.data());
  const Split padded = padded_split(states, padded_index, layout.padded_size);
  rep.exchange_bytes_per_step = exchange_bytes_per_step(a, layout);
  std::vector<cl_mem> value_buffers(devices.size()), input_buffers(devices.size());
  const auto synthesis_start = Clock::now();
  int current = 0;
  for (unsigned step = a.horizon; step-- > 0;) {
    phase_start = Clock::now();
    for (std::size_t i = 0; i < devices.size(); ++i) {
      Member& m = members[i];
      if (!m.buffers.chunks.empty())
        enqueue_sweep(devices[i].session.queue.get(), m.sweep.get(), m.plan, m.buffers, current);
      check(clFlush(devices[i].session.queue.get()), "clFlush(synthesize)");
      value_buffers[i] = m.buffers.values[1 - current].get();
      input_buffers[i] = m.buffers.best_input.get();
    }
    for (TeamDevice& device : devices) check(clFinish(device.session.queue.get()), "clFinish(synthesize)");
    team.exchange(padded, sizeof(double), value_buffers, host_values.data(), true);
    team.exchange(states, sizeof(std::uint32_t), input_buffers,
                  policy.input_index.data() + std::size_t(step) * n_states, false);
    current = 1 - current;
    unpad(policy, step, padded_index, host_values.data());
    report_team_step(a, step, seconds_since(phase_start), 0, seconds_since(synthesis_start), rep, progress);
  }
  report_team_exchange(a, team, rep);
  return policy;
}

std::vector<std::string> describe_dense_team(const Abstraction& a, Team& team, const SynthesisOptions& options,
                                             const OpenClEngineOptions& engine_options) {
  const Layout layout(a);
  const Split states = team.split(a.states.size());
  std::vector<std::string> lines = {"dense sweep: states split in contiguous slices by device throughput"};
  for (std::size_t r = 0; r < states.ranks.size(); ++r)
    lines.push_back("rank " + std::to_string(r) + ": states [" + std::to_string(states.ranks[r].begin) + ", " +
                    std::to_string(states.ranks[r].end) + ")");
  for (std::size_t i = 0; i < team.devices().size(); ++i) {
    SynthesisReport ignored;
    const DeviceInfo& info = team.devices()[i].info;
    const RunPlan plan =
        plan_run(a, layout, info, options, engine_options, ignored, states.devices[i].begin, states.devices[i].end);
    const double values = 2.0 * double(layout.padded_size + kValueSlack) * 8.0 + double(a.states.size()) * 5.0;
    const double records = plan.on_the_fly ? 0.0
                                           : double(states.devices[i].size()) * double(plan.records_per_state) *
                                                 double(layout.record_bytes());
    lines.push_back("rank " + std::to_string(states.rank) + " device " + std::to_string(i) + ": " + info.label() +
                    ", states [" + std::to_string(states.devices[i].begin) + ", " +
                    std::to_string(states.devices[i].end) + "), " + (plan.on_the_fly ? "on the fly" : "stored") +
                    ", device memory " + format_bytes(values + records) + " (records " + format_bytes(records) +
                    ", values " + format_bytes(values) + ") of " + format_bytes(double(info.global_memory)));
  }
  lines.push_back("exchange per step: " + format_bytes(exchange_bytes_per_step(a, layout)) + " (padded values " +
                  format_bytes(8.0 * double(layout.padded_size)) + " + inputs " +
                  format_bytes(4.0 * double(a.states.size())) +
                  "), each device receiving the parts it did not compute");
  return lines;
}

}  // namespace amytiss::detail
