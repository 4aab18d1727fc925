// The factored sweep over several devices and ranks. Every stage's output entries are split in
// contiguous ranges; each device computes its range (each entry the same FMA chain over its
// window as on one device) and the ranges are exchanged before the next stage reads them. Q is
// split the same way, and accumulates the slices in order per entry, so it is exchanged once per
// step; the input choice is split by states. The result is bit-identical to one device.
#include "scale_out/team_factored.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "amytiss/format.hpp"
#include "opencl/factored/device_parts.hpp"
#include "opencl/factored/tables.hpp"
#include "serial/point_iteration.hpp"

namespace amytiss::detail {
namespace {

// A stage's split: parts over the team, their entries, and whether the next stage needs the
// whole output (then it is exchanged).
struct StageSplit {
  StageParts parts;
  Split by_part, by_entry;
  bool exchange = false;
};

std::vector<StageSplit> stage_splits(const FactoredPlan& plan, const Team& team) {
  std::vector<StageSplit> splits;
  for (const FactoredStage& stage : plan.stages) {
    StageSplit split;
    split.parts = stage_parts(stage, team.total_devices());
    split.by_part = team.split(split.parts.parts);
    const std::uint64_t entries = split.parts.entries;
    split.by_entry = split.by_part.mapped([entries](std::uint64_t part) { return part * entries; });
    splits.push_back(split);
  }
  std::vector<StageParts> parts;
  for (const StageSplit& split : splits) parts.push_back(split.parts);
  for (std::size_t k = 0; k < splits.size(); ++k) splits[k].exchange = exchange_after(plan, parts, k);
  return splits;
}

// Bytes one step exchanges: split stage tensors of every slice, Q once, V and the inputs.
double exchange_bytes_per_step(const Abstraction& a, const FactoredPlan& plan, const std::vector<StageSplit>& splits) {
  double bytes = 12.0 * double(a.states.size());
  for (std::size_t k = 0; k < plan.stages.size(); ++k) {
    if (!splits[k].exchange) continue;
    const bool last = k + 1 == plan.stages.size();
    bytes += 8.0 * double(plan.stages[k].output_size) * (last ? 1.0 : double(plan.slices));
  }
  return bytes;
}

void finish_all(Team& team) {
  for (TeamDevice& device : team.devices()) check(clFinish(device.session.queue.get()), "clFinish(factored sweep)");
}

// Every device's kernels and buffers (the same whole tensors on each).
struct TeamMember {
  FactoredKernels kernels;
  FactoredBuffers buffers;
};

// Kernels built on every device, then the mass tables computed and sent to every device.
std::vector<TeamMember> set_up_members(const Abstraction& a, const FactoredPlan& plan, Team& team,
                                       const OpenClEngineOptions& engine_options, std::vector<MassTable>& tables,
                                       StepReporter& reporter) {
  SynthesisReport& rep = reporter.report();
  std::vector<TeamMember> members(team.devices().size());
  auto phase_start = SteadyClock::now();
  // A stage split by more than its major digit needs each part's rows as one range of work-items.
  bool rows_in_output_order = false;
  for (const FactoredStage& stage : plan.stages) {
    const StageParts parts = stage_parts(stage, team.total_devices());
    rows_in_output_order = rows_in_output_order || (parts.parts > 1 && !parts.by_major_digit);
  }
  for (std::size_t i = 0; i < members.size(); ++i) {
    TeamDevice& device = team.devices()[i];
    StageShape shape = factored_stage_shape(device.info, engine_options);
    shape.rows_in_output_order = rows_in_output_order;
    shape.split_by_team = true;
    shape.states_in_q_order = false;  // the input choice is split by states
    members[i].kernels = build_factored_kernels(a, plan, device.info, device.session.context.get(),
                                                engine_options.kernel_cache_dir, shape, rep.notes);
  }
  reporter.phase(PhaseKind::KernelBuild, "kernel build", seconds_since(phase_start));
  reporter.reached(Phase::Setup);
  phase_start = SteadyClock::now();
  tables = factored_mass_tables(a, plan);
  for (std::size_t i = 0; i < members.size(); ++i) {
    members[i].buffers = allocate_factored_buffers(a, plan, tables, team.devices()[i].session.context.get(),
                                                   team.devices()[i].info.is_cpu(), members[i].kernels.shape);
    rep.device_bytes = std::max(rep.device_bytes, members[i].buffers.device_bytes);
  }
  reporter.phase(PhaseKind::Construction, "construction", seconds_since(phase_start));
  reporter.reached(Phase::Construction);
  return members;
}

// One time step over the team: every slice's stages, each device computing its part of every
// stage's entries (exchanged where the next stage needs the whole tensor), then the input choice
// split by states, the new values and inputs exchanged.
class FactoredTeamStep : public BellmanStep {
 public:
  FactoredTeamStep(const Abstraction& a, const FactoredPlan& plan, Team& team, std::vector<TeamMember>& members,
                   double multiply_adds)
      : a_(a), plan_(plan), team_(team), members_(members), splits_(stage_splits(plan, team)),
        states_(team.split(a.states.size())), host_values_(factored_terminal_values(a)),
        host_tensor_(plan.largest_stage_tensor), host_q_(plan.q_size), exchanged_(members.size()),
        inputs_(members.size()), multiply_adds_(multiply_adds) {}
  // Team runs compute bounded horizons only (the plan refuses the others): the devices always
  // hold the previous step's values.
  void apply(const double*, double*, std::uint32_t*) override {
    throw std::logic_error("a team step runs on the values its devices hold");
  }
  void apply_resident(const double*, double* out, std::uint32_t* chosen) override {
    for (std::size_t slice = 0; slice < plan_.slices; ++slice)
      for (std::size_t k = 0; k < plan_.stages.size(); ++k) run_stage(slice, k);
    const StageSplit& last = splits_.back();
    if (last.exchange) team_.exchange(last.by_entry, sizeof(double), exchanged_, host_q_.data(), true);
    choose_inputs();
    team_.exchange(states_, sizeof(double), exchanged_, host_values_.data(), true);
    team_.exchange(states_, sizeof(std::uint32_t), inputs_, chosen, false);
    std::copy(host_values_.begin(), host_values_.begin() + std::ptrdiff_t(a_.states.size()), out);
    current_ = 1 - current_;
  }
  double multiply_adds() const override { return multiply_adds_; }
  const Split& states() const { return states_; }
  double exchange_bytes() const { return exchange_bytes_per_step(a_, plan_, splits_); }

