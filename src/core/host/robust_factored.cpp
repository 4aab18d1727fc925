#include "host/robust_factored.hpp"

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
  // The plan counts its tensors, Q and tables; the sorted lines take as much again as a tensor.
  std::optional<FactoredPlan> plan = plan_factored_sweep(a, kMaxBytes / 2, kMaxBytes / 4, reason);
  if (plan && plan->slices > 1) {
    if (reason)
      *reason = "its tensors need " + std::to_string(plan->slices) + " slices within " + format_bytes(kMaxBytes / 2) +
                " (an O-maximisation needs its whole line)";
    return std::nullopt;
  }
  return plan;
}

RobustFactoredSweep::RobustFactoredSweep(const Abstraction& a, const RowBounds& rows, const std::vector<bool>& has_rows,
                                         FactoredPlan plan, Bound bound, unsigned threads)
    : plan_(std::move(plan)), bound_(bound), threads_(threads) {
  require(plan_.slices == 1 && plan_.stages.size() == a.states.dims(), "a plan of one slice, a stage per dimension");
  for (std::size_t d = 0; d < a.states.dims(); ++d) counts_.push_back(a.states.count(d));
  gather_windows(a, rows, has_rows);
  number_q(a);
}

void RobustFactoredSweep::gather_windows(const Abstraction& a, const RowBounds& rows,
                                         const std::vector<bool>& has_rows) {
  const std::size_t dims = a.states.dims();
  // A tuple no row has feeds no row's bound: any feasible window will do.
  const DimensionView nowhere{0, 0, nullptr, {0.0, 1.0}, {0.0, 0.0}};
  std::vector<std::vector<char>> found(dims);
  windows_.resize(dims);
  for (std::size_t d = 0; d < dims; ++d) {
    std::size_t tuples = 1;
    for (std::size_t v : plan_.reads[d]) tuples *= plan_.variables[v].count;
    windows_[d].assign(tuples, nowhere);
    found[d].assign(tuples, 0);
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
          windows_[d][tuple] = rows.distinct(d, rows.bounds_index(row, d));
        }
      }
  }
  sums_.resize(dims);
  for (std::size_t d = 0; d < dims; ++d)
    for (const DimensionView& window : windows_[d]) sums_[d].push_back(window_sums(window));
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
  for (std::size_t k = 0; k < plan_.stages.size(); ++k) {
    std::vector<double>& out = k + 1 == plan_.stages.size() ? q_ : tensors_[k % 2];
    out.resize(plan_.stages[k].output_size);
    run_stage(k, in, in_size, out.data());
    in = out.data();
    in_size = out.size();
  }
}

void RobustFactoredSweep::run_stage(std::size_t k, const double* in, std::size_t in_size, double* out) {
  const FactoredStage& stage = plan_.stages[k];
  const std::size_t dim = stage.dimension, length = counts_[dim];
  const std::size_t stride = std::size_t(stage.contracted_stride), lines = in_size / length;
  // Line (high, low) of the input holds the entries high * stride * length + low + a * stride: its
  // values side by side, then sorted once for every tuple applied to it.
  lines_.resize(in_size);
  parallel_for(lines, threads_, [&](unsigned, std::size_t first, std::size_t last) {
    for (std::size_t line = first; line < last; ++line) {
      const std::size_t base = (line / stride) * stride * length + line % stride;
      for (std::size_t a = 0; a < length; ++a) lines_[line * length + a] = in[base + a * stride];
    }
  });
  sort_lines(lines_.data(), lines, length, bound_, threads_, line_order_);
  const std::vector<DimensionView>& windows = windows_[dim];
  const std::vector<WindowSums>& sums = sums_[dim];
  const std::size_t digits = stage.output.size();
  parallel_for(std::size_t(stage.output_size), threads_, [&](unsigned, std::size_t first, std::size_t last) {
    // The output entry's digits, its line's base in the input and its tuple, carried along.
    std::vector<std::size_t> digit(digits);
    std::size_t rest = first, base = 0, tuple = 0;
    for (std::size_t j = digits; j-- > 0;) {
      digit[j] = rest % stage.output[j].radix;
      rest /= stage.output[j].radix;
      base += digit[j] * std::size_t(stage.input_stride[j]);
      tuple += digit[j] * std::size_t(stage.tuple_stride[j]);
    }
    for (std::size_t entry = first; entry < last; ++entry) {
      const std::size_t line = (base / (stride * length)) * stride + base % stride;
      out[entry] = ordered_expectation(lines_.data() + line * length, line_order_.order.data() + line * length,
                                       line_order_.rank.data() + line * length, length, windows[tuple], sums[tuple],
                                       bound_);
      for (std::size_t j = digits; j-- > 0;) {
        const std::size_t radix = stage.output[j].radix;
        base += std::size_t(stage.input_stride[j]);
        tuple += std::size_t(stage.tuple_stride[j]);
        if (++digit[j] < radix) break;
        base -= radix * std::size_t(stage.input_stride[j]);
        tuple -= radix * std::size_t(stage.tuple_stride[j]);
        digit[j] = 0;
      }
    }
  });
}

}  // namespace amytiss::detail
