#pragma once
// Contiguous parts of an index range, one per worker (device or rank), sized by weight
// (internal). Scale-out splits states, stage entries and value cells this way (docs/scale_out.md).
#include <cstdint>
#include <vector>

namespace amytiss::detail {

/// Indices [begin, end).
struct Range {
  std::uint64_t begin = 0, end = 0;
  std::uint64_t size() const { return end - begin; }
  bool empty() const { return end == begin; }
};

/// [0, total) in contiguous ranges, in worker order, range i of size about
/// total * weights[i] / sum(weights); every weight > 0. Ranges may be empty when total is small.
std::vector<Range> split_by_weight(std::uint64_t total, const std::vector<double>& weights);

/// Where the work of one array lies: every rank's range and this rank's devices' ranges (inside
/// its rank's range), in elements of the array.
struct Split {
  std::vector<Range> ranks;
  std::vector<Range> devices;
  int rank = 0;
  /// The same split with every boundary b mapped to map(b) (monotone, map(0) = 0).
  template <typename Map>
  Split mapped(Map map) const {
    Split out = *this;
    for (Range& range : out.ranks) range = {map(range.begin), map(range.end)};
    for (Range& range : out.devices) range = {map(range.begin), map(range.end)};
    return out;
  }
};

}  // namespace amytiss::detail
