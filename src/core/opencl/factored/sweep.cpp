// The factored sweep's run on an OpenCL device: mass tables (construction), then per time step
// and slice one launch per elimination stage, and the input choice from Q.
#include <algorithm>
#include <chrono>
#include <numeric>
#include <string>
#include <vector>

#include "amytiss/errors.hpp"
#include "opencl/factored/program.hpp"
#include "opencl/factored/tables.hpp"
#include "host/interval_iteration.hpp"
#include "opencl/program_cache.hpp"
#include "opencl/run.hpp"

namespace amytiss::detail {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace

// Every tuple of the contracted dimension's table occurs output_size / tuples times per slice,
// with its kept cells.
double stage_multiply_adds(const FactoredStage& stage, const MassTable& table, std::size_t slices) {
  const double kept = std::accumulate(table.count.begin(), table.count.end(), 0.0);
  return double(stage.output_size) * double(slices) / double(table.count.size()) * kept;
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

FactoredKernels build_factored_kernels(const Abstraction& a, const FactoredPlan& plan, const DeviceInfo& device,
                                       cl_context context, const std::string& cache_dir, bool entry_per_item,
                                       std::vector<EngineNote>& notes) {
  FactoredKernels kernels;
  kernels.shape = stage_shape_for(entry_per_item ? 1 : device.native_double_width);
  notes.push_back({NoteSeverity::Info, NoteKind::Sweep,
                   std::string("factored stages: ") +
                       (kernels.shape.row_per_item ? "a row of entries per work-item in double vectors (SIMD device)"
                                                   : "one entry per work-item, neighbours contiguous (SIMT device)")});
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
                                          const std::vector<MassTable>& tables, cl_context context) {
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
  buffers.q = make_buffer(CL_MEM_READ_WRITE, plan.q_size * sizeof(double), nullptr);
  if (plan.stages.size() > 1)
    for (Buffer& tensor : buffers.stage_tensors)
      tensor = make_buffer(CL_MEM_READ_WRITE, (plan.largest_stage_tensor + kTensorSlack) * sizeof(double), nullptr);
  return buffers;
}

Policy run_factored_sweep(const Abstraction& a, const FactoredPlan& plan, const FactoredRunContext& run,
                          SynthesisReport& report) {
  const std::size_t n_states = a.states.size();

  // --- kernel build
  auto phase_start = Clock::now();
  FactoredKernels kernels = build_factored_kernels(a, plan, *run.device, run.context, run.kernel_cache_dir,
                                                   run.entry_per_item, report.notes);
  const StageShape shape = kernels.shape;
  std::vector<Kernel>& stage_kernels = kernels.stages;
  Kernel& choose = kernels.choose;
  report.phases.push_back({"kernel build", seconds_since(phase_start), 0, 0});
  if (run.progress) run.progress(Phase::Setup, 0, -1);

  // --- construction: the kept masses of every dimension, once
  phase_start = Clock::now();
  const std::vector<MassTable> tables = factored_mass_tables(a, plan);
  FactoredBuffers buffers = allocate_factored_buffers(a, plan, tables, run.context);
  const std::vector<DeviceTable>& device_tables = buffers.tables;
  Buffer& roles_buffer = buffers.roles;
  Buffer* values = buffers.values;
  Buffer& best_input = buffers.best_input;
  Buffer& q = buffers.q;
  Buffer* stage_tensors = buffers.stage_tensors;
  const std::vector<double> terminal = factored_terminal_values(a);
  report.device_bytes = buffers.device_bytes;
  report.notes.push_back({NoteSeverity::Info, NoteKind::DeviceMemory,
                          "device memory: " + std::to_string(buffers.device_bytes / 1048576) + " MiB"});
  const double construction_seconds = seconds_since(phase_start);
  report.phases.push_back({"construction", construction_seconds,
                           double(a.pairs()) / std::max(construction_seconds, 1e-9), 0});
  if (run.progress) run.progress(Phase::Construction, 0, -1);

  std::vector<double> stage_seconds(plan.stages.size() + 1, 0.0), stage_macs(plan.stages.size() + 1, 0.0);
  // Operand bytes: a value (double) per multiply-add, an entry stored per output; the input
  // choice loads Q and stores a value and an input per state.
  std::vector<double> stage_bytes(plan.stages.size() + 1, 0.0);
  double multiply_adds_per_step = 0, bytes_per_step = 0;
  for (std::size_t k = 0; k < plan.stages.size(); ++k) {
    stage_macs[k] = stage_multiply_adds(plan.stages[k], tables[plan.stages[k].dimension], plan.slices);
    stage_bytes[k] = 8.0 * (stage_macs[k] + double(plan.stages[k].output_size) * double(plan.slices));
    multiply_adds_per_step += stage_macs[k];
    bytes_per_step += stage_bytes[k];
  }
  stage_bytes.back() = 8.0 * double(plan.q_size) + 12.0 * double(n_states);
  bytes_per_step += stage_bytes.back();
  const std::size_t group = std::min(kFactoredGroupSize, std::max<std::size_t>(1, run.device->max_work_group));
  auto launch = [&](cl_kernel kernel, std::size_t entries, std::size_t timing_slot) {
    const auto launch_start = Clock::now();
    for (std::size_t offset = 0; offset < entries; offset += kFactoredMaxLaunchItems) {
      const std::size_t count = std::min(kFactoredMaxLaunchItems, entries - offset);
      const std::size_t global = (count + group - 1) / group * group;
      check(clEnqueueNDRangeKernel(run.queue, kernel, 1, &offset, &global, &group, 0, nullptr, nullptr),
            "clEnqueueNDRangeKernel(factored sweep)");
    }
    if (run.profile) {
      check(clFinish(run.queue), "clFinish(factored sweep)");
      stage_seconds[timing_slot] += seconds_since(launch_start);
    }
  };

  // --- synthesis, V_{T_d} -> V_0
  Policy policy = empty_policy(a, run.device->label());
  std::copy(terminal.begin(), terminal.begin() + std::ptrdiff_t(n_states),
            policy.values.begin() + std::ptrdiff_t(a.horizon * n_states));

  const std::size_t last_stage = plan.stages.size() - 1;
  int current = 0;
  // One Bellman step from values[current] (uploaded from host_in unless it is null: the previous
  // step's output is already there) into values[1 - current], read back into host_out and chosen.
  auto bellman = [&](const double* host_in, double* host_out, std::uint32_t* chosen) {
    if (host_in)
      check(clEnqueueWriteBuffer(run.queue, values[current].get(), CL_FALSE, 0, n_states * sizeof(double), host_in, 0,
                                 nullptr, nullptr),
            "clEnqueueWriteBuffer");
    for (std::size_t slice = 0; slice < plan.slices; ++slice) {
      for (std::size_t k = 0; k < plan.stages.size(); ++k) {
        const FactoredStage& stage = plan.stages[k];
        const DeviceTable& table = device_tables[stage.dimension];
        const bool last = k == last_stage;
        cl_mem in = k == 0 ? values[current].get() : stage_tensors[(k - 1) % 2].get();
        cl_mem out = last ? q.get() : stage_tensors[k % 2].get();
        // The first stage reads the slice out of V; the last contracts the slice's cells only.
        cl_kernel kernel = stage_kernels[k].get();
        set_stage_arguments(kernel, in, out, table, stage_placement(a, plan, k, slice));
        launch(kernel, stage_work_items(stage, shape), k);
      }
    }
    cl_kernel kernel = choose.get();
    check(clSetKernelArg(kernel, 0, sizeof(cl_mem), &q.handle), "clSetKernelArg");
    check(clSetKernelArg(kernel, 1, sizeof(cl_mem), &values[1 - current].handle), "clSetKernelArg");
    check(clSetKernelArg(kernel, 2, sizeof(cl_mem), &best_input.handle), "clSetKernelArg");
    check(clSetKernelArg(kernel, 3, sizeof(cl_mem), &roles_buffer.handle), "clSetKernelArg");
    launch(kernel, n_states, plan.stages.size());
    check(clEnqueueReadBuffer(run.queue, best_input.get(), CL_FALSE, 0, n_states * sizeof(cl_uint),
                              chosen, 0, nullptr, nullptr),
          "clEnqueueReadBuffer");
    check(clEnqueueReadBuffer(run.queue, values[1 - current].get(), CL_FALSE, 0, n_states * sizeof(double),
                              host_out, 0, nullptr, nullptr),
          "clEnqueueReadBuffer");
    check(clFinish(run.queue), "clFinish(factored sweep)");
    current = 1 - current;
  };
  if (a.unbounded) {
    FunctionStep step(bellman, multiply_adds_per_step, bytes_per_step);
    ReferenceStep host(a);
    UnboundedRun unbounded{run.device->label(), [&](unsigned iterations, double) {
                             if (run.progress) run.progress(Phase::Synthesis, iterations, -1);
                           }};
    return solve_unbounded(a, step, host, unbounded, report);
  }
  const auto synthesis_start = Clock::now();
  for (unsigned step = a.horizon; step-- > 0;) {
    phase_start = Clock::now();
    bellman(nullptr, policy.values.data() + std::size_t(step) * n_states,
            policy.input_index.data() + std::size_t(step) * n_states);
    const double seconds = seconds_since(phase_start);
    report.phases.push_back({"step " + std::to_string(step), seconds, double(a.pairs()) / std::max(seconds, 1e-9),
                             multiply_adds_per_step, bytes_per_step});
    const unsigned done = a.horizon - step;
    if (run.progress)
      run.progress(done == a.horizon ? Phase::Done : Phase::Synthesis, done,
                   seconds_since(synthesis_start) / done * (a.horizon - done));
  }
  if (run.profile) {
    for (std::size_t k = 0; k <= plan.stages.size(); ++k) {
      const std::string name = k < plan.stages.size()
                                   ? "stage " + std::to_string(k) + " (x'" + std::to_string(plan.stages[k].dimension) +
                                         ", all steps)"
                                   : "input choice (all steps)";
      report.phases.push_back({name, stage_seconds[k], 0, stage_macs[k] * a.horizon, stage_bytes[k] * a.horizon, true});
    }
  }
  return policy;
}

}  // namespace amytiss::detail
