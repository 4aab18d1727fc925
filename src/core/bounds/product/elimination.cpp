#include "bounds/product/elimination.hpp"

#include <algorithm>
#include <atomic>

#include "amytiss/format.hpp"
#include "amytiss/stopwatch.hpp"
#include "common/parallel_for.hpp"
#include "common/require.hpp"

namespace amytiss::detail {
namespace {

constexpr Require require{"robust factored sweep: "};

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
    walks_.push_back(StageWalk::of(stage, plan_.variables));
    walks_.back().share_searches(window_of_[stage.dimension], packed_[stage.dimension].size());
  }
  runs_ = stage_runs(plan_, counts_);
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
  std::size_t free_tensor = 0;  // the ping-pong tensor that `in` is not
  for (StageRun& run : runs_) {
    const std::size_t out_size = plan_.stages[run.last].output_size;
    double* out =
        run.last + 1 == plan_.stages.size() ? q_.data() : buffers_->stage_tensors[free_tensor].reserve(out_size);
    const auto start = SteadyClock::now();
    if (run.last > run.first)
      run_fused(run.first, in, in_size, out);
    else
      run_stage(run.first, in, in_size, out);
    run.seconds += seconds_since(start);
    free_tensor ^= 1;
    in = out;
    in_size = out_size;
  }
}

std::vector<RobustFactoredSweep::StageRun> RobustFactoredSweep::stage_runs(const FactoredPlan& plan,
                                                                           const std::vector<std::size_t>& counts) {
  // The pairs that leave the most entries of stage tensors unwritten: saved[k], the most from
  // stage k on; a stage is in one pair at most.
  const std::size_t stages = plan.stages.size();
  std::vector<std::size_t> saved(stages + 2, 0);
  for (std::size_t k = stages; k-- > 0;) {
    saved[k] = saved[k + 1];
    if (fuses_next(plan, counts, k))
      saved[k] = std::max(saved[k], std::size_t(plan.stages[k].output_size) + saved[k + 2]);
  }
  std::vector<StageRun> runs;
  for (std::size_t k = 0; k < stages;) {
    const std::size_t last = saved[k] != saved[k + 1] ? k + 1 : k;
    runs.push_back({k, last});
    k = last + 1;
  }
  return runs;
}

bool RobustFactoredSweep::fuses_next(const FactoredPlan& plan, const std::vector<std::size_t>& counts, std::size_t k) {
  if (k + 1 >= plan.stages.size()) return false;
  const std::vector<StageWalk::Carried> carried = StageWalk::carried_of(plan.stages[k], plan.variables);
  if (carried.empty()) return false;
  const FactoredStage& next = plan.stages[k + 1];
  // The fastest digit of stage k's lines is the post cell that stage k + 1 contracts: it has that
  // digit's stride in stage k's output, and its count.
  return carried[0].output_stride == next.contracted_stride && carried[0].radix == counts[next.dimension];
}

bool RobustFactoredSweep::sorts(std::size_t k) const {
  // A sort pays for itself over many searches of one line: each of its searches then steps from
  // key to key; without it, each step is a pass over the window.
  return search_ == LineSearch::Auto ? searches_per_line(k) >= kSearchesWorthASort : search_ == LineSearch::Sorted;
}

namespace {

// Workers take chunks of lines as they go: lines differ in cost (the searches' lengths), and an
// even split would leave a worker idle at the end of the stage. At least 16 lines a chunk: a chunk
// finds its first line by division, the others by counting; a multiple of `run` lines. The chunks
// do not depend on the number of workers, nor, therefore, do the results, bit for bit (a chunk's
// searches start from its own lines).
std::size_t chunk_lines(std::size_t lines, std::size_t run) {
  return std::max<std::size_t>(1, std::clamp<std::size_t>(lines / 64, 16, 256) / run) * run;
}

}  // namespace

RobustFactoredSweep::LineShape RobustFactoredSweep::lines_of(std::size_t k, std::size_t in_size) const {
  const FactoredStage& stage = plan_.stages[k];
  const std::size_t length = counts_[stage.dimension], lines = in_size / length;
  require(lines * walks_[k].free_offsets.size() == stage.output_size, "every output entry reads one line");
  return {stage.dimension, length, std::size_t(stage.contracted_stride), lines};
}

