// Scale-out devices and exchanges: which devices compute.devices names (sub-devices made with
// clCreateSubDevices), the weighted split, and the exchange of parts through the host and the
// communicator.
#include "scale_out/team.hpp"

#include <algorithm>

#include "amytiss/errors.hpp"
#include "amytiss/stopwatch.hpp"
#include "opencl/device_peak.hpp"

namespace amytiss::detail {
namespace {

// The device split into equal sub-devices of `units` compute units each.
std::vector<TeamDevice> split_device(const DeviceInfo& parent, unsigned units, const std::string& text) {
  const cl_device_partition_property properties[] = {CL_DEVICE_PARTITION_EQUALLY, cl_device_partition_property(units),
                                                     0};
  cl_uint count = 0;
  cl_int error = clCreateSubDevices(parent.device, properties, 0, nullptr, &count);
  if (error != CL_SUCCESS || count == 0)
    throw DeviceError("compute.devices: entry '" + text + "': " + parent.label() + " cannot be split into parts of " +
                      std::to_string(units) + " compute units (clCreateSubDevices: " + cl_error_name(error) +
                      "; example: cpu:0/1)");
  std::vector<cl_device_id> ids(count);
  check(clCreateSubDevices(parent.device, properties, count, ids.data(), nullptr), "clCreateSubDevices");
  // The sub-devices are not released: pocl's worker threads may still release the last events of
  // a context after clReleaseContext returns, and a released sub-device then crashes them (seen
  // in one run of eight). A process makes them once per synthesis.
  std::vector<TeamDevice> parts;
  for (cl_uint k = 0; k < count; ++k) {
    TeamDevice part;
    part.info = parent;
    part.info.device = ids[k];
    clGetDeviceInfo(ids[k], CL_DEVICE_MAX_COMPUTE_UNITS, sizeof(cl_uint), &part.info.compute_units, nullptr);
    part.info.device_name += " (part " + std::to_string(k + 1) + " of " + std::to_string(count) + ")";
    parts.push_back(std::move(part));
  }
  return parts;
}

}  // namespace

std::vector<TeamDevice> open_team_devices(const ComputeConfig& compute, std::vector<EngineNote>& notes) {
  std::vector<TeamDevice> team;
  if (compute.devices.empty()) {
    team.push_back({choose_device(compute, notes), {}, 1});
  } else {
    const std::vector<DeviceInfo> usable = with_double_precision(enumerate_devices(), notes);
    if (compute.devices.front() == "all") {
      if (usable.empty()) throw DeviceError("compute.devices all: no OpenCL device with double precision found");
      for (const DeviceInfo& info : usable) team.push_back({info, {}, 1});
    } else {
      for (const std::string& text : compute.devices) {
        const std::optional<DeviceSelector> selector = parse_device_selector(text);
        const DeviceInfo info = select_device(usable, *selector, text);  // validate() accepted the text
        if (selector->units_per_part == 0) {
          team.push_back({info, {}, 1});
        } else {
          for (TeamDevice& part : split_device(info, selector->units_per_part, text)) team.push_back(std::move(part));
        }
      }
    }
  }
  for (TeamDevice& member : team) {
    const DevicePeak peak =
        double_fma_peak(member.info.is_gpu(), member.info.is_cpu(), member.info.label(), member.info.compute_units,
                        member.info.max_clock_mhz, member.info.native_double_width);
    member.weight =
        peak.multiply_adds_per_second > 0 ? peak.multiply_adds_per_second : double(member.info.compute_units);
    member.session = open_session(member.info);
  }
  return team;
}

Team::Team(std::vector<TeamDevice> devices, Communicator& communicator)
    : devices_(std::move(devices)), communicator_(communicator) {
  double weight = 0;
  for (const TeamDevice& device : devices_) weight += device.weight;
  rank_weights_ = communicator_.allgather_value(weight);
  for (double count : communicator_.allgather_value(double(devices_.size()))) total_devices_ += std::size_t(count);
}

Split Team::split(std::uint64_t total) const {
  Split split;
  split.rank = communicator_.rank();
  split.ranks = split_by_weight(total, rank_weights_);
  std::vector<double> weights;
  for (const TeamDevice& device : devices_) weights.push_back(device.weight);
  const Range mine = split.ranks[std::size_t(split.rank)];
  for (Range range : split_by_weight(mine.size(), weights))
    split.devices.push_back({mine.begin + range.begin, mine.begin + range.end});
  return split;
}

void Team::exchange(const Split& split, std::size_t element_bytes, const std::vector<cl_mem>& buffers, void* host,
                    bool write_back) {
  const auto start = SteadyClock::now();
  char* bytes = static_cast<char*>(host);
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    const Range range = split.devices[i];
    if (range.empty()) continue;
    check(clEnqueueReadBuffer(devices_[i].session.queue.get(), buffers[i], CL_FALSE, range.begin * element_bytes,
                              range.size() * element_bytes, bytes + range.begin * element_bytes, 0, nullptr, nullptr),
          "clEnqueueReadBuffer(exchange)");
  }
  for (TeamDevice& device : devices_) check(clFinish(device.session.queue.get()), "clFinish(exchange)");
  if (communicator_.size() > 1) {
    std::vector<std::size_t> offsets, counts;
    for (const Range& range : split.ranks) {
      offsets.push_back(range.begin * element_bytes);
      counts.push_back(range.size() * element_bytes);
    }
    communicator_.allgather_bytes(host, offsets, counts);
  }
  if (write_back) {
    const std::uint64_t total = split.ranks.back().end;
    for (std::size_t i = 0; i < devices_.size(); ++i) {
      const Range own = split.devices[i];
      const Range others[] = {{0, own.begin}, {own.end, total}};
      for (const Range& range : others) {
        if (range.empty()) continue;
        check(clEnqueueWriteBuffer(devices_[i].session.queue.get(), buffers[i], CL_FALSE, range.begin * element_bytes,
                                   range.size() * element_bytes, bytes + range.begin * element_bytes, 0, nullptr,
                                   nullptr),
              "clEnqueueWriteBuffer(exchange)");
      }
    }
    for (TeamDevice& device : devices_) check(clFinish(device.session.queue.get()), "clFinish(exchange)");
  }
  exchange_seconds_ += seconds_since(start);
}

