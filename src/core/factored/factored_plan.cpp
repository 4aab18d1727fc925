#include "factored/factored_plan.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "amytiss/format.hpp"
#include "factored/factored_layout.hpp"

namespace amytiss::detail {
namespace {

// Orders are searched exhaustively up to this many dimensions (8! = 40,320 orders), greedily above.
constexpr std::size_t kExhaustiveOrderDims = 8;
// Tensor sizes are indexed with 64-bit integers in the kernels; plans beyond this are refused.
constexpr double kMaxTensorEntries = 4.0e18;

std::vector<FactorVariable> grid_variables(const Abstraction& a) {
  std::vector<FactorVariable> variables;
  for (std::size_t i = 0; i < a.states.dims(); ++i)
    variables.push_back({FactorVariable::Space::State, i, a.states.count(i)});
  for (std::size_t i = 0; i < a.inputs.dims(); ++i)
    variables.push_back({FactorVariable::Space::Input, i, a.inputs.count(i)});
  for (std::size_t i = 0; i < a.disturbances.dims(); ++i)
    variables.push_back({FactorVariable::Space::Disturbance, i, a.disturbances.count(i)});
  return variables;
}

// Kept cells of a dimension's window at most (the whole dimension for truncation none).
std::size_t window_width(const Abstraction& a, std::size_t dim) {
  const std::size_t count = a.states.count(dim);
  if (a.noise->whole_grid_dims()[dim]) return count;
  const std::int64_t half = a.noise->window_half_cells()[dim];
  return std::size_t(std::min<std::int64_t>(2 * half + 1, std::int64_t(count)));
}

// Entries of W_k for k = 1..d in the order (the sliced dimension, order.back(), at full size),
// the multiply-adds of all stages, and the cost the order is chosen by: multiply-adds, a stage
// without a vector digit (factored/factored_layout.cpp) weighted by kScalarStageWeight in the kernels'
// layout.
struct OrderCost {
  std::vector<double> sizes;
  double multiply_adds = 0;
  double weighted = 0;
};

// Entries of the largest stage tensor W_1..W_{d-1} (all slices, unpadded); 0 with one stage.
double stage_tensor_entries(const OrderCost& cost) {
  return cost.sizes.size() > 1 ? *std::max_element(cost.sizes.begin(), cost.sizes.end() - 1) : 0.0;
}

// A stage whose entries cannot be computed eight at a time from contiguous values runs several
// times slower per multiply-add (measured on pocl: ~0.9 against ~10 GMAC/s).
constexpr double kScalarStageWeight = 8.0;

OrderCost order_cost(const std::vector<std::size_t>& order, const std::vector<std::vector<std::size_t>>& reads,
                     const std::vector<FactorVariable>& variables, const std::vector<std::size_t>& counts,
                     const std::vector<std::size_t>& widths, FactoredLayout layout) {
  OrderCost cost;
  const std::size_t dims = counts.size();
  std::vector<char> used(variables.size(), 0), remaining(dims, 1);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t dim = order[k];
    std::vector<char> used_before = used;
    for (std::size_t v : reads[dim]) used[v] = 1;
    remaining[dim] = 0;
    double size = 1;
    for (std::size_t v = 0; v < variables.size(); ++v)
      if (used[v]) size *= double(variables[v].count);
    std::size_t posts_left = 0;
    for (std::size_t r = 0; r < dims; ++r)
      if (remaining[r]) {
        size *= double(counts[r]);
        ++posts_left;
      }
    // Vector digits (factored/factored_layout.cpp): V's last dimension in the first stage; later, a
    // remaining post cell or a variable the contracted coordinate does not read.
    bool vector = false;
    if (k == 0) {
      vector = dims >= 2 && dim != dims - 1;
    } else if (posts_left > 0) {
      vector = true;
    } else {
      for (std::size_t v = 0; v < variables.size(); ++v)
        vector = vector || (used_before[v] && std::find(reads[dim].begin(), reads[dim].end(), v) == reads[dim].end() &&
                            variables[v].count >= 2);
    }
    cost.sizes.push_back(size);
    cost.multiply_adds += size * double(widths[dim]);
    const bool scalar_stage = !vector && layout == FactoredLayout::Kernels;
    cost.weighted += size * double(widths[dim]) * (scalar_stage ? kScalarStageWeight : 1.0);
  }
  return cost;
}

std::vector<std::size_t> greedy_order(const std::vector<std::vector<std::size_t>>& reads,
                                      const std::vector<FactorVariable>& variables,
                                      const std::vector<std::size_t>& counts, const std::vector<std::size_t>& widths,
                                      FactoredLayout layout) {
  std::vector<std::size_t> order, left(counts.size());
  std::iota(left.begin(), left.end(), 0);
  while (!left.empty()) {
    std::size_t best = 0;
    double best_cost = INFINITY;
    for (std::size_t j = 0; j < left.size(); ++j) {
      std::vector<std::size_t> trial = order;
      trial.push_back(left[j]);
      const double cost = order_cost(trial, reads, variables, counts, widths, layout).weighted;
      if (cost < best_cost) {
        best_cost = cost;
        best = j;
      }
    }
    order.push_back(left[best]);
    left.erase(left.begin() + std::ptrdiff_t(best));
  }
  return order;
}

std::string variable_name(const FactorVariable& variable) {
  const char* prefix = variable.space == FactorVariable::Space::State   ? "x"
                       : variable.space == FactorVariable::Space::Input ? "u"
                                                                         : "w";
  return prefix + std::to_string(variable.index);
}

}  // namespace

