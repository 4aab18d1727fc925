#include "amytiss/policy.hpp"

#include "amytiss/format.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace amytiss {
namespace {

std::string format_state(const double* state, std::size_t length) {
  std::string text = "[";
  for (std::size_t i = 0; i < length; ++i) {
    if (i) text += ", ";
    text += format_number(state[i]);
  }
  return text + "]";
}

std::string component_names(std::size_t dims) {
  std::string text = "(";
  for (std::size_t i = 0; i < dims; ++i) text += (i ? ", x" : "x") + std::to_string(i);
  return text + ")";
}

// The covered interval of dimension d: [lb - eta/2, last + eta/2], or the outermost faces.
std::string covered_interval(const Grid& grid, std::size_t d) {
  const double low = grid.covered_low(d);
  const double high = grid.covered_high(d);
  return "[" + format_number(low) + ", " + format_number(high) + "]";
}

}  // namespace

LookupStatus Policy::lookup(const double* state, std::size_t state_length, unsigned step,
                            double* input_out, double* probability_out, double* upper_out) const {
  if (state_length != states.dims()) return LookupStatus::WrongDimension;
  for (std::size_t i = 0; i < state_length; ++i)
    if (!std::isfinite(state[i])) return LookupStatus::NotFinite;
  if (stationary) step = 0;
  if (step >= horizon) return LookupStatus::StepBeyondHorizon;
  const auto cell = states.cell_of(state);
  if (!cell) return LookupStatus::OutsideGrid;
  inputs.point(input(step, *cell), input_out);
  *probability_out = value(step, *cell);
  if (upper_out) *upper_out = upper_value(step, *cell);
  return LookupStatus::Ok;
}

std::string Policy::describe(LookupStatus status, const double* state, std::size_t state_length,
                             unsigned step) const {
  switch (status) {
    case LookupStatus::Ok:
      return "ok";
    case LookupStatus::WrongDimension:
      return "state has " + std::to_string(state_length) + " value" + (state_length == 1 ? "" : "s") +
             ", expected " + std::to_string(states.dims()) + " " + component_names(states.dims());
    case LookupStatus::NotFinite: {
      std::string which;
      for (std::size_t i = 0; i < state_length; ++i)
        if (!std::isfinite(state[i])) {
          which = "x" + std::to_string(i) + " = " + format_number(state[i]);
          break;
        }
      return "state " + format_state(state, state_length) + " is not finite (" + which +
             "), expected finite numbers";
    }
    case LookupStatus::OutsideGrid: {
      std::string grid_text, which;
      for (std::size_t d = 0; d < states.dims(); ++d) {
        grid_text += (d ? " x " : "") + covered_interval(states, d);
        if (which.empty() && d < state_length) {
          const double low = states.covered_low(d);
          const double high = states.covered_high(d);
          if (!(state[d] >= low && state[d] <= high))
            which = "x" + std::to_string(d) + " = " + format_number(state[d]) + " is not in " +
                    covered_interval(states, d);
        }
      }
      return "state " + format_state(state, state_length) + " is outside the grid " + grid_text +
             (which.empty() ? "" : " (" + which + ")");
    }
    case LookupStatus::StepBeyondHorizon:
      return "time_step " + std::to_string(step) + " is beyond the horizon, expected 0 <= time_step < " +
             std::to_string(horizon);
  }
  return "unknown lookup status";
}

ValueSummary summarize_initial_values(const Policy& policy) {
  ValueSummary summary;
  double sum = 0;
  const std::size_t cells = policy.states.size();
  for (std::size_t cell = 0; cell < cells; ++cell) {
    if (cell < policy.roles.size() && policy.roles[cell] != CellRole::Free) continue;
    const double value = policy.value(0, cell);
    if (summary.free_cells == 0) {
      summary.min = summary.max = value;
    } else {
      summary.min = std::min(summary.min, value);
      summary.max = std::max(summary.max, value);
    }
    sum += value;
    ++summary.free_cells;
    if (value >= 0.5) ++summary.cells_at_least_half;
  }
  if (summary.free_cells) summary.mean = sum / double(summary.free_cells);
  return summary;
}

BoundsSummary summarize_bounds(const Policy& policy) {
  BoundsSummary summary;
  RangeSummary* ranges[] = {&summary.lower, &summary.upper, &summary.gap};
  double sums[3] = {0, 0, 0};
  for (std::size_t cell = 0; cell < policy.states.size(); ++cell) {
    if (cell < policy.roles.size() && policy.roles[cell] != CellRole::Free) continue;
    const double lower = policy.value(0, cell), upper = policy.upper_value(0, cell);
    const double values[3] = {lower, upper, upper - lower};
    for (int k = 0; k < 3; ++k) {
      RangeSummary& range = *ranges[k];
      range.min = summary.free_cells ? std::min(range.min, values[k]) : values[k];
      range.max = summary.free_cells ? std::max(range.max, values[k]) : values[k];
      sums[k] += values[k];
    }
    ++summary.free_cells;
  }
  if (summary.free_cells)
    for (int k = 0; k < 3; ++k) ranges[k]->mean = sums[k] / double(summary.free_cells);
  return summary;
}

}  // namespace amytiss
