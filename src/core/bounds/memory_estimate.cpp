#include "bounds/memory_estimate.hpp"

#include <algorithm>

#include "bounds/product/elimination.hpp"
#include "bounds/product/whole_tables.hpp"
#include "bounds/robust_step.hpp"
#include "bounds/row_bounds.hpp"

namespace amytiss::detail {
namespace {

// Bytes of one distinct key in a worker's tables: the key (four doubles) in the list and in the
// hash map's node (with its index, the next pointer and the cached hash) and a bucket.
constexpr double kKeyBytes = 32 + 56 + 8;
// Each worker's keys are merged into one table: as many again, and an index per key.
constexpr double kMergeFactor = 2;

struct Sizes {
  double cells = 0, rows = 0, rows_per_cell = 0, dims = 0;
  std::vector<double> distinct;  // per dimension: the most distinct bounds the sizes allow
  std::vector<double> window;    // per dimension: the cells of one window
};

Sizes sizes_of(const Abstraction& a) {
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
  return s;
}

// Per stage d >= 1, the most entries of a table over (prefix, suffix class).
double stage_entries(const Abstraction& a, const Sizes& s, std::size_t d) {
  double prefixes = 1, classes = 1;
  for (std::size_t j = 0; j < d; ++j) prefixes *= double(a.states.count(j));
  for (std::size_t e = d; e < a.states.dims(); ++e) classes *= s.distinct[e];
  return prefixes * std::min(classes, s.rows);
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

double elimination_bytes(const Abstraction& a, const FactoredPlan& plan, unsigned threads) {
  // Q per bound; the shared ping-pong stage tensors (none for two dimensions: one pair);
  // per worker of a pair of stages, the first stage's results of a run of lines; the tuples'
  // windows.
  double bytes = 2 * double(plan.q_size) * 8;
  if (a.states.dims() > 2) bytes += 2 * double(plan.largest_stage_tensor) * 8;
  double in_size = double(a.states.size()), run = 0;
  for (std::size_t k = 0; k + 1 < plan.stages.size(); ++k) {
    const double length = double(a.states.count(plan.stages[k].dimension));
    const double lines = std::max(in_size / length, 1.0);
    const double next_length = double(a.states.count(plan.stages[k + 1].dimension));
    run = std::max(run, double(plan.stages[k].output_size) / lines * next_length * 8);
    in_size = double(plan.stages[k].output_size);
  }
  bytes += double(threads) * run;
  for (std::size_t d = 0; d < plan.reads.size(); ++d) {
    double tuples = 1;
    for (std::size_t v : plan.reads[d]) tuples *= double(plan.variables[v].count);
    bytes += tuples * (4 + 1);
  }
  return bytes;
}

double stage_cache_bytes(const Abstraction& a, const Sizes& s) {
  // Per bound, caches of at most kMaxStageCacheEntries doubles, none larger than 16 lines a row.
  double entries = 0;
  for (std::size_t d = 1; d < a.states.dims(); ++d) entries += std::min(stage_entries(a, s, d), 16 * s.rows);
  return 2 * std::min(entries, double(RobustStep::kMaxStageCacheEntries)) * 8;
}

}  // namespace

BoundsMemory estimate_bounds_memory(const Abstraction& a, BoundsMethod method, unsigned threads) {
  const Sizes s = sizes_of(a);
  BoundsMemory memory;
  // Both bounds' roles and the cells needed, the policy's roles, the upper bound's inputs.
  memory.cells_bytes = s.cells * (2 + 1 + 1 + 4);
  const double suffix_digits = std::max(s.dims - 2, 0.0);
  memory.rows_bytes = s.rows * (s.dims + suffix_digits) * 4;
  double keys = 0;
  for (std::size_t d = 0; d < s.distinct.size(); ++d) {
    keys += s.distinct[d];
    // The mass intervals (two doubles a cell) and the view of each distinct bound.
    memory.rows_bytes += s.distinct[d] * (std::min(s.window[d], double(a.states.count(d))) * 16 + 48);
  }
  // Every worker may meet every key; the merged table holds each once more.
  memory.build_bytes = keys * kKeyBytes * (std::min(double(threads), s.cells) + kMergeFactor - 1);

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
      memory.method_bytes = plan ? elimination_bytes(a, *plan, threads) : 0;
      break;
    case BoundsMethod::Auto: {
      const double other = plan ? elimination_bytes(a, *plan, threads) : stage_cache_bytes(a, s);
      memory.method = tables >= other ? "whole_tables" : plan ? "elimination" : "rows";
      memory.method_bytes = std::max(tables, other);
      break;
    }
  }
  return memory;
}

}  // namespace amytiss::detail
