#include "host/factored_plan.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "amytiss/format.hpp"

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
// without a vector digit (see build_stages) weighted by kScalarStageWeight in the kernels' layout.
struct OrderCost {
  std::vector<double> sizes;
  double multiply_adds = 0;
  double weighted = 0;
};

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
    // Vector digits (see vector_digits): V's last dimension in the first stage; later, a remaining
    // post cell or a variable the contracted coordinate does not read.
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

std::vector<std::uint64_t> strides_of(const std::vector<TensorDigit>& layout) {
  std::vector<std::uint64_t> strides(layout.size());
  std::uint64_t stride = 1;
  for (std::size_t j = layout.size(); j-- > 0;) {
    strides[j] = stride;
    stride *= layout[j].radix;
  }
  return strides;
}

std::uint64_t stride_in(const std::vector<TensorDigit>& layout, const std::vector<std::uint64_t>& strides,
                        bool post, std::size_t id) {
  for (std::size_t j = 0; j < layout.size(); ++j)
    if (layout[j].post == post && layout[j].id == id) return strides[j];
  return 0;
}

// The digit each stage computes eight (or four, two) entries at a time along: it must be in the
// stage's input and output, read by no mass of the contracted coordinate (so that the entries
// share their masses and window) and be the input's fastest digit (contiguous values). The first
// stage reads V, whose fastest digit is the last post dimension; later inputs are laid out by the
// stage before, which puts the next stage's vector digit last, so any remaining post cell or
// unread variable qualifies: the one with the most values. nullopt: the stage runs scalar.
struct DigitId {
  bool post;
  std::size_t id;
};
std::vector<std::optional<DigitId>> vector_digits(const std::vector<std::size_t>& order,
                                                  const std::vector<std::vector<std::size_t>>& reads,
                                                  const std::vector<FactorVariable>& variables,
                                                  const std::vector<std::size_t>& counts, std::size_t slice_cells) {
  const std::size_t dims = counts.size(), sliced = order.back();
  std::vector<std::optional<DigitId>> digits(order.size());
  std::vector<char> used(variables.size(), 0), remaining(dims, 1);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t dim = order[k];
    remaining[dim] = 0;
    auto radix_of_post = [&](std::size_t r) { return r == sliced ? slice_cells : counts[r]; };
    std::size_t best_radix = 1;
    if (k == 0) {
      if (dims >= 2 && dim != dims - 1 && radix_of_post(dims - 1) >= 2) digits[k] = DigitId{true, dims - 1};
    } else {
      for (std::size_t r = 0; r < dims; ++r)
        if (remaining[r] && radix_of_post(r) > best_radix) {
          best_radix = radix_of_post(r);
          digits[k] = DigitId{true, r};
        }
      for (std::size_t v = 0; v < variables.size(); ++v)
        if (used[v] && std::find(reads[dim].begin(), reads[dim].end(), v) == reads[dim].end() &&
            variables[v].count > best_radix) {
          best_radix = variables[v].count;
          digits[k] = DigitId{false, v};
        }
    }
    for (std::size_t v : reads[dim]) used[v] = 1;
  }
  return digits;
}

// The final layout of stage k's output, from the input's digits and then the new variables.
void arrange_output(std::vector<TensorDigit>& output, std::size_t k, const std::vector<std::size_t>& order,
                    const std::vector<std::optional<DigitId>>& vectors, const std::vector<FactorVariable>& variables,
                    FactoredLayout layout) {
  // Q: input and disturbance digits last, so that the input choice reads each state's values
  // from one stretch of memory.
  if (k + 1 == order.size())
    std::stable_partition(output.begin(), output.end(), [&](const TensorDigit& digit) {
      return variables[digit.id].space == FactorVariable::Space::State;
    });
  if (layout == FactoredLayout::Lines) {
    // The largest remaining post cell that the next stage does not contract goes last: the next
    // stage's consecutive lines then differ in it alone (neighbouring cells of the value
    // function: close values, the same windows) and lie side by side in memory.
    auto last = output.end();
    for (auto digit = output.begin(); k + 1 < order.size() && digit != output.end(); ++digit)
      if (digit->post && digit->id != order[k + 1] && (last == output.end() || digit->radix > last->radix))
        last = digit;
    if (last != output.end()) std::rotate(last, last + 1, output.end());
    return;
  }
  // The next stage's contracted cell goes just before its vector digit: each work-item's
  // window is then one contiguous block of the next input.
  if (k + 1 < order.size()) {
    const auto next = std::find_if(output.begin(), output.end(), [&](const TensorDigit& digit) {
      return digit.post && digit.id == order[k + 1];
    });
    std::rotate(next, next + 1, output.end());
  }
  if (k + 1 < order.size() && vectors[k + 1]) {
    const auto next = std::find_if(output.begin(), output.end(), [&](const TensorDigit& digit) {
      return digit.post == vectors[k + 1]->post && digit.id == vectors[k + 1]->id;
    });
    std::rotate(next, next + 1, output.end());
  }
}

