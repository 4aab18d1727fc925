#include "bounds/memory_estimate.hpp"

#include <algorithm>

#include "amytiss/enclosure.hpp"
#include "bounds/mean_box.hpp"
#include "bounds/omax/threshold_expectation.hpp"
#include "bounds/product/elimination.hpp"
#include "bounds/product/whole_tables.hpp"
#include "bounds/robust_step.hpp"
#include "bounds/row_bounds.hpp"

namespace amytiss::detail {
namespace {

// Bytes of one distinct key in a worker's tables: the key (five doubles) in the list and in the
// hash map's node (with its index, the next pointer, the cached hash and malloc's header) and a
// bucket.
constexpr double kKeyBytes = 40 + 80 + 8;
// Each worker's keys are merged into one table: as many again, and an index per key.
constexpr double kMergeFactor = 2;
// Bytes of one suffix class in its hash map: the node (key, index, next pointer, malloc's header)
// and a bucket.
constexpr double kClassBytes = 40;

struct Sizes {
  double cells = 0, rows = 0, rows_per_cell = 0, dims = 0;
  std::vector<double> distinct;  // per dimension: the distinct bounds (counted over every cell; else the most the sizes allow)
  bool counted = false;
  std::vector<double> window;    // per dimension: the cells of one window
};

// The distinct bounds are counted from at most this many mean boxes (a fraction of a second to
// seconds: one per combination of what each dimension reads, and row of its cell) and this many
// keys per dimension; beyond, the most that the sizes allow.
constexpr double kMaxCountedMeanBoxes = double(std::size_t(1) << 21);
constexpr std::size_t kMaxCountedKeys = std::size_t(1) << 21;

Sizes sizes_of(const Abstraction& a, unsigned threads) {
  Sizes s;
  s.cells = double(a.states.size());
  s.rows_per_cell = double(a.inputs.size()) * double(a.disturbances.size());
  s.rows = s.cells * s.rows_per_cell;
  s.dims = double(a.states.dims());
  const auto reads = bounds_reads(a);
  for (std::size_t d = 0; d < a.states.dims(); ++d) {
    double keys = s.rows;
    if (!reads.empty()) {
      keys = s.rows_per_cell;
      for (std::size_t j : reads[d]) keys *= double(a.states.count(j));
    }
    s.distinct.push_back(std::min(keys, s.rows));
    s.window.push_back(double(dense_window_width(a, d)));
  }
  // Every cell's rows, a superset of those the engine builds (the cells free under either bound,
  // which a footprint takes seconds to find): at least the distinct bounds it stores.
  double mean_boxes = 0;
  for (double tuples : s.distinct) mean_boxes += tuples;
  if (mean_boxes > kMaxCountedMeanBoxes) return s;
  const ImageEnclosure enclosure(a.config);
  const auto counted = count_distinct_bounds(a, enclosure_mean_box(enclosure, a.states, a.inputs, a.disturbances),
                                             threads, kMaxCountedKeys);
  if (!counted) return s;
  s.counted = true;
  for (std::size_t d = 0; d < s.distinct.size(); ++d) s.distinct[d] = double((*counted)[d]);
  return s;
}

// Per stage d >= 1, the most entries of a table over (prefix, suffix class).
// The most suffix classes of dimensions d..dims-1: combinations of their distinct bounds, at most
// one a row.
double suffix_classes(const Sizes& s, std::size_t d) {
  double classes = 1;
  for (std::size_t e = d; e < s.distinct.size(); ++e) classes *= s.distinct[e];
  return std::min(classes, s.rows);
}

double stage_entries(const Abstraction& a, const Sizes& s, std::size_t d) {
  double prefixes = 1;
  for (std::size_t j = 0; j < d; ++j) prefixes *= double(a.states.count(j));
  return prefixes * suffix_classes(s, d);
}

double whole_tables_bytes(const Abstraction& a, const Sizes& s) {
  // Tables (a double each), the source lines' order and rank (two uint32), stage 0's order and
  // its running maxima (two doubles) over the first table; the cells' visit order and last choice
  // per bound.
  double entries = 0;
  for (std::size_t d = 1; d < a.states.dims(); ++d) entries += stage_entries(a, s, d);
  entries = std::min(entries, double(ProductSweep::kMaxTableEntries));
  const double first = a.states.dims() > 1 ? std::min(stage_entries(a, s, 1), entries) : s.cells;
  return entries * (8 + 8) + first * (8 + 16) + 2 * s.cells * (4 + 4);
}

double elimination_bytes(const Abstraction& a, const Sizes& s, const FactoredPlan& plan, unsigned threads) {
  // Q per bound; the shared ping-pong stage tensors, each as large as the largest output it
  // receives (the last run writes Q, a pair never writes its first stage's); per worker of a pair
  // of stages, the first stage's results of a run of lines; the tuples' windows.
  double bytes = 2 * double(plan.q_size) * 8;
  const auto& counts = a.states.counts();
  const std::vector<RobustFactoredSweep::StageRun> runs = RobustFactoredSweep::stage_runs(plan, counts);
  double tensor[2] = {0, 0};
  for (std::size_t r = 0; r + 1 < runs.size(); ++r)
    tensor[r % 2] = std::max(tensor[r % 2], double(plan.stages[runs[r].last].output_size));
  bytes += (tensor[0] + tensor[1]) * 8;
  double in_size = double(a.states.size()), run = 0;
  for (std::size_t k = 0; k + 1 < plan.stages.size(); ++k) {
    const double length = double(a.states.count(plan.stages[k].dimension));
    const double lines = std::max(in_size / length, 1.0);
    const double next_length = double(a.states.count(plan.stages[k + 1].dimension));
    run = std::max(run, double(plan.stages[k].output_size) / lines * next_length * 8);
    in_size = double(plan.stages[k].output_size);
  }
  bytes += double(threads) * run;
  // Per bound, each stage's walk: per combination of its new digits, two offsets, its order and
  // its search.
  for (const FactoredStage& stage : plan.stages) {
    double combinations = 1;
    for (std::size_t j = 0; j < stage.output.size(); ++j)
      if (!stage.input_stride[j]) combinations *= double(stage.output[j].radix);
    bytes += 2 * combinations * (8 + 8 + 4 + 4);
  }
  for (std::size_t d = 0; d < plan.reads.size(); ++d) {
    double tuples = 1;
    for (std::size_t v : plan.reads[d]) tuples *= double(plan.variables[v].count);
    bytes += tuples * (4 + 1);
    // Per bound, the distinct windows packed for the threshold search: lower and upper masses,
    // padded to whole lanes and followed by a lane of the outcomes off the line, and a view each.
    const double cells = std::min(s.window[d], double(a.states.count(d))) + 2 * double(kThresholdLanes);
    bytes += 2 * (s.distinct[d] + 1) * (cells * 16 + double(sizeof(PackedWindow)));
  }
  return bytes;
}

// Whether auto takes the whole tables (ProductSweep::pays), from the counted distinct bounds and
// the noise's window for their mass intervals: a dimension's suffix classes are at least its
// distinct bounds (the last dimension's are exactly those).
bool tables_pay(const Abstraction& a, const Sizes& s) {
  double prefixes = 1, entries = 0;
  for (std::size_t d = 0; d < a.states.dims(); ++d) {
    const double window_cells = s.distinct[d] * (std::min(s.window[d], double(a.states.count(d))) + 2);
    if (double(a.states.count(d)) * s.distinct[d] > double(ProductSweep::kScanLengthPerOutcome) * window_cells)
      return false;
    if (d == 0) continue;
    prefixes *= double(a.states.count(d - 1));
    if (prefixes * s.distinct[d] > double(ProductSweep::kLinesPerRow) * s.rows) return false;
    entries += prefixes * s.distinct[d];
  }
  return entries <= double(ProductSweep::kMaxTableEntries);
}

double stage_cache_bytes(const Abstraction& a, const Sizes& s) {
  // Per bound, caches of at most kMaxStageCacheEntries doubles, none larger than 16 lines a row.
  double entries = 0;
  for (std::size_t d = 1; d < a.states.dims(); ++d) entries += std::min(stage_entries(a, s, d), 16 * s.rows);
  return 2 * std::min(entries, double(RobustStep::kMaxStageCacheEntries)) * 8;
}

}  // namespace

BoundsMemory estimate_bounds_memory(const Abstraction& a, BoundsMethod method, unsigned threads) {
  const Sizes s = sizes_of(a, threads);
  BoundsMemory memory;
  // Both bounds' roles and the cells needed, the policy's roles, the upper bound's inputs.
  memory.cells_bytes = s.cells * (2 + 1 + 1 + 4);
  const double suffix_digits = std::max(s.dims - 2, 0.0);
  memory.rows_bytes = s.rows * (s.dims + suffix_digits) * 4;
  double keys = 0, intervals_bytes = 0;
  for (std::size_t d = 0; d < s.distinct.size(); ++d) {
    keys += s.distinct[d];
    // The mass intervals (two doubles a cell) and the view of each distinct bound.
    intervals_bytes += s.distinct[d] * (std::min(s.window[d], double(a.states.count(d))) * 16 + 48);
  }
  memory.rows_bytes += intervals_bytes;
  // Every worker may meet every key; the merged table holds each once more. The intervals are
  // computed per key before they are copied into the pool; the suffix classes of one dimension at
  // a time are numbered in a hash map.
  double classes = 0;
  for (std::size_t d = 1; d + 1 < a.states.dims(); ++d) classes = std::max(classes, suffix_classes(s, d));
  memory.build_bytes =
      keys * kKeyBytes * (std::min(double(threads), s.cells) + kMergeFactor - 1) + intervals_bytes + classes * kClassBytes;

  std::string no_plan;
  const bool eliminates = method == BoundsMethod::Auto || method == BoundsMethod::Elimination;
  const std::optional<FactoredPlan> plan = eliminates ? RobustFactoredSweep::plan(a, &no_plan) : std::nullopt;
  const double tables = whole_tables_bytes(a, s);
  switch (method) {
    case BoundsMethod::Joint:
      memory.method = "joint";
      break;
    case BoundsMethod::Rows:
      memory.method = "rows";
      memory.method_bytes = stage_cache_bytes(a, s);
      break;
    case BoundsMethod::WholeTables:
      memory.method = "whole_tables";
      memory.method_bytes = tables;
      break;
    case BoundsMethod::Elimination:
      memory.method = "elimination";
      memory.method_bytes = plan ? elimination_bytes(a, s, *plan, threads) : 0;
      break;
    case BoundsMethod::Auto: {
      const double other = plan ? elimination_bytes(a, s, *plan, threads) : stage_cache_bytes(a, s);
      if (s.counted) {  // the method that auto takes
        const bool tables_taken = tables_pay(a, s);
        memory.method = tables_taken ? "whole_tables" : plan ? "elimination" : "rows";
        memory.method_bytes = tables_taken ? tables : other;
      } else {  // the dearest that it may take
        memory.method = tables >= other ? "whole_tables" : plan ? "elimination" : "rows";
        memory.method_bytes = std::max(tables, other);
      }
      break;
    }
  }
  return memory;
}

}  // namespace amytiss::detail
