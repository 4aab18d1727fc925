// The dense sweep over several devices and ranks: contiguous slices of the states, each device
// constructing and sweeping its own, the new values exchanged after every step. Every state's
// value comes from the same kernel code over the same whole V as on one device: bit-identical.
#include "scale_out/team_dense.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "amytiss/format.hpp"
#include "opencl/layout.hpp"
#include "opencl/program_cache.hpp"
#include "opencl/run.hpp"
#include "opencl/source.hpp"
#include "serial/point_iteration.hpp"

namespace amytiss::detail {
namespace {

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

// Every device's plan, program and buffers for its slice of the states: kernels built, then
// buffers allocated (notes: each device's storage and memory).
std::vector<Member> set_up_members(const Abstraction& a, const Layout& layout, Team& team, const Split& states,
                                   const ComputeConfig& compute, const OpenClEngineOptions& engine_options,
                                   StepReporter& reporter) {
  SynthesisReport& rep = reporter.report();
  std::vector<TeamDevice>& devices = team.devices();
  const auto phase_start = SteadyClock::now();
  std::vector<Member> members(devices.size());
  for (std::size_t i = 0; i < devices.size(); ++i) {
    Member& m = members[i];
    const DeviceInfo& info = devices[i].info;
    m.plan = plan_run(a, layout, info, compute, engine_options, rep, states.devices[i].begin, states.devices[i].end);
    m.program = build_program(devices[i].session.context.get(), info,
                              opencl_program_source(a, m.plan.on_the_fly, m.plan.group_size),
                              engine_options.kernel_cache_dir, rep.notes);
    m.construct = create_kernel(m.program.get(), "construct");
    m.sweep = create_kernel(m.program.get(),
                            m.plan.variant == SweepVariant::GroupPerState ? "synthesize_group" : "synthesize_item");
  }
  reporter.phase(PhaseKind::KernelBuild, "kernel build", seconds_since(phase_start));
  reporter.reached(Phase::Setup);
  std::size_t stored_devices = 0;
  for (std::size_t i = 0; i < devices.size(); ++i) {
    members[i].buffers = allocate_buffers(a, layout, members[i].plan, devices[i].session.context.get(), rep);
    rep.device_bytes = std::max(rep.device_bytes, members[i].buffers.device_bytes);
    stored_devices += !members[i].plan.on_the_fly;
  }
  rep.transitions = "stored on " + std::to_string(stored_devices) + " of " + std::to_string(devices.size()) +
                    " devices of this rank, each its slice's records (the others on the fly)";
  return members;
}

void construct_all(const Abstraction& a, Team& team, std::vector<Member>& members, StepReporter& reporter) {
  const auto phase_start = SteadyClock::now();
  std::vector<TeamDevice>& devices = team.devices();
  for (std::size_t i = 0; i < devices.size(); ++i)
    if (!members[i].plan.on_the_fly)
      construct_transitions(devices[i].session.queue.get(), members[i].construct.get(), members[i].plan,
                            members[i].buffers, false);
  for (TeamDevice& device : devices) check(clFinish(device.session.queue.get()), "clFinish(construct)");
  const double seconds = seconds_since(phase_start);
  reporter.phase(PhaseKind::Construction, "construction", seconds, double(a.pairs()) / std::max(seconds, 1e-9));
  reporter.reached(Phase::Construction);
}

// One time step over the team: every device sweeps its slice from its whole copy of V, then the
// new values and inputs of every slice go to every device and to the host.
class DenseTeamStep : public BellmanStep {
 public:
  DenseTeamStep(const Abstraction& a, const Layout& layout, Team& team, std::vector<Member>& members,
                const Split& states)
      : team_(team), members_(members), states_(states),
        padded_(padded_split(states, members.front().buffers.padded_index, layout.padded_size)),
        host_values_(members.front().buffers.terminal), value_buffers_(members.size()), input_buffers_(members.size()) {
    multiply_adds_ = double(members.front().buffers.free_states) * double(members.front().plan.records_per_state) *
                     contraction_multiply_adds(a);
  }
  // Team runs compute bounded horizons only (the plan refuses the others): the devices always
  // hold the previous step's values.
  void apply(const double*, double*, std::uint32_t*) override {
    throw std::logic_error("a team step runs on the values its devices hold");
  }
  void apply_resident(const double*, double* out, std::uint32_t* chosen) override {
    std::vector<TeamDevice>& devices = team_.devices();
    for (std::size_t i = 0; i < devices.size(); ++i) {
      Member& m = members_[i];
      if (!m.buffers.chunks.empty())
        enqueue_sweep(devices[i].session.queue.get(), m.sweep.get(), m.plan, m.buffers, current_);
      check(clFlush(devices[i].session.queue.get()), "clFlush(synthesize)");
      value_buffers_[i] = m.buffers.values[1 - current_].get();
      input_buffers_[i] = m.buffers.best_input.get();
    }
    for (TeamDevice& device : devices) check(clFinish(device.session.queue.get()), "clFinish(synthesize)");
    team_.exchange(padded_, sizeof(double), value_buffers_, host_values_.data(), true);
    team_.exchange(states_, sizeof(std::uint32_t), input_buffers_, chosen, false);
    current_ = 1 - current_;
    unpad(out, members_.front().buffers.padded_index, host_values_.data());
  }
  double multiply_adds() const override { return multiply_adds_; }

 private:
  Team& team_;
  std::vector<Member>& members_;
  const Split& states_;
  const Split padded_;
  std::vector<double> host_values_;
  std::vector<cl_mem> value_buffers_, input_buffers_;
  int current_ = 0;
  double multiply_adds_ = 0;
};

}  // namespace

Policy run_dense_team(const Abstraction& a, Team& team, const ComputeConfig& compute,
                      const OpenClEngineOptions& engine_options, StepReporter& reporter) {
  const Layout layout(a);
  const Split states = team.split(a.states.size());
  for (const std::string& line : team.describe(states, "states"))
    reporter.report().notes.push_back({NoteSeverity::Info, NoteKind::Sweep, line});
  std::vector<Member> members = set_up_members(a, layout, team, states, compute, engine_options, reporter);
  construct_all(a, team, members, reporter);
  DenseTeamStep step(a, layout, team, members, states);
  Policy policy = run_abstraction_backward(a, step, reporter);
  team.report_exchange(exchange_bytes_per_step(a, layout), a.horizon, reporter.report());
  return policy;
}

std::vector<std::string> describe_dense_team(const Abstraction& a, Team& team, const ComputeConfig& compute) {
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
        plan_run(a, layout, info, compute, {}, ignored, states.devices[i].begin, states.devices[i].end);
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