// Stages of an order for slices of `slice_cells` cells of the last dimension eliminated.
std::vector<FactoredStage> build_stages(const std::vector<std::size_t>& order,
                                        const std::vector<std::vector<std::size_t>>& reads,
                                        const std::vector<FactorVariable>& variables,
                                        const std::vector<std::size_t>& counts, const std::vector<std::size_t>& widths,
                                        std::size_t slice_cells, FactoredLayout layout) {
  const std::size_t dims = counts.size(), sliced = order.back();
  std::vector<std::optional<DigitId>> vectors = vector_digits(order, reads, variables, counts, slice_cells);
  if (layout == FactoredLayout::Lines) vectors.assign(order.size(), std::nullopt);
  std::vector<TensorDigit> input;
  for (std::size_t r = 0; r < dims; ++r) input.push_back({true, r, counts[r]});  // V, unsliced
  std::vector<char> used(variables.size(), 0), remaining(dims, 1);
  std::vector<FactoredStage> stages;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t dim = order[k];
    for (std::size_t v : reads[dim]) used[v] = 1;
    remaining[dim] = 0;
    FactoredStage stage;
    stage.dimension = dim;
    stage.width = widths[dim];
    // The input's digits in the input's order (so that work-items stream the input), then the
    // variables new to this stage (neighbouring work-items then differ in masses only and re-read
    // the same window of values from cache).
    for (const TensorDigit& digit : input)
      if (!(digit.post && digit.id == dim))
        stage.output.push_back({digit.post, digit.id, digit.post && digit.id == sliced ? slice_cells : digit.radix});
    for (std::size_t v : reads[dim])
      if (std::none_of(input.begin(), input.end(), [&](const TensorDigit& digit) { return !digit.post && digit.id == v; }))
        stage.output.push_back({false, v, variables[v].count});
    arrange_output(stage.output, k, order, vectors, variables, layout);
    const std::vector<std::uint64_t> input_strides = strides_of(input);
    std::vector<std::uint64_t> tuple_strides(variables.size(), 0);
    std::uint64_t tuple_stride = 1;
    for (std::size_t j = reads[dim].size(); j-- > 0;) {
      tuple_strides[reads[dim][j]] = tuple_stride;
      tuple_stride *= variables[reads[dim][j]].count;
    }
    stage.output_size = 1;
    for (std::size_t j = 0; j < stage.output.size(); ++j) {
      const TensorDigit& digit = stage.output[j];
      stage.output_size *= digit.radix;
      stage.input_stride.push_back(stride_in(input, input_strides, digit.post, digit.id));
      stage.tuple_stride.push_back(digit.post ? 0 : tuple_strides[digit.id]);
      if (vectors[k] && digit.post == vectors[k]->post && digit.id == vectors[k]->id) stage.vector_digit = j;
    }
    assert(!stage.vector_digit || (stage.input_stride[*stage.vector_digit] == 1 && stage.tuple_stride[*stage.vector_digit] == 0));
    stage.contracted_stride = stride_in(input, input_strides, true, dim);
    input = stage.output;
    stages.push_back(std::move(stage));
  }
  return stages;
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
                "; %.3g multiply-adds per step against %.3g for the dense sweep (%.1fx fewer); %zu slice%s; ",
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
  const double largest_stage = dims > 1 ? *std::max_element(cost.sizes.begin(), cost.sizes.end() - 1) : 0.0;
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
  plan.stages = build_stages(plan.order, plan.reads, plan.variables, counts, widths, plan.slice_cells, layout);
  for (std::size_t k = 0; k + 1 < plan.stages.size(); ++k)
    plan.largest_stage_tensor = std::max(plan.largest_stage_tensor, plan.stages[k].output_size);
  const FactoredStage& last = plan.stages.back();
  assert(last.output_size == plan.q_size);
  plan.q_stride.assign(plan.variables.size(), 0);
  const std::vector<std::uint64_t> q_strides = strides_of(last.output);
  for (std::size_t j = 0; j < last.output.size(); ++j) plan.q_stride[last.output[j].id] = q_strides[j];
  return plan;
}

}  // namespace amytiss::detail
