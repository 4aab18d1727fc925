#pragma once
// Scale-out (internal): the OpenCL devices of this process and the MPI ranks beside it, which
// split one synthesis into contiguous parts and exchange the parts after every stage or step
// (docs/scale_out.md). Each device keeps a whole copy of the arrays that the next kernel reads.
#include <CL/cl.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "amytiss/engine.hpp"
#include "opencl/device.hpp"
#include "opencl/engine.hpp"
#include "opencl/run.hpp"
#include "scale_out/partition.hpp"

namespace amytiss::detail {

/// A device of this process with its own context and queue.
struct TeamDevice {
  DeviceInfo info;
  DeviceSession session;
  double weight = 1;  ///< share of the work: the device's estimated double multiply-add rate
};

/// The devices that compute.devices names ("all": every device with double precision; empty:
/// the one device compute.device selects), sub-devices made, sessions open. Notes each device.
/// Throws DeviceError when an entry matches no device or a device cannot be split.
std::vector<TeamDevice> open_team_devices(const ComputeConfig& compute, std::vector<EngineNote>& notes);

/// True when options ask for more than one device or rank.
bool is_scale_out(const SynthesisOptions& options);

class Team {
 public:
  /// Collective: learns every rank's total weight.
  Team(std::vector<TeamDevice> devices, Communicator& communicator);
  std::vector<TeamDevice>& devices() { return devices_; }
  Communicator& communicator() { return communicator_; }
  /// Devices of every rank together.
  std::size_t total_devices() const { return total_devices_; }
  /// [0, total) split over the ranks by their weights, and this rank's range over its devices.
  Split split(std::uint64_t total) const;
  /// Every device wrote its range of its buffer (elements of `element_bytes`, split in
  /// elements); after this, `host` (total elements) holds every range of every rank, and every
  /// device's buffer too (buffers[i] of device i; write_back false: the host only). Blocks.
  void exchange(const Split& split, std::size_t element_bytes, const std::vector<cl_mem>& buffers, void* host,
                bool write_back);
  double exchange_seconds() const { return exchange_seconds_; }
  /// Lines for the notes and --dry-run: "rank r device i: label, <what> [b, e)".
  std::vector<std::string> describe(const Split& split, const std::string& what) const;

 private:
  std::vector<TeamDevice> devices_;
  Communicator& communicator_;
  std::vector<double> rank_weights_;
  std::size_t total_devices_ = 0;
  double exchange_seconds_ = 0;
};

}  // namespace amytiss::detail

namespace amytiss::detail {

struct FactoredPlan;
struct FactoredStage;
struct Layout;
/// Called after construction and after each time step (phase, steps done, seconds left or -1).
using TeamProgress = std::function<void(Phase, unsigned, double)>;

/// The end of a team run's time step `step`: its phase in the report (seconds, pairs per second,
/// multiply-adds) and the progress (steps done, seconds left from the synthesis so far).
void report_team_step(const Abstraction& abstraction, unsigned step, double step_seconds, double multiply_adds,
                      double synthesis_seconds, SynthesisReport& report, const TeamProgress& progress);
/// After the last step: the exchanges' time and bytes as a breakdown phase.
void report_team_exchange(const Abstraction& abstraction, const Team& team, SynthesisReport& report);

/// The dense sweep over the team: device i of rank r constructs and sweeps its contiguous slice
/// of the states; after every step the new values (and inputs) of every slice go to every device.
Policy run_dense_team(const Abstraction& abstraction, Team& team, const SynthesisOptions& options,
                      const OpenClEngineOptions& engine_options, SynthesisReport& report, const TeamProgress& progress);
/// The dense sweep's split, memory per device and exchange per step, without computing.
std::vector<std::string> describe_dense_team(const Abstraction& abstraction, Team& team,
                                             const SynthesisOptions& options,
                                             const OpenClEngineOptions& engine_options);

/// How a stage's output entries are split: in `parts` contiguous parts of `entries` each. By the
/// major output digit when it has at least as many values as there are devices (then a stage
/// split by the same variable digit next reads only the part its device computed, and no
/// exchange is needed between them); else by every digit before the vector digit (a part is then
/// still a contiguous range of work-items whatever the device's stage shape); parts 1: not split,
/// every device computes the whole stage (its vector digit is the major one).
struct StageParts {
  std::uint64_t parts = 1, entries = 0;
  bool by_major_digit = false;
};
StageParts stage_parts(const FactoredStage& stage, std::size_t devices);
/// Whether the output of stage `k` must be exchanged before stage k + 1 runs.
bool exchange_after(const FactoredPlan& plan, const std::vector<StageParts>& parts, std::size_t k);

/// The factored sweep over the team: every stage's output entries (and the input choice's
/// states) split in contiguous ranges, each device's part exchanged where the next stage needs it.
Policy run_factored_team(const Abstraction& abstraction, const FactoredPlan& plan, Team& team,
                         const OpenClEngineOptions& engine_options, SynthesisReport& report,
                         const TeamProgress& progress);
/// The factored sweep's split and exchange per step, without computing.
std::vector<std::string> describe_factored_team(const Abstraction& abstraction, const FactoredPlan& plan, Team& team);

}  // namespace amytiss::detail
