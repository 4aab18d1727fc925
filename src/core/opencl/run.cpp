#include "opencl/run.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "amytiss/errors.hpp"
#include "amytiss/format.hpp"

namespace amytiss::detail {
namespace {

// Construction: 64 triples per work-group. Sweep (ItemPerState): 16 states per work-group, so
// that pocl's threads can balance groups of unequal cost (fixed cells are free of work):
// robot reach-avoid has 106 groups instead of 27, ~5% faster sweep than 64 (BENCHMARKS.md).
constexpr std::size_t kConstructGroup = 64, kItemGroup = 16;
// Launch sizes that keep every launch short (on the fly, and GPUs with watchdogs).
constexpr std::size_t kOnTheFlyRecordsPerLaunch = std::size_t(1) << 24;
constexpr std::size_t kGroupPerStateMaxStates = std::size_t(1) << 20;
constexpr std::size_t kMaxGroupSize = 128;

std::size_t round_up(std::size_t value, std::size_t multiple) { return (value + multiple - 1) / multiple * multiple; }

void set_argument(cl_kernel kernel, cl_uint index, std::size_t size, const void* value) {
  check(clSetKernelArg(kernel, index, size, value), "clSetKernelArg");
}

}  // namespace

RunPlan plan_run(const Abstraction& a, const Layout& layout, const DeviceInfo& device, const ComputeConfig& compute,
                 const OpenClEngineOptions& engine_options, SynthesisReport& rep, std::size_t slice_first,
                 std::size_t slice_end) {
  RunPlan plan;
  const std::size_t n_inputs = a.inputs.size();
  plan.slice_first = slice_first;
  plan.slice_end = std::min(slice_end, a.states.size());
  // The records this device stores: its slice's.
  const std::size_t n_states = plan.slice_end - plan.slice_first;
  plan.records_per_state = n_inputs * a.disturbances.size();
  // Stored when the records fit the budget, else on the fly.
  const std::size_t masses_per_state = plan.records_per_state * sizeof(float) * std::size_t(layout.mass_record);
  const std::size_t value_cells = layout.padded_size + kValueSlack;
  const std::size_t base_bytes = 2 * value_cells * sizeof(double) + a.states.size() * (1 + sizeof(cl_uint));
  const double budget = compute.memory_fraction * double(device.global_memory);
  const double stored_bytes = double(n_states) * double(plan.records_per_state) * double(layout.record_bytes());
  const std::size_t max_states_by_allocation =
      std::max<std::size_t>(1, std::size_t(device.max_allocation / masses_per_state));
  const bool fits = double(base_bytes) + stored_bytes <= budget && masses_per_state <= device.max_allocation;
  const std::string estimate = "stored transitions need " + format_bytes(stored_bytes) + ", budget " + format_bytes(budget) +
                               " (memory_fraction " + c_double_literal(compute.memory_fraction) + " of " +
                               format_bytes(double(device.global_memory)) + ")";
  switch (compute.transitions) {
    case TransitionStorage::OnTheFly:
      plan.on_the_fly = true;
      rep.transitions = "on_the_fly (requested; " + estimate + ")";
      break;
    case TransitionStorage::Stored:
      // An explicit request is honoured or refused, never silently replaced.
      if (!fits)
        throw DeviceError("compute.transitions: got stored, but the records do not fit on " + device.label() + ": " +
                          estimate + " (example: transitions: auto, or a larger memory_fraction)");
      rep.transitions = "stored (requested; " + estimate + ")";
      break;
    default:
      plan.on_the_fly = !fits;
      rep.transitions = (fits ? "stored (auto: " : "on_the_fly (auto: ") + estimate + ")";
      break;
  }
  rep.notes.push_back({NoteSeverity::Info, NoteKind::Transitions, "transitions: " + rep.transitions});

  plan.variant = engine_options.variant;
  if (plan.variant == SweepVariant::Auto)
    plan.variant = device.is_gpu() ? SweepVariant::GroupPerState : SweepVariant::ItemPerState;
  while (plan.group_size < std::min<std::size_t>(n_inputs, kMaxGroupSize)) plan.group_size *= 2;
  plan.group_size = std::min(plan.group_size, std::max<std::size_t>(1, device.max_work_group));
  rep.notes.push_back({NoteSeverity::Info, NoteKind::Sweep,
                       std::string("sweep: ") + (plan.variant == SweepVariant::GroupPerState
                                                     ? "one work-group of " + std::to_string(plan.group_size) +
                                                           " per state"
                                                     : std::string("one work-item per state"))});

  // Chunks of states: bounded by the allocation limit (stored) and by a launch size that keeps
  // every launch short.
  std::size_t states_per_chunk =
      plan.on_the_fly ? std::max<std::size_t>(1, kOnTheFlyRecordsPerLaunch / plan.records_per_state)
                      : max_states_by_allocation;
  if (plan.variant == SweepVariant::GroupPerState)
    states_per_chunk = std::min(states_per_chunk, kGroupPerStateMaxStates);
  if (engine_options.max_states_per_chunk)
    states_per_chunk = std::min(states_per_chunk, engine_options.max_states_per_chunk);
  plan.states_per_chunk = std::max<std::size_t>(1, std::min(states_per_chunk, n_states));
  return plan;
}

RunBuffers allocate_buffers(const Abstraction& a, const Layout& layout, const RunPlan& plan, cl_context context,
                            SynthesisReport& rep) {
  RunBuffers buffers;
  const std::size_t n_states = a.states.size();
  const std::size_t value_cells = layout.padded_size + kValueSlack;
  auto make_buffer = [&](cl_mem_flags flags, std::size_t bytes, void* host) {
    cl_int error = CL_SUCCESS;
    Buffer buffer(clCreateBuffer(context, flags, std::max<std::size_t>(bytes, 4), host, &error));
    check(error, "clCreateBuffer");
    buffers.device_bytes += bytes;
    return buffer;
  };
  std::vector<cl_uchar> roles(n_states);
  buffers.terminal.assign(value_cells, 0.0);
  buffers.padded_index.resize(n_states);
  for (std::size_t x = 0; x < n_states; ++x) {
    roles[x] = static_cast<cl_uchar>(a.roles[x]);
    buffers.free_states += a.roles[x] == CellRole::Free;
    buffers.padded_index[x] = layout.padded_offset(a.states, x);
    buffers.terminal[buffers.padded_index[x]] = a.terminal_value(a.roles[x]);
  }
  buffers.roles = make_buffer(CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, n_states, roles.data());
  for (Buffer& values : buffers.values)
    values = make_buffer(CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, value_cells * sizeof(double),
                         buffers.terminal.data());
  buffers.best_input = make_buffer(CL_MEM_READ_WRITE, n_states * sizeof(cl_uint), nullptr);
  for (std::size_t first = plan.slice_first; first < plan.slice_end; first += plan.states_per_chunk) {
    Chunk chunk;
    chunk.first = first;
    chunk.count = std::min(plan.states_per_chunk, plan.slice_end - first);
    const std::size_t records = plan.on_the_fly ? 1 : chunk.count * plan.records_per_state;
    chunk.starts = make_buffer(CL_MEM_READ_WRITE, records * sizeof(cl_uint), nullptr);
    chunk.masses = make_buffer(CL_MEM_READ_WRITE, records * sizeof(float) * std::size_t(layout.mass_record), nullptr);
    buffers.chunks.push_back(std::move(chunk));
  }
  if (buffers.chunks.size() > 1)
    rep.notes.push_back({NoteSeverity::Info, NoteKind::Chunking,
                         "split into " + std::to_string(buffers.chunks.size()) + " chunks of up to " +
                             std::to_string(plan.states_per_chunk) + " states"});
  rep.device_bytes = buffers.device_bytes;
  rep.notes.push_back({NoteSeverity::Info, NoteKind::DeviceMemory, "device memory: " + format_bytes(double(buffers.device_bytes))});
  return buffers;
}

void construct_transitions(cl_command_queue queue, cl_kernel construct, const RunPlan& plan, RunBuffers& buffers,
                           bool wait) {
  for (Chunk& chunk : buffers.chunks) {
    const cl_ulong triple_begin = cl_ulong(chunk.first) * plan.records_per_state;
    const cl_ulong triple_count = cl_ulong(chunk.count) * plan.records_per_state;
    set_argument(construct, 0, sizeof(cl_ulong), &triple_begin);
    set_argument(construct, 1, sizeof(cl_ulong), &triple_count);
    set_argument(construct, 2, sizeof(cl_mem), &chunk.starts.handle);
    set_argument(construct, 3, sizeof(cl_mem), &chunk.masses.handle);
    const std::size_t global = round_up(std::size_t(triple_count), kConstructGroup);
    check(clEnqueueNDRangeKernel(queue, construct, 1, nullptr, &global, &kConstructGroup, 0, nullptr, nullptr),
          "clEnqueueNDRangeKernel(construct)");
  }
  if (wait) check(clFinish(queue), "clFinish(construct)");
}

void enqueue_sweep(cl_command_queue queue, cl_kernel sweep, const RunPlan& plan, RunBuffers& buffers, int current) {
  for (Chunk& chunk : buffers.chunks) {
    const cl_uint state_begin = cl_uint(chunk.first), state_count = cl_uint(chunk.count);
    set_argument(sweep, 0, sizeof(cl_mem), &buffers.values[current].handle);
    set_argument(sweep, 1, sizeof(cl_mem), &buffers.values[1 - current].handle);
    set_argument(sweep, 2, sizeof(cl_mem), &buffers.best_input.handle);
    set_argument(sweep, 3, sizeof(cl_mem), &buffers.roles.handle);
    set_argument(sweep, 4, sizeof(cl_uint), &state_begin);
    set_argument(sweep, 5, sizeof(cl_uint), &state_count);
    set_argument(sweep, 6, sizeof(cl_mem), &chunk.starts.handle);
    set_argument(sweep, 7, sizeof(cl_mem), &chunk.masses.handle);
    const bool groups = plan.variant == SweepVariant::GroupPerState;
    const std::size_t local = groups ? plan.group_size : kItemGroup;
    const std::size_t global = groups ? chunk.count * plan.group_size : round_up(chunk.count, kItemGroup);
    check(clEnqueueNDRangeKernel(queue, sweep, 1, nullptr, &global, &local, 0, nullptr, nullptr),
          "clEnqueueNDRangeKernel(synthesize)");
  }
}

void sweep_step(cl_command_queue queue, cl_kernel sweep, const RunPlan& plan, RunBuffers& buffers, int current,
                std::uint32_t* input_index, std::vector<double>& padded_values) {
  enqueue_sweep(queue, sweep, plan, buffers, current);
  const std::size_t n_states = buffers.padded_index.size();
  check(clEnqueueReadBuffer(queue, buffers.best_input.get(), CL_FALSE, 0, n_states * sizeof(cl_uint), input_index, 0,
                            nullptr, nullptr),
        "clEnqueueReadBuffer");
  check(clEnqueueReadBuffer(queue, buffers.values[1 - current].get(), CL_FALSE, 0,
                            padded_values.size() * sizeof(double), padded_values.data(), 0, nullptr, nullptr),
        "clEnqueueReadBuffer");
  check(clFinish(queue), "clFinish(synthesize)");
}

void unpad(double* out, const std::vector<std::size_t>& padded_index, const double* padded) {
  for (std::size_t x = 0; x < padded_index.size(); ++x) out[x] = padded[padded_index[x]];
}

}  // namespace amytiss::detail
