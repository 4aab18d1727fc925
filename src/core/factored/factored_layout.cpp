#include "factored/factored_layout.hpp"

#include <algorithm>
#include <cassert>

namespace amytiss::detail {
namespace {

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

}  // namespace

std::vector<std::uint64_t> strides_of(const std::vector<TensorDigit>& layout) {
  std::vector<std::uint64_t> strides(layout.size());
  std::uint64_t stride = 1;
  for (std::size_t j = layout.size(); j-- > 0;) {
    strides[j] = stride;
    stride *= layout[j].radix;
  }
  return strides;
}

namespace {

// The strides of a stage's output; `padded`: the fastest digit's values span whole cache lines
// where that adds at most 1/kMaxLinePadding (a row of 81 values spans 88 doubles, one of 28 does
// not span 32), so that every row, and every line of entries of the fastest digit, starts a line.
std::vector<std::uint64_t> output_strides(const std::vector<TensorDigit>& layout, bool padded) {
  std::vector<std::uint64_t> strides = strides_of(layout);
  const std::uint64_t radix = layout.back().radix;
  const std::uint64_t span = (radix + kLineDoubles - 1) / kLineDoubles * kLineDoubles;
  if (!padded || span == radix || (span - radix) * kMaxLinePadding > radix) return strides;
  for (std::size_t j = 0; j + 1 < layout.size(); ++j) strides[j] = strides[j] / radix * span;
  return strides;
}

}  // namespace

std::vector<FactoredStage> build_stages(const std::vector<std::size_t>& order,
                                        const std::vector<std::vector<std::size_t>>& reads,
                                        const std::vector<FactorVariable>& variables,
                                        const std::vector<std::size_t>& counts, const std::vector<std::size_t>& widths,
                                        std::size_t slice_cells, FactoredLayout layout, bool pad_to_lines) {
  const std::size_t dims = counts.size(), sliced = order.back();
  std::vector<std::optional<DigitId>> vectors = vector_digits(order, reads, variables, counts, slice_cells);
  if (layout == FactoredLayout::Lines) vectors.assign(order.size(), std::nullopt);
  std::vector<TensorDigit> input;
  for (std::size_t r = 0; r < dims; ++r) input.push_back({true, r, counts[r]});  // V, unsliced
  std::vector<std::uint64_t> input_strides = strides_of(input);
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
    std::vector<std::uint64_t> tuple_strides(variables.size(), 0);
    std::uint64_t tuple_stride = 1;
    for (std::size_t j = reads[dim].size(); j-- > 0;) {
      tuple_strides[reads[dim][j]] = tuple_stride;
      tuple_stride *= variables[reads[dim][j]].count;
    }
    stage.output_stride = output_strides(stage.output, pad_to_lines && k + 1 < order.size());
    stage.output_entries = 1;
    for (std::size_t j = 0; j < stage.output.size(); ++j) {
      const TensorDigit& digit = stage.output[j];
      stage.output_entries *= digit.radix;
      stage.input_stride.push_back(stride_in(input, input_strides, digit.post, digit.id));
      stage.tuple_stride.push_back(digit.post ? 0 : tuple_strides[digit.id]);
      if (vectors[k] && digit.post == vectors[k]->post && digit.id == vectors[k]->id) stage.vector_digit = j;
    }
    assert(!stage.vector_digit || (stage.input_stride[*stage.vector_digit] == 1 && stage.tuple_stride[*stage.vector_digit] == 0));
    stage.output_size = stage.output_stride.front() * stage.output.front().radix;
    stage.contracted_stride = stride_in(input, input_strides, true, dim);
    input = stage.output;
    input_strides = stage.output_stride;
    stages.push_back(std::move(stage));
  }
  return stages;
}

}  // namespace amytiss::detail
