#include "host/robust_factored.hpp"

#include <algorithm>
#include <atomic>
#include <stdexcept>

#include "amytiss/format.hpp"

namespace amytiss::detail {
namespace {

void require(bool invariant, const char* what) {
  if (!invariant) throw std::logic_error(std::string("robust factored sweep: ") + what);
}

// The index of each state, input and disturbance component among FactoredPlan::variables.
std::size_t variable_of(const Abstraction& a, FactorVariable::Space space, std::size_t index) {
  switch (space) {
    case FactorVariable::Space::State: return index;
    case FactorVariable::Space::Input: return a.states.dims() + index;
    default: return a.states.dims() + a.inputs.dims() + index;
  }
}

// Digit values of every variable for one (cell, input, disturbance): the multi-indices side by side.
void variable_digits(const Abstraction& a, std::size_t cell, std::size_t input, std::size_t disturbance,
                     std::vector<std::size_t>& digits) {
  digits.assign(a.states.dims() + a.inputs.dims() + a.disturbances.dims(), 0);
  a.states.multi_index(cell, digits.data());
  if (a.inputs.dims()) a.inputs.multi_index(input, digits.data() + a.states.dims());
  if (a.disturbances.dims()) a.disturbances.multi_index(disturbance, digits.data() + a.states.dims() + a.inputs.dims());
}

}  // namespace

std::optional<FactoredPlan> RobustFactoredSweep::plan(const Abstraction& a, std::string* reason) {
  std::optional<FactoredPlan> plan = plan_factored_sweep(a, kMaxBytes, kMaxBytes / 2, reason, FactoredLayout::Lines);
  if (plan && plan->slices > 1) {
    if (reason)
      *reason = "its tensors need " + std::to_string(plan->slices) + " slices within " + format_bytes(kMaxBytes) +
                " (an O-maximisation needs its whole line)";
    return std::nullopt;
  }
  return plan;
}

RobustFactoredSweep::RobustFactoredSweep(const Abstraction& a, const RowBounds& rows, const std::vector<bool>& has_rows,
                                         FactoredPlan plan, Bound bound, unsigned threads,
                                         std::shared_ptr<SweepBuffers> buffers, LineSearch search)
    : plan_(std::move(plan)), bound_(bound), threads_(threads), search_(search), buffers_(std::move(buffers)) {
  if (!buffers_) buffers_ = std::make_shared<SweepBuffers>();
  require(plan_.slices == 1 && plan_.stages.size() == a.states.dims(), "a plan of one slice, a stage per dimension");
  for (std::size_t d = 0; d < a.states.dims(); ++d) counts_.push_back(a.states.count(d));
  gather_windows(a, rows, has_rows);
  number_q(a);
  for (const FactoredStage& stage : plan_.stages) {
    walks_.push_back(walk_of(stage, plan_.variables));
    share_searches(walks_.back(), stage.dimension);
  }
}

void RobustFactoredSweep::gather_windows(const Abstraction& a, const RowBounds& rows,
                                         const std::vector<bool>& has_rows) {
  const std::size_t dims = a.states.dims();
  // Window 0 of every dimension, for the tuples no row has (they feed no row's bound: any feasible
  // window will do); the others are rows' distinct bounds, numbered as first met.
  const DimensionView nowhere{0, 0, nullptr, {0.0, 1.0}, {0.0, 0.0}};
  constexpr std::uint32_t kUnseen = ~std::uint32_t(0);
  std::vector<std::vector<char>> found(dims);
  std::vector<std::vector<DimensionView>> windows(dims, {nowhere});
  std::vector<std::vector<std::uint32_t>> window_of_bounds(dims);
  window_of_.assign(dims, {});
  for (std::size_t d = 0; d < dims; ++d) {
    std::size_t tuples = 1;
    for (std::size_t v : plan_.reads[d]) tuples *= plan_.variables[v].count;
    window_of_[d].assign(tuples, 0);
    found[d].assign(tuples, 0);
    window_of_bounds[d].assign(rows.distinct_bounds(d), kUnseen);
  }
  std::vector<std::size_t> digits;
  for (std::size_t cell = 0; cell < has_rows.size(); ++cell) {
    if (!has_rows[cell]) continue;
    for (std::size_t input = 0; input < a.inputs.size(); ++input)
      for (std::size_t disturbance = 0; disturbance < a.disturbances.size(); ++disturbance) {
        variable_digits(a, cell, input, disturbance, digits);
        const std::size_t row = rows.row(cell, input, disturbance);
        for (std::size_t d = 0; d < dims; ++d) {
          std::size_t tuple = 0;
          for (std::size_t v : plan_.reads[d]) tuple = tuple * plan_.variables[v].count + digits[v];
          if (found[d][tuple]) continue;
          found[d][tuple] = 1;
          const std::uint32_t bounds = rows.bounds_index(row, d);
          if (window_of_bounds[d][bounds] == kUnseen) {
            window_of_bounds[d][bounds] = std::uint32_t(windows[d].size());
            windows[d].push_back(rows.distinct(d, bounds));
          }
          window_of_[d][tuple] = window_of_bounds[d][bounds];
        }
      }
  }
  for (std::size_t d = 0; d < dims; ++d) packed_.emplace_back(windows[d]);
}

void RobustFactoredSweep::number_q(const Abstraction& a) {
  auto offsets = [&](const Grid& grid, FactorVariable::Space space, std::vector<std::size_t>& out) {
    out.assign(grid.size(), 0);
    std::vector<std::size_t> multi(grid.dims());
    for (std::size_t flat = 0; flat < grid.size(); ++flat) {
      if (grid.dims()) grid.multi_index(flat, multi.data());
      for (std::size_t j = 0; j < grid.dims(); ++j)
        out[flat] += multi[j] * std::size_t(plan_.q_stride[variable_of(a, space, j)]);
    }
  };
  offsets(a.states, FactorVariable::Space::State, cell_offset_);
  offsets(a.inputs, FactorVariable::Space::Input, input_offset_);
  offsets(a.disturbances, FactorVariable::Space::Disturbance, disturbance_offset_);
}

void RobustFactoredSweep::prepare(const double* values) {
  const double* in = values;
  std::size_t in_size = 1;
  for (std::size_t count : counts_) in_size *= count;
  q_.resize(plan_.stages.back().output_size);
  for (std::size_t k = 0; k < plan_.stages.size(); ++k) {
    const std::size_t out_size = plan_.stages[k].output_size;
    double* out = k + 1 == plan_.stages.size() ? q_.data() : buffers_->stage_tensors[k % 2].reserve(out_size);
    run_stage(k, in, in_size, out);
    in = out;
    in_size = out_size;
  }
}

RobustFactoredSweep::StageWalk RobustFactoredSweep::walk_of(const FactoredStage& stage,
                                                             const std::vector<FactorVariable>& variables) {
  StageWalk walk;
  walk.free_offsets.assign(1, 0);
  walk.free_tuples.assign(1, 0);
  std::size_t output_stride = stage.output_size;
  for (std::size_t j = 0; j < stage.output.size(); ++j) {
    const std::size_t radix = stage.output[j].radix;
    output_stride /= radix;
    const auto tuple_stride = std::size_t(stage.tuple_stride[j]);
    if (stage.input_stride[j]) {
      const TensorDigit& digit = stage.output[j];
      const bool jumps = !digit.post && variables[digit.id].space != FactorVariable::Space::State;
      walk.carried.push_back({radix, std::size_t(stage.input_stride[j]), output_stride, tuple_stride, jumps});
      continue;
    }
    std::vector<std::size_t> offsets, tuples;
    for (std::size_t i = 0; i < walk.free_offsets.size(); ++i)
      for (std::size_t digit = 0; digit < radix; ++digit) {
        offsets.push_back(walk.free_offsets[i] + digit * output_stride);
        tuples.push_back(walk.free_tuples[i] + digit * tuple_stride);
      }
    walk.free_offsets.swap(offsets);
    walk.free_tuples.swap(tuples);
  }
  // Lines that differ in a state or post cell hold close values (a line is sorted from the one
  // before); lines of another input or disturbance may not: those digits count slowest. The others
  // by input stride, for the caches.
  std::stable_sort(walk.carried.begin(), walk.carried.end(),
                   [](const StageWalk::Carried& a, const StageWalk::Carried& b) {
                     return a.jumps != b.jumps ? b.jumps : a.input_stride < b.input_stride;
                   });
  return walk;
}

void RobustFactoredSweep::share_searches(StageWalk& walk, std::size_t dimension) const {
  for (const StageWalk::Carried& digit : walk.carried)
    if (digit.tuple_stride) return;
  const std::vector<std::uint32_t>& window_of = window_of_[dimension];
  std::vector<std::uint32_t> search_of_window(packed_[dimension].size(), ~std::uint32_t(0));
  walk.search_of.resize(walk.free_tuples.size());
  for (std::size_t i = 0; i < walk.free_tuples.size(); ++i) {
    std::uint32_t& search = search_of_window[window_of[walk.free_tuples[i]]];
    if (search == ~std::uint32_t(0)) {
      search = std::uint32_t(walk.searched.size());
      walk.searched.push_back(i);
    }
    walk.search_of[i] = search;
  }
}

// The carried digits of a stage's lines, counted up line by line: consecutive lines are
// consecutive values of the carried digits, fastest first (no division per line).
struct RobustFactoredSweep::LineCursor {
  explicit LineCursor(const std::vector<StageWalk::Carried>& carried) : carried(carried), digits(carried.size()) {}
  // To line `line`, by division.
  void seek(std::size_t line) {
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
  // To the next line.
  void next() {
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
  const std::vector<StageWalk::Carried>& carried;
  std::vector<std::size_t> digits;
  std::size_t input = 0, output = 0, tuple = 0;  // the line's first entry, results and tuples
};

void RobustFactoredSweep::run_stage(std::size_t k, const double* in, std::size_t in_size, double* out) {
  const FactoredStage& stage = plan_.stages[k];
  const std::size_t dim = stage.dimension, length = counts_[dim];
  const std::size_t stride = std::size_t(stage.contracted_stride), lines = in_size / length;
  const StageWalk& walk = walks_[k];
  const std::size_t applied = walk.free_offsets.size();
  require(lines * applied == stage.output_size, "every output entry reads one line");
  const bool shared = !walk.search_of.empty();
  const std::size_t searches = searches_per_line(k);
  const PackedWindows& windows = packed_[dim];
  const std::vector<std::uint32_t>& window_of = window_of_[dim];
  const double sign = bound_ == Bound::Lower ? 1.0 : -1.0;
  // Workers take chunks of lines as they go: lines differ in cost (the searches' lengths), and an
  // even split would leave a worker idle at the end of the stage. At least 16 lines a chunk: a
  // chunk finds its first line by division, the others by counting. The chunks do not
  // depend on the number of workers, nor, therefore, do the results, bit for bit (a chunk's
  // searches start from its own lines).
  const std::size_t chunk = std::clamp<std::size_t>(lines / 64, 16, 256);
  // A sort pays for itself over many searches of one line: each of its searches then steps from
  // key to key; without it, each step is a pass over the window.
  const bool sorted = search_ == LineSearch::Auto ? searches >= kSearchesWorthASort : search_ == LineSearch::Sorted;
  std::atomic<std::size_t> next_line{0};
  parallel_for(threads_, threads_, [&](unsigned, std::size_t, std::size_t) {
    SortedLine line(length);
    // Where the search of each of the line's windows ended on the previous line (a position):
    // neighbouring lines hold close values, and their i-th windows are one tuple or neighbouring
    // ones, so the threshold sits at the same cell or next to it.
    std::vector<std::uint32_t> ends(searches);
    std::vector<const PackedWindow*> line_windows(searches);
    std::size_t windows_tuple_base = ~std::size_t(0);  // whose windows line_windows holds
    std::vector<double> bounds(searches);
    ThresholdSearches batch;
    LineCursor cursor(walk.carried);
    for (std::size_t first; (first = next_line.fetch_add(chunk)) < lines;) {
      const std::size_t last = std::min(first + chunk, lines);
      cursor.seek(first);
      for (std::size_t index = first; index < last; ++index, cursor.next()) {
        const std::size_t base = cursor.input, output_base = cursor.output, tuple_base = cursor.tuple;
        const bool previous_line = index > first;  // a chunk's lines alone decide its results, bit for bit
        for (std::size_t a = 0; a < length; ++a) line.keys()[a] = sign * in[base + a * stride];
        if (tuple_base != windows_tuple_base)  // consecutive lines mostly read the same windows
          for (std::size_t s = 0; s < searches; ++s)
            line_windows[s] = &windows[window_of[tuple_base + walk.free_tuples[shared ? walk.searched[s] : s]]];
        windows_tuple_base = tuple_base;
        if (sorted) {
          line.sort(previous_line);
          // A chunk's first line: every search from the median key.
          if (!previous_line) std::fill(ends.begin(), ends.end(), std::uint32_t(line.order(length / 2)));
          batch.run(line, line_windows.data(), searches, bound_, ends.data(), bounds.data(), unit_);
        } else {
          // A chunk's first line: each search from where the previous window's ended.
          std::size_t start = length / 2;
          for (std::size_t s = 0; s < searches; ++s) {
            if (previous_line) start = ends[s];
            bounds[s] = threshold_scan(line.keys(), *line_windows[s], bound_, start, unit_);
            ends[s] = std::uint32_t(start);
          }
        }
        for (std::size_t i = 0; i < applied; ++i)
          out[output_base + walk.free_offsets[i]] = bounds[shared ? walk.search_of[i] : i];
      }
    }
  });
}

}  // namespace amytiss::detail
