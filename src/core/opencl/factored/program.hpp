#pragma once
// The factored sweep's generated OpenCL program (internal): the stage kernels' shape and source.
#include <cstdint>
#include <string>

#include "amytiss/abstraction.hpp"
#include "factored/factored_plan.hpp"

namespace amytiss::detail {

/// Cells after the end of every value and stage tensor buffer: a vector stage's last chunk of a
/// row may read that far past it.
constexpr std::size_t kTensorSlack = 8;

/// Launches of the factored sweep: at most this many work-items each (watchdogs, and 32-bit
/// work-item limits of some drivers), in groups of kFactoredGroupSize (or the device's maximum).
constexpr std::size_t kFactoredMaxLaunchItems = std::size_t(1) << 30;
constexpr std::size_t kFactoredGroupSize = 64;

/// Stage outputs above this many bytes are stored past the caches by default: larger than the
/// last-level caches of the CPUs measured (32 MiB per core complex on the EPYCs), they are gone
/// from the cache by the time the next stage reads them (traffic 3-d's x'0 writes 688 MB a step).
constexpr double kStreamOutputBytes = 64.0 * 1024 * 1024;

/// How a stage with a vector digit maps to work-items. SIMD devices (CPUs: native double vector
/// width > 1) take a row of the vector digit per work-item in explicit vectors; SIMT devices
/// (GPUs: width 1) one entry per work-item with the vector digit fastest, so that neighbouring
/// work-items read neighbouring values. Same sums in the same order either way.
struct StageShape {
  bool row_per_item = true;
  /// Rows: false (the default) takes them window by window, the major output digit first;
  /// true in output order (a team that splits a stage's rows by more than the major digit).
  bool rows_in_output_order = false;
  /// Input choice: true (SIMD devices) takes a run of states per work-item in Q's order, false
  /// one state per work-item (SIMT devices, and a team, which splits the choice by states).
  bool states_in_q_order = false;
  /// Rows: a team splits the rows by the digits before the vector digit, which a work-item must
  /// then not take two at a time (each device's part is one range of work-items).
  bool split_by_team = false;
  /// The device's native double vector width (the row kernels' register budget follows it).
  unsigned native_double_width = 1;
  /// Row kernels store outputs of more bytes than this past the caches where their lines align
  /// (streams_output in opencl/factored/row_kernel.hpp); 0 streams every aligned output (tests).
  double stream_output_bytes = kStreamOutputBytes;
};
StageShape stage_shape_for(unsigned native_double_width);

/// Work-items of a stage's launch.
std::uint64_t stage_work_items(const FactoredStage& stage, const StageShape& shape);

/// Work-items of the input choice's launch.
std::uint64_t choose_work_items(const Abstraction& abstraction, const StageShape& shape);

/// OpenCL C of the plan: kernels stage0..stage{d-1} (one elimination each) and choose_inputs.
std::string factored_program_source(const Abstraction& abstraction, const FactoredPlan& plan,
                                    const StageShape& shape);

}  // namespace amytiss::detail
