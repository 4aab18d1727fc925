// The factored sweep's device pieces that one device and a team share.
#include "opencl/factored/device_parts.hpp"

#include <algorithm>
#include <optional>
#include <utility>

#include "amytiss/format.hpp"
#include "opencl/factored/fused_stage.hpp"
#include "opencl/factored/row_kernel.hpp"
#include "opencl/factored/tables.hpp"
#include "opencl/program_cache.hpp"

namespace amytiss::detail {

StageWork stage_work(const Abstraction& a, const FactoredPlan& plan, std::size_t k, const MassTable& table,
                     const StageShape& shape) {
  const FactoredStage& stage = plan.stages[k];
  const std::optional<std::size_t> paired = paired_digit(stage, shape);
  const std::uint64_t group = rows_per_item(stage, shape);
  const std::size_t tuples = table.count.size();
  // Per slice, every tuple's window clipped to the block the input holds, as the kernels clip it.
  auto window = [&](std::size_t tuple, const StagePlacement& placement) {
    const long long lo = std::max<long long>(table.first[tuple], placement.lo);
    const long long end = std::min<long long>(table.first[tuple] + table.count[tuple], placement.hi);
    const long long hi = std::max(lo, end);
    return std::pair<long long, long long>{lo, hi};
  };
  double cells = 0, loads = 0;
  for (std::size_t slice = 0; slice < plan.slices; ++slice) {
    const StagePlacement placement = stage_placement(a, plan, k, slice);
    for (std::size_t tuple = 0; tuple < tuples; ++tuple) {
      const auto [lo_a, hi_a] = window(tuple, placement);
      cells += double(hi_a - lo_a);
      if (!paired) {
        loads += double(hi_a - lo_a);
        continue;
      }
      const std::uint64_t stride = stage.tuple_stride[*paired], radix = stage.output[*paired].radix;
      const std::uint64_t value = tuple / stride % radix;
      if (value % group != 0) continue;  // counted with its group's first row
      long long lo = lo_a, hi = hi_a, apart = hi_a - lo_a;
      for (std::uint64_t i = 1; i < std::min(group, radix - value); ++i) {
        const auto [lo_i, hi_i] = window(tuple + i * stride, placement);
        lo = std::min(lo, lo_i);
        hi = std::max(hi, hi_i);
        apart += hi_i - lo_i;
      }
      // One row alone never shares: 4 x cells > 3 x cells (or both are 0).
      loads += double(rows_share_pass(hi - lo, apart) ? hi - lo : apart);
    }
  }
  // Every tuple occurs output_entries / tuples times in a slice's output.
  const double uses = double(stage.output_entries) / double(tuples);
  StageWork work;
  work.multiply_adds = uses * cells;
  work.value_loads = uses * loads;
  // The input is read at most once, and at most as often as the kernels load values (windows that
  // cover part of the contracted cells leave the rest unread).
  const double input = k == 0 ? double(a.states.size()) / double(plan.slices) : double(plan.stages[k - 1].output_size);
  work.memory_bytes = 8.0 * (std::min(double(plan.slices) * input, work.value_loads) +
                             double(plan.slices) * double(stage.output_size));
  return work;
}

StagePlacement stage_placement(const Abstraction& a, const FactoredPlan& plan, std::size_t k, std::size_t slice) {
  // V's stride of the sliced dimension (row-major over the state grid).
  std::uint64_t sliced_stride = 1;
  for (std::size_t r = plan.order.back() + 1; r < a.states.dims(); ++r) sliced_stride *= a.states.count(r);
  const bool last = k + 1 == plan.stages.size();
  const cl_uint block_first = cl_uint(slice * plan.slice_cells);
  StagePlacement placement;
  placement.in_offset = (k == 0 && !last) ? cl_ulong(block_first) * sliced_stride : 0;
  placement.lo = last ? block_first : 0;
  placement.hi = last ? cl_uint(block_first + plan.slice_cells) : cl_uint(a.states.count(plan.stages[k].dimension));
  placement.accumulate = last && slice > 0;
  return placement;
}

void set_stage_arguments(cl_kernel kernel, cl_mem in, cl_mem out, const DeviceTable& table,
                         const StagePlacement& placement) {
  check(clSetKernelArg(kernel, 0, sizeof(cl_mem), &in), "clSetKernelArg");
  check(clSetKernelArg(kernel, 1, sizeof(cl_mem), &out), "clSetKernelArg");
  check(clSetKernelArg(kernel, 2, sizeof(cl_mem), &table.first.handle), "clSetKernelArg");
  check(clSetKernelArg(kernel, 3, sizeof(cl_mem), &table.count.handle), "clSetKernelArg");
  check(clSetKernelArg(kernel, 4, sizeof(cl_mem), &table.masses.handle), "clSetKernelArg");
  check(clSetKernelArg(kernel, 5, sizeof(cl_ulong), &placement.in_offset), "clSetKernelArg");
  check(clSetKernelArg(kernel, 6, sizeof(cl_uint), &placement.lo), "clSetKernelArg");
  check(clSetKernelArg(kernel, 7, sizeof(cl_uint), &placement.hi), "clSetKernelArg");
  check(clSetKernelArg(kernel, 8, sizeof(cl_uint), &placement.accumulate), "clSetKernelArg");
}

void set_fused_arguments(cl_kernel kernel, const DeviceTable& next_table) {
  check(clSetKernelArg(kernel, 9, sizeof(cl_mem), &next_table.first.handle), "clSetKernelArg");
  check(clSetKernelArg(kernel, 10, sizeof(cl_mem), &next_table.count.handle), "clSetKernelArg");
  check(clSetKernelArg(kernel, 11, sizeof(cl_mem), &next_table.masses.handle), "clSetKernelArg");
}

StageShape factored_stage_shape(const DeviceInfo& device, const OpenClEngineOptions& options) {
  const unsigned width = options.factored_vector_width;
  StageShape shape = stage_shape_for(width > 0 ? width : device.native_double_width);
  if (options.factored_stream_bytes) shape.stream_output_bytes = *options.factored_stream_bytes;
  return shape;
}

FactoredKernels build_factored_kernels(const Abstraction& a, const FactoredPlan& plan, const DeviceInfo& device,
                                       cl_context context, const std::string& cache_dir, const StageShape& shape,
                                       std::vector<EngineNote>& notes) {
  FactoredKernels kernels;
  kernels.shape = shape;
  notes.push_back({NoteSeverity::Info, NoteKind::Sweep,
                   std::string("factored stages: ") +
                       (kernels.shape.row_per_item ? "a row of entries per work-item in double vectors (SIMD device)"
                                                   : "one entry per work-item, neighbours contiguous (SIMT device)")});
  for (std::size_t k = 0; k < plan.stages.size(); ++k) {
    if (!fuses_next(plan, k, shape)) continue;
    const std::string between = format_bytes(8.0 * double(plan.stages[k].output_size));
    notes.push_back({NoteSeverity::Info, NoteKind::Sweep,
                     "factored stages " + std::to_string(k) + " and " + std::to_string(k + 1) + " fused: x'" +
                         std::to_string(plan.stages[k].dimension) + "'s lines of rows contracted over x'" +
                         std::to_string(plan.stages[k + 1].dimension) + " into Q by the same work-item (" + between +
                         " a step neither written nor read)"});
  }
  kernels.program = build_program(context, device, factored_program_source(a, plan, kernels.shape), cache_dir, notes);
  for (std::size_t k = 0; k < plan.stages.size(); ++k)
    kernels.stages.push_back(create_kernel(kernels.program.get(), ("stage" + std::to_string(k)).c_str()));
  kernels.choose = create_kernel(kernels.program.get(), "choose_inputs");
  return kernels;
}

std::vector<double> factored_terminal_values(const Abstraction& a) {
  std::vector<double> terminal(a.states.size() + kTensorSlack, 0.0);
  for (std::size_t x = 0; x < a.states.size(); ++x) terminal[x] = a.terminal_value(a.roles[x]);
  return terminal;
}

FactoredBuffers allocate_factored_buffers(const Abstraction& a, const FactoredPlan& plan,
                                          const std::vector<MassTable>& tables, cl_context context, bool cpu_device,
                                          const StageShape& shape) {
  const std::size_t n_states = a.states.size();
  FactoredBuffers buffers;
  cl_int error = CL_SUCCESS;
  auto make_buffer = [&](cl_mem_flags flags, std::size_t bytes, const void* host) {
    Buffer buffer(clCreateBuffer(context, flags, std::max<std::size_t>(bytes, 8), const_cast<void*>(host), &error));
    check(error, "clCreateBuffer");
    buffers.device_bytes += bytes;
    return buffer;
  };
  for (const MassTable& table : tables) {
    const cl_mem_flags flags = CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR;
    buffers.tables.push_back({make_buffer(flags, table.first.size() * sizeof(cl_uint), table.first.data()),
                              make_buffer(flags, table.count.size() * sizeof(cl_uint), table.count.data()),
                              make_buffer(flags, table.masses.size() * sizeof(double), table.masses.data())});
  }
  std::vector<cl_uchar> roles(n_states);
  for (std::size_t x = 0; x < n_states; ++x) roles[x] = static_cast<cl_uchar>(a.roles[x]);
  const std::vector<double> terminal = factored_terminal_values(a);
  buffers.roles = make_buffer(CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, n_states, roles.data());
  for (Buffer& values : buffers.values)
    values = make_buffer(CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, terminal.size() * sizeof(double), terminal.data());
  buffers.best_input = make_buffer(CL_MEM_READ_WRITE, n_states * sizeof(cl_uint), nullptr);
  // The large ones: on a CPU device, in host blocks that the device uses as they are.
  auto make_large = [&](std::size_t bytes) {
    if (!cpu_device) return make_buffer(CL_MEM_READ_WRITE, bytes, nullptr);
    buffers.host_blocks.emplace_back(bytes);
    return make_buffer(CL_MEM_READ_WRITE | CL_MEM_USE_HOST_PTR, bytes, buffers.host_blocks.back().data());
  };
  buffers.host_blocks.reserve(3);
  buffers.q = make_large(plan.q_size * sizeof(double));
  // Stage k writes stage tensor k % 2, except the last (Q) and a stage fused with it.
  std::uint64_t written[2] = {0, 0};
  for (std::size_t k = 0; k + 1 < plan.stages.size(); ++k)
    if (!fuses_next(plan, k, shape)) written[k % 2] = std::max(written[k % 2], plan.stages[k].output_size);
  if (plan.stages.size() > 1)
    for (int t = 0; t < 2; ++t) buffers.stage_tensors[t] = make_large((written[t] + kTensorSlack) * sizeof(double));
  return buffers;
}

void launch_range(cl_command_queue queue, cl_kernel kernel, std::uint64_t first, std::uint64_t end, std::size_t group) {
  for (std::uint64_t offset = first; offset < end; offset += kFactoredMaxLaunchItems) {
    const std::size_t count = std::size_t(std::min<std::uint64_t>(kFactoredMaxLaunchItems, end - offset));
    const std::size_t global = (count + group - 1) / group * group, global_offset = std::size_t(offset);
    check(clEnqueueNDRangeKernel(queue, kernel, 1, &global_offset, &global, &group, 0, nullptr, nullptr),
          "clEnqueueNDRangeKernel(factored sweep)");
  }
}

std::size_t factored_group_size(const DeviceInfo& device) {
  return std::min(kFactoredGroupSize, std::max<std::size_t>(1, device.max_work_group));
}

void set_choose_arguments(cl_kernel kernel, FactoredBuffers& buffers, int output) {
  check(clSetKernelArg(kernel, 0, sizeof(cl_mem), &buffers.q.handle), "clSetKernelArg");
  check(clSetKernelArg(kernel, 1, sizeof(cl_mem), &buffers.values[output].handle), "clSetKernelArg");
  check(clSetKernelArg(kernel, 2, sizeof(cl_mem), &buffers.best_input.handle), "clSetKernelArg");
  check(clSetKernelArg(kernel, 3, sizeof(cl_mem), &buffers.roles.handle), "clSetKernelArg");
}

}  // namespace amytiss::detail