std::size_t dense_window_width(const Abstraction& a, std::size_t dim) {
  const auto count = std::int64_t(a.states.count(dim));
  if (a.noise->whole_grid_dims()[dim]) return std::size_t(count);
  return std::size_t(2 * std::min<std::int64_t>(a.noise->window_half_cells()[dim], count - 1) + 1);
}

double contraction_multiply_adds(const Abstraction& a) {
  double total = 0, product = 1;
  for (std::size_t dim = 0; dim < a.states.dims(); ++dim) {
    product *= double(dense_window_width(a, dim));
    total += product;
  }
  return total;
}

std::string FactoredPlan::describe() const {
  std::string text = "factored sweep: eliminates";
  for (std::size_t dim : order) text += " x'" + std::to_string(dim);
  char numbers[200];
  std::snprintf(numbers, sizeof numbers,
                "; %.3g multiply-adds per step against %.3g for the dense sweep (%.1fx fewer); %zu slice%s; at most ",
                multiply_adds, dense_multiply_adds, dense_multiply_adds / std::max(multiply_adds, 1.0), slices,
                slices == 1 ? "" : "s");
  text += numbers + format_bytes(double(device_bytes));
  text += "; reads:";
  for (std::size_t dim = 0; dim < reads.size(); ++dim) {
    text += " x'" + std::to_string(dim) + "(";
    for (std::size_t j = 0; j < reads[dim].size(); ++j) text += (j ? "," : "") + variable_name(variables[reads[dim][j]]);
    text += ")";
  }
  return text;
}

namespace {

// The variables each post coordinate's masses read: the states, inputs and disturbances its
// dynamics read, and its own state under multiplicative noise (the scale is |x_dim|).
std::vector<std::vector<std::size_t>> coordinate_reads(const Abstraction& a, const std::vector<VariableUse>& dependencies) {
  const std::size_t dims = a.states.dims(), inputs_base = dims, disturbances_base = dims + a.inputs.dims();
  std::vector<std::vector<std::size_t>> all;
  for (std::size_t dim = 0; dim < dims; ++dim) {
    const VariableUse& use = dependencies[dim];
    std::vector<std::size_t> reads;
    for (std::size_t i : use.states) reads.push_back(i);
    if (a.noise->type() == NoiseType::Multiplicative) reads.push_back(dim);
    for (std::size_t i : use.inputs) reads.push_back(inputs_base + i);
    for (std::size_t i : use.disturbances) reads.push_back(disturbances_base + i);
    std::sort(reads.begin(), reads.end());
    reads.erase(std::unique(reads.begin(), reads.end()), reads.end());
    all.push_back(std::move(reads));
  }
  return all;
}

// The cheapest order (the kernels' weighted cost, or the lines' multiply-adds); among equally
// cheap ones, the one with the smallest tensors.
std::vector<std::size_t> cheapest_order(const FactoredPlan& plan, const std::vector<std::size_t>& counts,
                                        const std::vector<std::size_t>& widths, FactoredLayout layout,
                                        OrderCost& best_cost) {
  std::vector<std::size_t> best_order;
  auto consider = [&](const std::vector<std::size_t>& order) {
    OrderCost cost = order_cost(order, plan.reads, plan.variables, counts, widths, layout);
    const double largest = *std::max_element(cost.sizes.begin(), cost.sizes.end());
    const double best_largest =
        best_order.empty() ? INFINITY : *std::max_element(best_cost.sizes.begin(), best_cost.sizes.end());
    if (best_order.empty() || cost.weighted < best_cost.weighted ||
        (cost.weighted == best_cost.weighted && largest < best_largest)) {
      best_order = order;
      best_cost = std::move(cost);
    }
  };
  const std::size_t dims = counts.size();
  if (dims <= kExhaustiveOrderDims) {
    std::vector<std::size_t> order(dims);
    std::iota(order.begin(), order.end(), 0);
    do consider(order);
    while (std::next_permutation(order.begin(), order.end()));
  } else {
    consider(greedy_order(plan.reads, plan.variables, counts, widths, layout));
  }
  return best_order;
}

// The fewest slices of the last eliminated dimension whose tensors fit the budget and the
// largest buffer (plan.slices 0: none fits); sets plan.slices and plan.device_bytes.
void choose_slices(const Abstraction& a, const OrderCost& cost, const std::vector<std::size_t>& counts,
                   const std::vector<std::size_t>& widths, double budget_bytes, double max_buffer_bytes,
                   FactoredPlan& plan) {
  const std::size_t dims = counts.size();
  double table_bytes = 0;
  for (std::size_t dim = 0; dim < dims; ++dim) {
    double tuples = 1;
    for (std::size_t v : plan.reads[dim]) tuples *= double(plan.variables[v].count);
    table_bytes += tuples * (double(widths[dim]) * sizeof(double) + 2 * sizeof(std::uint32_t));
  }
  const double fixed_bytes = double(sizeof(double)) * (2.0 * double(a.states.size()) + double(plan.q_size)) +
                             double(a.states.size()) * (1 + sizeof(std::uint32_t)) + table_bytes;
  // Stage tensors W_1..W_{d-1} hold the sliced dimension's cells: they shrink with the slice.
  const double largest_stage = stage_tensor_entries(cost);
  const std::size_t sliced_count = counts[plan.order.back()];
  plan.slices = 0;
  for (std::size_t slices = 1; slices <= sliced_count; ++slices) {
    if (sliced_count % slices) continue;
    if (dims == 1 && slices > 1) break;  // a single stage reads V itself: nothing to slice
    const double bytes = fixed_bytes + 2.0 * sizeof(double) * largest_stage / double(slices);
    const double largest_buffer =
        sizeof(double) * std::max({largest_stage / double(slices), double(plan.q_size), double(a.states.size())});
    if (bytes <= budget_bytes && largest_buffer <= max_buffer_bytes) {
      plan.slices = slices;
      plan.device_bytes = std::size_t(bytes);
      return;
    }
  }
}

}  // namespace

