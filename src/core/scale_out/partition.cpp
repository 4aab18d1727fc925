// Weighted contiguous splits, and the compute.devices entry syntax.
#include "scale_out/partition.hpp"

#include <cassert>
#include <cctype>
#include <cmath>
#include <numeric>
#include <string>

#include "amytiss/config.hpp"

namespace amytiss {
namespace detail {

std::vector<Range> split_by_weight(std::uint64_t total, const std::vector<double>& weights) {
  assert(!weights.empty());
  const double sum = std::accumulate(weights.begin(), weights.end(), 0.0);
  std::vector<Range> ranges(weights.size());
  double cumulative = 0;
  std::uint64_t begin = 0;
  for (std::size_t i = 0; i < weights.size(); ++i) {
    assert(weights[i] > 0);
    cumulative += weights[i];
    const std::uint64_t end =
        i + 1 == weights.size()
            ? total
            : std::min<std::uint64_t>(total, std::uint64_t(std::llround(double(total) * cumulative / sum)));
    ranges[i] = {begin, std::max(begin, end)};
    begin = ranges[i].end;
  }
  return ranges;
}

}  // namespace detail

namespace {

// Digits only, at least one, no more than fit an index.
bool read_index(const std::string& text, std::size_t& value) {
  if (text.empty() || text.size() > 9) return false;
  for (char c : text)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  value = std::stoul(text);
  return true;
}

}  // namespace

std::optional<DeviceSelector> parse_device_selector(const std::string& text) {
  DeviceSelector selector;
  std::string head = text;
  if (const auto slash = text.find('/'); slash != std::string::npos) {
    std::size_t units = 0;
    if (!read_index(text.substr(slash + 1), units) || units == 0) return std::nullopt;
    selector.units_per_part = unsigned(units);
    head = text.substr(0, slash);
  }
  if (const auto colon = head.find(':'); colon != std::string::npos) {
    const std::string kind = head.substr(0, colon);
    if (kind == "gpu")
      selector.kind = DeviceSelector::Kind::Gpu;
    else if (kind == "cpu")
      selector.kind = DeviceSelector::Kind::Cpu;
    else
      return std::nullopt;
    if (!read_index(head.substr(colon + 1), selector.index)) return std::nullopt;
    return selector;
  }
  const auto dot = head.find('.');
  if (dot == std::string::npos) return std::nullopt;
  selector.kind = DeviceSelector::Kind::Index;
  if (!read_index(head.substr(0, dot), selector.platform) || !read_index(head.substr(dot + 1), selector.index))
    return std::nullopt;
  return selector;
}

}  // namespace amytiss
