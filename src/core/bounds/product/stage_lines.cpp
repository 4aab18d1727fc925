#include "bounds/product/stage_lines.hpp"

#include <algorithm>
#include <numeric>

namespace amytiss::detail {
namespace {

// An input or disturbance: lines that differ in one may hold far-apart values.
bool jumps(const TensorDigit& digit, const std::vector<FactorVariable>& variables) {
  return !digit.post && variables[digit.id].space != FactorVariable::Space::State;
}

}  // namespace

std::vector<StageWalk::Carried> StageWalk::carried_of(const FactoredStage& stage,
                                                      const std::vector<FactorVariable>& variables) {
  std::vector<Carried> carried;
  std::size_t output_stride = stage.output_size;
  for (std::size_t j = 0; j < stage.output.size(); ++j) {
    output_stride /= stage.output[j].radix;
    if (!stage.input_stride[j]) continue;
    carried.push_back({stage.output[j].radix, std::size_t(stage.input_stride[j]), output_stride,
                       std::size_t(stage.tuple_stride[j]), jumps(stage.output[j], variables)});
  }
  // Lines that differ in a state or post cell hold close values (a line is sorted from the one
  // before); lines of another input or disturbance may not: those digits count slowest. The others
  // by input stride, for the caches.
  std::stable_sort(carried.begin(), carried.end(), [](const Carried& a, const Carried& b) {
    return a.jumps != b.jumps ? b.jumps : a.input_stride < b.input_stride;
  });
  return carried;
}

StageWalk StageWalk::of(const FactoredStage& stage, const std::vector<FactorVariable>& variables) {
  StageWalk walk;
  walk.carried = carried_of(stage, variables);
  walk.free_offsets.assign(1, 0);
  walk.free_tuples.assign(1, 0);
  std::vector<std::size_t> jumps_of(1, 0);  // per combination: its input and disturbance digits, as one number
  std::size_t output_stride = stage.output_size;
  for (std::size_t j = 0; j < stage.output.size(); ++j) {
    const std::size_t radix = stage.output[j].radix;
    output_stride /= radix;
    if (stage.input_stride[j]) continue;
    const auto tuple_stride = std::size_t(stage.tuple_stride[j]);
    const bool digit_jumps = jumps(stage.output[j], variables);
    std::vector<std::size_t> offsets, tuples, jump_digits;
    for (std::size_t i = 0; i < walk.free_offsets.size(); ++i)
      for (std::size_t digit = 0; digit < radix; ++digit) {
        offsets.push_back(walk.free_offsets[i] + digit * output_stride);
        tuples.push_back(walk.free_tuples[i] + digit * tuple_stride);
        jump_digits.push_back(digit_jumps ? jumps_of[i] * radix + digit : jumps_of[i]);
      }
    walk.free_offsets.swap(offsets);
    walk.free_tuples.swap(tuples);
    jumps_of.swap(jump_digits);
  }
  walk.free_order.resize(walk.free_offsets.size());
  std::iota(walk.free_order.begin(), walk.free_order.end(), 0u);
  std::stable_sort(walk.free_order.begin(), walk.free_order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return jumps_of[a] < jumps_of[b]; });
  return walk;
}

void StageWalk::share_searches(const std::vector<std::uint32_t>& window_of, std::size_t windows) {
  for (const Carried& digit : carried)
    if (digit.tuple_stride) return;
  std::vector<std::uint32_t> search_of_window(windows, ~std::uint32_t(0));
  search_of.resize(free_tuples.size());
  for (std::size_t i = 0; i < free_tuples.size(); ++i) {
    std::uint32_t& search = search_of_window[window_of[free_tuples[i]]];
    if (search == ~std::uint32_t(0)) {
      search = std::uint32_t(searched.size());
      searched.push_back(i);
    }
    search_of[i] = search;
  }
}

void LineCursor::seek(std::size_t line) {
  input = output = tuple = 0;
  std::size_t lines_below = 1;
  for (std::size_t j = 0; j < carried.size(); ++j) {
    digits[j] = line / lines_below % carried[j].radix;
    lines_below *= carried[j].radix;
    input += digits[j] * carried[j].input_stride;
    output += digits[j] * carried[j].output_stride;
    tuple += digits[j] * carried[j].tuple_stride;
  }
}

void LineCursor::seek_input(std::size_t line_input) {
  input = line_input;
  output = tuple = 0;
  for (std::size_t j = 0; j < carried.size(); ++j) {
    digits[j] = line_input / carried[j].input_stride % carried[j].radix;
    output += digits[j] * carried[j].output_stride;
    tuple += digits[j] * carried[j].tuple_stride;
  }
}

void LineCursor::next() {
  for (std::size_t j = 0; j < carried.size(); ++j) {
    const StageWalk::Carried& digit = carried[j];
    input += digit.input_stride;
    output += digit.output_stride;
    tuple += digit.tuple_stride;
    if (++digits[j] < digit.radix) return;
    input -= digit.radix * digit.input_stride;
    output -= digit.radix * digit.output_stride;
    tuple -= digit.radix * digit.tuple_stride;
    digits[j] = 0;
  }
}

LineSearcher::LineSearcher(const StageWalk& walk, const PackedWindows& windows,
                           const std::vector<std::uint32_t>& window_of, std::size_t length, Bound bound, bool sorted,
                           VectorUnit unit)
    : walk_(walk),
      windows_(windows),
      window_of_(window_of),
      bound_(bound),
      sorted_(sorted),
      shared_(!walk.search_of.empty()),
      unit_(unit),
      searches_(walk.searches_per_line()),
      line_(length),
      ends_(searches_),
      line_windows_(searches_),
      bounds_(searches_) {}

void LineSearcher::search(std::size_t tuple_base, bool after_neighbour) {
  const std::size_t length = line_.length();
  if (tuple_base != windows_tuple_base_)  // consecutive lines mostly read the same windows
    for (std::size_t s = 0; s < searches_; ++s)
      line_windows_[s] = &windows_[window_of_[tuple_base + walk_.free_tuples[shared_ ? walk_.searched[s] : s]]];
  windows_tuple_base_ = tuple_base;
  if (sorted_) {
    line_.sort(after_neighbour);
    if (after_neighbour) {
      batch_.run(line_, line_windows_.data(), searches_, bound_, ends_.data(), bounds_.data(), unit_);
      return;
    }
    // Afresh: the first search from the median key, each other from where the previous window's
    // ended (neighbouring windows have their thresholds close by), one at a time.
    std::uint32_t start = std::uint32_t(line_.order(length / 2));
    for (std::size_t s = 0; s < searches_; ++s) {
      ends_[s] = start;
      batch_.run(line_, &line_windows_[s], 1, bound_, &ends_[s], &bounds_[s], unit_);
      start = ends_[s];
    }
    return;
  }
  // Afresh: each search from where the previous window's ended.
  std::size_t start = length / 2;
  for (std::size_t s = 0; s < searches_; ++s) {
    if (after_neighbour) start = ends_[s];
    bounds_[s] = threshold_scan(line_.keys(), *line_windows_[s], bound_, start, unit_);
    ends_[s] = std::uint32_t(start);
  }
}

}  // namespace amytiss::detail