std::optional<FactoredPlan> plan_factored_sweep(const Abstraction& a, double budget_bytes, double max_buffer_bytes,
                                                std::string* reason, FactoredLayout layout) {
  auto refuse = [&](const std::string& why) -> std::optional<FactoredPlan> {
    if (reason) *reason = why;
    return std::nullopt;
  };
  if (!a.noise->separable()) return refuse("the noise is not separable (full covariance)");
  const auto dependencies = a.dynamics->dependencies();
  if (!dependencies) return refuse("the dynamics (" + a.dynamics->describe() + ") do not say which components each coordinate reads");

  FactoredPlan plan;
  plan.variables = grid_variables(a);
  const std::size_t dims = a.states.dims();
  std::vector<std::size_t> counts(dims), widths(dims);
  for (std::size_t dim = 0; dim < dims; ++dim) {
    counts[dim] = a.states.count(dim);
    widths[dim] = window_width(a, dim);
  }
  plan.reads = coordinate_reads(a, *dependencies);
  OrderCost best_cost;
  plan.order = cheapest_order(plan, counts, widths, layout, best_cost);
  if (*std::max_element(best_cost.sizes.begin(), best_cost.sizes.end()) > kMaxTensorEntries)
    return refuse("its tensors would exceed 64-bit indexing");
  plan.multiply_adds = best_cost.multiply_adds;
  plan.dense_multiply_adds = double(a.states.size()) * double(a.inputs.size()) * double(a.disturbances.size()) *
                             contraction_multiply_adds(a);
  plan.q_size = std::uint64_t(best_cost.sizes.back());
  choose_slices(a, best_cost, counts, widths, budget_bytes, max_buffer_bytes, plan);
  if (plan.slices == 0)
    return refuse("its tensors need more than the budget of " + format_bytes(budget_bytes) + " (or buffers above " +
                  format_bytes(max_buffer_bytes) + ") even in slices");
  plan.slice_cells = counts[plan.order.back()] / plan.slices;
  auto build = [&](bool pad_to_lines) {
    plan.stages =
        build_stages(plan.order, plan.reads, plan.variables, counts, widths, plan.slice_cells, layout, pad_to_lines);
    plan.largest_stage_tensor = 0;
    for (std::size_t k = 0; k + 1 < plan.stages.size(); ++k)
      plan.largest_stage_tensor = std::max(plan.largest_stage_tensor, plan.stages[k].output_size);
  };
  build(layout == FactoredLayout::Kernels);
  // The slices were chosen for unpadded tensors: the padding of the two stage buffers must fit
  // too, or the tensors stay unpadded.
  const double unpadded_entries = stage_tensor_entries(best_cost) / double(plan.slices);
  const double padding_bytes = 2.0 * sizeof(double) * (double(plan.largest_stage_tensor) - unpadded_entries);
  if (padding_bytes > 0) {
    if (double(plan.device_bytes) + padding_bytes <= budget_bytes &&
        sizeof(double) * double(plan.largest_stage_tensor) <= max_buffer_bytes)
      plan.device_bytes += std::size_t(padding_bytes);
    else
      build(false);
  }
  const FactoredStage& last = plan.stages.back();
  assert(last.output_size == plan.q_size);
  plan.q_stride.assign(plan.variables.size(), 0);
  const std::vector<std::uint64_t> q_strides = strides_of(last.output);
  for (std::size_t j = 0; j < last.output.size(); ++j) plan.q_stride[last.output[j].id] = q_strides[j];
  return plan;
}

}  // namespace amytiss::detail