 private:
  void run_stage(std::size_t slice, std::size_t k);
  void choose_inputs();

  const Abstraction& a_;
  const FactoredPlan& plan_;
  Team& team_;
  std::vector<TeamMember>& members_;
  const std::vector<StageSplit> splits_;
  const Split states_;
  std::vector<double> host_values_, host_tensor_, host_q_;
  std::vector<cl_mem> exchanged_, inputs_;
  double multiply_adds_;
  int current_ = 0;
};

void FactoredTeamStep::run_stage(std::size_t slice, std::size_t k) {
  std::vector<TeamDevice>& devices = team_.devices();
  const FactoredStage& stage = plan_.stages[k];
  const bool last = k + 1 == plan_.stages.size();
  const StageSplit& split = splits_[k];
  const StagePlacement placement = stage_placement(a_, plan_, k, slice);
  for (std::size_t i = 0; i < devices.size(); ++i) {
    FactoredBuffers& b = members_[i].buffers;
    cl_mem in = k == 0 ? b.values[current_].get() : b.stage_tensors[(k - 1) % 2].get();
    cl_mem out = last ? b.q.get() : b.stage_tensors[k % 2].get();
    exchanged_[i] = out;
    cl_kernel kernel = members_[i].kernels.stages[k].get();
    set_stage_arguments(kernel, in, out, b.tables[stage.dimension], placement);
    const std::uint64_t items = stage_work_items(stage, members_[i].kernels.shape);
    const std::uint64_t items_per_part = items / split.parts.parts;
    const Range part = split.parts.parts == 1 ? Range{0, 1} : split.by_part.devices[i];
    launch_range(devices[i].session.queue.get(), kernel, part.begin * items_per_part, part.end * items_per_part,
                 factored_group_size(devices[i].info));
    check(clFlush(devices[i].session.queue.get()), "clFlush(factored sweep)");
  }
  finish_all(team_);
  if (!last && split.exchange) team_.exchange(split.by_entry, sizeof(double), exchanged_, host_tensor_.data(), true);
}

void FactoredTeamStep::choose_inputs() {
  std::vector<TeamDevice>& devices = team_.devices();
  for (std::size_t i = 0; i < devices.size(); ++i) {
    FactoredBuffers& b = members_[i].buffers;
    cl_kernel kernel = members_[i].kernels.choose.get();
    set_choose_arguments(kernel, b, 1 - current_);
    launch_range(devices[i].session.queue.get(), kernel, states_.devices[i].begin, states_.devices[i].end,
                 factored_group_size(devices[i].info));
    check(clFlush(devices[i].session.queue.get()), "clFlush(factored sweep)");
    exchanged_[i] = b.values[1 - current_].get();
    inputs_[i] = b.best_input.get();
  }
  finish_all(team_);
}

}  // namespace

Policy run_factored_team(const Abstraction& a, const FactoredPlan& plan, Team& team,
                         const OpenClEngineOptions& engine_options, StepReporter& reporter) {
  std::vector<MassTable> tables;
  std::vector<TeamMember> members = set_up_members(a, plan, team, engine_options, tables, reporter);
  double multiply_adds_per_step = 0;
  for (std::size_t k = 0; k < plan.stages.size(); ++k)
    multiply_adds_per_step +=
        stage_work(a, plan, k, tables[plan.stages[k].dimension], members.front().kernels.shape).multiply_adds;
  FactoredTeamStep step(a, plan, team, members, multiply_adds_per_step);
  for (const std::string& line : team.describe(step.states(), "input choice, states"))
    reporter.report().notes.push_back({NoteSeverity::Info, NoteKind::Sweep, line});
  Policy policy = run_abstraction_backward(a, step, reporter);
  team.report_exchange(step.exchange_bytes(), a.horizon, reporter.report());
  return policy;
}

StageParts stage_parts(const FactoredStage& stage, std::size_t devices) {
  StageParts parts;
  if (stage.vector_digit && *stage.vector_digit == 0) {
    parts.entries = stage.output_size;
    return parts;
  }
  if (stage.output.front().radix >= devices) {
    parts.parts = stage.output.front().radix;
    parts.by_major_digit = true;
  } else {
    const std::size_t prefix = stage.vector_digit ? *stage.vector_digit : stage.output.size();
    for (std::size_t j = 0; j < prefix; ++j) parts.parts *= stage.output[j].radix;
  }
  parts.entries = stage.output_size / parts.parts;
  return parts;
}

bool exchange_after(const FactoredPlan& plan, const std::vector<StageParts>& parts, std::size_t k) {
  if (parts[k].parts == 1) return false;  // every device computed all of it
  if (k + 1 == plan.stages.size()) return true;
  // Stage k + 1 split by the same variable digit reads only entries of its device's part.
  const TensorDigit& mine = plan.stages[k].output.front();
  const TensorDigit& next = plan.stages[k + 1].output.front();
  const bool chained = parts[k].by_major_digit && parts[k + 1].by_major_digit && !mine.post && !next.post &&
                       mine.id == next.id && mine.radix == next.radix;
  return !chained;
}

std::vector<std::string> describe_factored_team(const Abstraction& a, const FactoredPlan& plan, Team& team) {
  const std::vector<StageSplit> splits = stage_splits(plan, team);
  std::vector<std::string> lines = {
      "factored sweep: every stage's output entries split in contiguous ranges by device throughput, "
      "exchanged where the next stage needs the whole tensor (Q once per step)"};
  for (std::size_t k = 0; k < plan.stages.size(); ++k) {
    const StageSplit& split = splits[k];
    std::string line = "stage " + std::to_string(k) + " (x'" + std::to_string(plan.stages[k].dimension) +
                       "): " + std::to_string(plan.stages[k].output_size) + " entries (" +
                       format_bytes(8.0 * double(plan.stages[k].output_size)) + ")";
    if (split.parts.parts == 1) {
      line += ", not split (every device computes all: its vector digit is the major one)";
    } else {
      line += std::string(", split by ") + (split.parts.by_major_digit ? "its major digit" : "entries") + " into " +
              std::to_string(split.parts.parts) + " parts";
      for (std::size_t r = 0; r < split.by_entry.ranks.size(); ++r)
        line += ", rank " + std::to_string(r) + " [" + std::to_string(split.by_entry.ranks[r].begin) + ", " +
                std::to_string(split.by_entry.ranks[r].end) + ")";
      for (std::size_t i = 0; i < split.by_entry.devices.size(); ++i)
        line += ", rank " + std::to_string(split.by_entry.rank) + " device " + std::to_string(i) + " [" +
                std::to_string(split.by_entry.devices[i].begin) + ", " + std::to_string(split.by_entry.devices[i].end) +
                ")";
      line += split.exchange ? "; exchanged" : "; not exchanged (the next stage reads only its device's part)";
    }
    lines.push_back(line);
  }
  const Split states = team.split(a.states.size());
  for (const std::string& line : team.describe(states, "input choice, states")) lines.push_back(line);
  for (std::size_t i = 0; i < team.devices().size(); ++i)
    lines.push_back("rank " + std::to_string(states.rank) + " device " + std::to_string(i) + ": device memory " +
                    format_bytes(double(plan.device_bytes)) + " (whole tensors) of " +
                    format_bytes(double(team.devices()[i].info.global_memory)));
  lines.push_back("exchange per step: " + format_bytes(exchange_bytes_per_step(a, plan, splits)) + " (" +
                  std::to_string(plan.slices) +
                  " slice(s); stage tensors, Q, values and inputs), each device "
                  "receiving the parts it did not compute");
  return lines;
}

}  // namespace amytiss::detail
