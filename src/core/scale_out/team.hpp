#pragma once
// Scale-out (internal): the OpenCL devices of this process and the MPI ranks beside it, which
// split one synthesis into contiguous parts and exchange the parts after every stage or step
// (docs/scale_out.md). Each device keeps a whole copy of the arrays that the next kernel reads.
#include <CL/cl.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/synthesis_types.hpp"
#include "opencl/device.hpp"
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
  /// The least memory and allocation limit of any device of any rank, in a copy of this rank's
  /// first device: the sweep and its plan must be the same on every rank and fit every device.
  /// Collective.
  DeviceInfo smallest_device();
  /// Every device's label joined by " + ", after the ranks when there are several.
  std::string label() const;
  /// The exchanges' time and `bytes_per_step` into the report, and a breakdown phase over `steps`.
  void report_exchange(double bytes_per_step, unsigned steps, SynthesisReport& report) const;
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