void RobustFactoredSweep::run_stage(std::size_t k, const double* in, std::size_t in_size, double* out) {
  const auto [dim, length, stride, lines] = lines_of(k, in_size);
  const StageWalk& walk = walks_[k];
  const std::size_t applied = walk.free_offsets.size();
  const double sign = bound_ == Bound::Lower ? 1.0 : -1.0;
  const std::size_t chunk = chunk_lines(lines, 1);
  std::atomic<std::size_t> next_line{0};
  parallel_for(threads_, threads_, [&](unsigned, std::size_t, std::size_t) {
    LineSearcher searcher(walk, packed_[dim], window_of_[dim], length, bound_, sorts(k), unit_);
    LineCursor cursor(walk.carried);
    for (std::size_t first; (first = next_line.fetch_add(chunk)) < lines;) {
      const std::size_t last = std::min(first + chunk, lines);
      cursor.seek(first);
      for (std::size_t index = first; index < last; ++index, cursor.next()) {
        for (std::size_t a = 0; a < length; ++a) searcher.keys()[a] = sign * in[cursor.input + a * stride];
        searcher.search(cursor.tuple, index > first);
        for (std::size_t i = 0; i < applied; ++i) out[cursor.output + walk.free_offsets[i]] = searcher.bound(i);
      }
    }
  });
}

void RobustFactoredSweep::run_fused(std::size_t k, const double* in, std::size_t in_size, double* out) {
  const auto [dim, length, stride, lines] = lines_of(k, in_size);
  const StageWalk& walk = walks_[k];
  const std::size_t applied = walk.free_offsets.size();
  require(fuses_next(plan_, counts_, k), "stage k's lines give stage k + 1's");
  const std::size_t next_dim = plan_.stages[k + 1].dimension, next_length = counts_[next_dim];
  const StageWalk& next_walk = walks_[k + 1];
  const std::size_t next_applied = next_walk.free_offsets.size();
  const double sign = bound_ == Bound::Lower ? 1.0 : -1.0;
  // A run: stage k's lines over its fastest digit, next_length of them; their results form
  // `applied` lines of stage k + 1.
  const std::size_t chunk = chunk_lines(lines, next_length);
  std::atomic<std::size_t> next_line{0};
  parallel_for(threads_, threads_, [&](unsigned, std::size_t, std::size_t) {
    LineSearcher searcher(walk, packed_[dim], window_of_[dim], length, bound_, sorts(k), unit_);
    LineSearcher next_searcher(next_walk, packed_[next_dim], window_of_[next_dim], next_length, bound_, sorts(k + 1),
                               unit_);
    LineCursor cursor(walk.carried), next_cursor(next_walk.carried);
    std::vector<double> run_results(applied * next_length);  // [i][position along the fastest digit]
    for (std::size_t first; (first = next_line.fetch_add(chunk)) < lines;) {
      const std::size_t last = std::min(first + chunk, lines);
      cursor.seek(first);
      for (std::size_t run = first; run < last; run += next_length) {
        const std::size_t run_output = cursor.output;  // W_k's offset of the run's first results
        for (std::size_t position = 0; position < next_length; ++position, cursor.next()) {
          for (std::size_t a = 0; a < length; ++a) searcher.keys()[a] = sign * in[cursor.input + a * stride];
          searcher.search(cursor.tuple, run + position > first);
          for (std::size_t i = 0; i < applied; ++i) run_results[i * next_length + position] = searcher.bound(i);
        }
        // Stage k + 1's lines in an order where neighbours hold close values (good starts).
        for (std::size_t m = 0; m < applied; ++m) {
          const std::size_t i = walk.free_order[m];
          next_cursor.seek_input(run_output + walk.free_offsets[i]);
          const double* line = run_results.data() + i * next_length;
          for (std::size_t a = 0; a < next_length; ++a) next_searcher.keys()[a] = sign * line[a];
          next_searcher.search(next_cursor.tuple, run > first || m > 0);
          for (std::size_t j = 0; j < next_applied; ++j)
            out[next_cursor.output + next_walk.free_offsets[j]] = next_searcher.bound(j);
        }
      }
    }
  });
}

}  // namespace amytiss::detail
