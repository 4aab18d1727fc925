// The factored sweep over several devices and ranks. Every stage's output entries are split in
// contiguous ranges; each device computes its range (each entry the same FMA chain over its
// window as on one device) and the ranges are exchanged before the next stage reads them. Q is
// split the same way, and accumulates the slices in order per entry, so it is exchanged once per
// step; the input choice is split by states. The result is bit-identical to one device.
#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "amytiss/format.hpp"
#include "opencl/factored/program.hpp"
#include "opencl/factored/tables.hpp"
#include "scale_out/team.hpp"

namespace amytiss::detail {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Work-items [first, end) of a kernel, in launches of at most kFactoredMaxLaunchItems. The last group
// may run past `end`: those items compute entries of another device's range, which the exchange
// overwrites.
void launch_range(cl_command_queue queue, cl_kernel kernel, std::uint64_t first, std::uint64_t end, std::size_t group) {
  for (std::uint64_t offset = first; offset < end; offset += kFactoredMaxLaunchItems) {
    const std::size_t count = std::size_t(std::min<std::uint64_t>(kFactoredMaxLaunchItems, end - offset));
    const std::size_t global = (count + group - 1) / group * group, global_offset = std::size_t(offset);
    check(clEnqueueNDRangeKernel(queue, kernel, 1, &global_offset, &global, &group, 0, nullptr, nullptr),
          "clEnqueueNDRangeKernel(factored sweep)");
  }
}

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

}  // namespace

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

Policy run_factored_team(const Abstraction& a, const FactoredPlan& plan, Team& team,
                         const OpenClEngineOptions& engine_options, SynthesisReport& rep,
                         const TeamProgress& progress) {
  const std::size_t n_states = a.states.size();
  std::vector<TeamDevice>& devices = team.devices();
  auto phase_start = Clock::now();
  std::vector<FactoredKernels> kernels;
  for (TeamDevice& device : devices)
    kernels.push_back(build_factored_kernels(a, plan, device.info, device.session.context.get(),
                                             engine_options.kernel_cache_dir, engine_options.factored_entry_per_item,
                                             rep.notes));
  rep.phases.push_back({"kernel build", seconds_since(phase_start), 0, 0});
  if (progress) progress(Phase::Setup, 0, -1);

  phase_start = Clock::now();
  const std::vector<MassTable> tables = factored_mass_tables(a, plan);
  std::vector<FactoredBuffers> buffers;
  for (TeamDevice& device : devices) {
    buffers.push_back(allocate_factored_buffers(a, plan, tables, device.session.context.get()));
    rep.device_bytes = std::max(rep.device_bytes, buffers.back().device_bytes);
  }
  rep.phases.push_back({"construction", seconds_since(phase_start), 0, 0});
  if (progress) progress(Phase::Construction, 0, -1);

  const std::vector<StageSplit> splits = stage_splits(plan, team);
  const Split states = team.split(n_states);
  for (const std::string& line : team.describe(states, "input choice, states"))
    rep.notes.push_back({NoteSeverity::Info, NoteKind::Sweep, line});
  rep.exchange_bytes_per_step = exchange_bytes_per_step(a, plan, splits);
  double multiply_adds_per_step = 0;
  for (const FactoredStage& stage : plan.stages)
    multiply_adds_per_step += stage_multiply_adds(stage, tables[stage.dimension], plan.slices);

  Policy policy = empty_policy(a, "");
  std::vector<double> host_values = factored_terminal_values(a);
  std::copy(host_values.begin(), host_values.begin() + std::ptrdiff_t(n_states),
            policy.values.begin() + std::ptrdiff_t(std::size_t(a.horizon) * n_states));
  std::vector<double> host_tensor(plan.largest_stage_tensor), host_q(plan.q_size);
  std::vector<cl_mem> exchanged(devices.size());
  const std::size_t last_stage = plan.stages.size() - 1;
  const auto synthesis_start = Clock::now();
  int current = 0;
  for (unsigned step = a.horizon; step-- > 0;) {
    phase_start = Clock::now();
    for (std::size_t slice = 0; slice < plan.slices; ++slice) {
      for (std::size_t k = 0; k < plan.stages.size(); ++k) {
        const FactoredStage& stage = plan.stages[k];
        const bool last = k == last_stage;
        const StageSplit& split = splits[k];
        const StagePlacement placement = stage_placement(a, plan, k, slice);
        for (std::size_t i = 0; i < devices.size(); ++i) {
          FactoredBuffers& b = buffers[i];
          cl_mem in = k == 0 ? b.values[current].get() : b.stage_tensors[(k - 1) % 2].get();
          cl_mem out = last ? b.q.get() : b.stage_tensors[k % 2].get();
          exchanged[i] = out;
          cl_kernel kernel = kernels[i].stages[k].get();
          set_stage_arguments(kernel, in, out, b.tables[stage.dimension], placement);
          const std::uint64_t items = stage_work_items(stage, kernels[i].shape);
          const std::uint64_t items_per_part = items / split.parts.parts;
          const Range part = split.parts.parts == 1 ? Range{0, 1} : split.by_part.devices[i];
          const std::size_t group =
              std::min(kFactoredGroupSize, std::max<std::size_t>(1, devices[i].info.max_work_group));
          launch_range(devices[i].session.queue.get(), kernel, part.begin * items_per_part, part.end * items_per_part,
                       group);
          check(clFlush(devices[i].session.queue.get()), "clFlush(factored sweep)");
        }
        finish_all(team);
        if (!last && split.exchange) team.exchange(split.by_entry, sizeof(double), exchanged, host_tensor.data(), true);
      }
    }
    if (splits[last_stage].exchange)
      team.exchange(splits[last_stage].by_entry, sizeof(double), exchanged, host_q.data(), true);
    std::vector<cl_mem> inputs(devices.size());
    for (std::size_t i = 0; i < devices.size(); ++i) {
      FactoredBuffers& b = buffers[i];
      cl_kernel kernel = kernels[i].choose.get();
      check(clSetKernelArg(kernel, 0, sizeof(cl_mem), &b.q.handle), "clSetKernelArg");
      check(clSetKernelArg(kernel, 1, sizeof(cl_mem), &b.values[1 - current].handle), "clSetKernelArg");
      check(clSetKernelArg(kernel, 2, sizeof(cl_mem), &b.best_input.handle), "clSetKernelArg");
      check(clSetKernelArg(kernel, 3, sizeof(cl_mem), &b.roles.handle), "clSetKernelArg");
      const std::size_t group = std::min(kFactoredGroupSize, std::max<std::size_t>(1, devices[i].info.max_work_group));
      launch_range(devices[i].session.queue.get(), kernel, states.devices[i].begin, states.devices[i].end, group);
      check(clFlush(devices[i].session.queue.get()), "clFlush(factored sweep)");
      exchanged[i] = b.values[1 - current].get();
      inputs[i] = b.best_input.get();
    }
    finish_all(team);
    team.exchange(states, sizeof(double), exchanged, host_values.data(), true);
    team.exchange(states, sizeof(std::uint32_t), inputs, policy.input_index.data() + std::size_t(step) * n_states,
                  false);
    std::copy(host_values.begin(), host_values.begin() + std::ptrdiff_t(n_states),
              policy.values.begin() + std::ptrdiff_t(std::size_t(step) * n_states));
    current = 1 - current;
    report_team_step(a, step, seconds_since(phase_start), multiply_adds_per_step, seconds_since(synthesis_start), rep,
                     progress);
  }
  report_team_exchange(a, team, rep);
  return policy;
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