std::vector<std::string> Team::describe(const Split& split, const std::string& what) const {
  std::vector<std::string> lines;
  for (std::size_t i = 0; i < devices_.size(); ++i)
    lines.push_back("rank " + std::to_string(split.rank) + " device " + std::to_string(i) + ": " +
                    devices_[i].info.label() + ", " + what + " [" + std::to_string(split.devices[i].begin) + ", " +
                    std::to_string(split.devices[i].end) + ")");
  return lines;
}

DeviceInfo Team::smallest_device() {
  DeviceInfo smallest = devices_.front().info;
  for (const TeamDevice& device : devices_) {
    smallest.global_memory = std::min(smallest.global_memory, device.info.global_memory);
    smallest.max_allocation = std::min(smallest.max_allocation, device.info.max_allocation);
  }
  auto least = [&](std::uint64_t value) {
    const std::vector<double> all = communicator_.allgather_value(double(value));
    return std::uint64_t(*std::min_element(all.begin(), all.end()));
  };
  smallest.global_memory = least(smallest.global_memory);
  smallest.max_allocation = least(smallest.max_allocation);
  return smallest;
}

std::string Team::label() const {
  std::string label;
  for (const TeamDevice& device : devices_) label += (label.empty() ? "" : " + ") + device.info.label();
  const int ranks = communicator_.size();
  return ranks > 1 ? std::to_string(ranks) + " ranks, rank " + std::to_string(communicator_.rank()) + ": " + label
                   : label;
}

void Team::report_exchange(double bytes_per_step, unsigned steps, SynthesisReport& report) const {
  report.exchange_seconds = exchange_seconds_;
  report.exchange_bytes_per_step = bytes_per_step;
  PhaseReport phase;
  phase.kind = PhaseKind::Breakdown;
  phase.name = "exchange (all steps)";
  phase.seconds = exchange_seconds_;
  phase.bytes = bytes_per_step * steps;
  report.phases.push_back(phase);
}

}  // namespace amytiss::detail
