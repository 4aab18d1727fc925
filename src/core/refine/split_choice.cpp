#include "refine/split_choice.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "amytiss/closed_loop.hpp"
#include "amytiss/format.hpp"
#include "amytiss/grid_rules.hpp"
#include "bounds/lattice.hpp"
#include "common/parallel_for.hpp"

namespace amytiss::detail {
namespace {

// A cell is not halved below this share of its dimension's covered extent: finer than any noise
// the bounds resolve, and far above the faces' rounding.
constexpr double kMinWidthShare = 1e-9;

using GapTable = std::vector<std::vector<double>>;

GapTable zero_table(const Grid& states) {
  GapTable table(states.dims());
  for (std::size_t d = 0; d < states.dims(); ++d) table[d].assign(states.count(d), 0.0);
  return table;
}

void add_table(GapTable& sum, const GapTable& part) {
  for (std::size_t d = 0; d < sum.size(); ++d)
    for (std::size_t k = 0; k < sum[d].size(); ++k) sum[d][k] += part[d][k];
}

// upper - lower of `cell` with `steps` steps gone (a stationary policy has one row).
double cell_gap(const Policy& policy, unsigned step, std::size_t cell) {
  const unsigned row = policy.stationary ? 0u : std::min(step, policy.horizon);
  return policy.upper_value(row, cell) - policy.value(row, cell);
}

constexpr std::int64_t kOutside = -1;

// One episode's cells (kOutside beyond the grid), in step order: each adds its gap less the next
// one's, to every dimension's interval it lies in.
void attribute_path(const Policy& policy, const std::vector<std::int64_t>& path, double weight, GapTable& table,
                    std::vector<std::size_t>& multi) {
  const Grid& states = policy.states;
  auto gap_of = [&](std::size_t t) { return path[t] == kOutside ? 0.0 : cell_gap(policy, unsigned(t), std::size_t(path[t])); };
  double gap = path.empty() ? 0.0 : gap_of(0);
  for (std::size_t t = 0; t < path.size(); ++t) {
    const double next = t + 1 < path.size() ? gap_of(t + 1) : 0.0;
    if (path[t] != kOutside) {
      states.multi_index(std::size_t(path[t]), multi.data());
      for (std::size_t d = 0; d < states.dims(); ++d) table[d][multi[d]] += weight * (gap - next);
    }
    gap = next;
  }
}

GapTable attribute_free_cells(const Policy& policy) {
  const Grid& states = policy.states;
  GapTable table = zero_table(states);
  std::size_t free_cells = 0;
  for (CellRole role : policy.roles) free_cells += role == CellRole::Free;
  std::vector<std::size_t> multi(states.dims());
  for (std::size_t cell = 0; cell < states.size(); ++cell) {
    if (policy.roles[cell] != CellRole::Free) continue;
    states.multi_index(cell, multi.data());
    for (std::size_t d = 0; d < states.dims(); ++d) table[d][multi[d]] += cell_gap(policy, 0, cell) / double(free_cells);
  }
  return table;
}

struct Candidate {
  std::size_t dim = 0, interval = 0;
  double weight = 0;
};

// Intervals of noisy dimensions with a positive weighed gap, the heaviest first.
std::vector<Candidate> candidates(const Grid& grid, const NoiseModel& noise, const GapTable& gap) {
  std::vector<Candidate> out;
  for (std::size_t d = 0; d < grid.dims(); ++d) {
    const double scale = noise.base_scale()[d];
    if (noise_free(noise, d) || !(scale > 0)) continue;
    const double smallest = kMinWidthShare * (grid.covered_high(d) - grid.covered_low(d));
    for (std::size_t k = 0; k < grid.count(d); ++k) {
      const double width = grid.width(d, k);
      const double weight = std::max(gap[d][k], 0.0) * width / scale;
      if (weight > 0 && width / 2 > smallest) out.push_back({d, k, weight});
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) { return a.weight > b.weight; });
  return out;
}

GridSpec halved(const GridSpec& current, const Grid& grid, const std::vector<std::vector<char>>& marked) {
  GridSpec next = current;
  for (std::size_t d = 0; d < grid.dims(); ++d) {
    if (std::find(marked[d].begin(), marked[d].end(), 1) == marked[d].end()) continue;
    const std::vector<double> faces = grid.faces(d);
    std::vector<double> refined;
    for (std::size_t k = 0; k + 1 < faces.size(); ++k) {
      refined.push_back(faces[k]);
      if (marked[d][k]) refined.push_back(faces[k] + (faces[k + 1] - faces[k]) / 2);
    }
    refined.push_back(faces.back());
    set_dimension_faces(next, d, std::move(refined));
  }
  return next;
}

}  // namespace

GapTable attribute_gap(const Abstraction& abstraction, const Policy& policy, const std::vector<std::vector<double>>& at,
                       std::size_t episodes, std::uint64_t seed) {
  if (at.empty()) return attribute_free_cells(policy);
  const Grid& states = policy.states;
  const ClosedLoop loop(abstraction.config, policy);
  std::vector<std::size_t> start_cells;
  for (const auto& point : at) start_cells.push_back(*states.cell_of(point.data()));
  const std::size_t per_start = std::max<std::size_t>(1, episodes / at.size());
  const std::size_t total = per_start * at.size();
  const double weight = 1.0 / double(per_start);
  const unsigned parts = host_threads();
  std::vector<GapTable> tables(parts, zero_table(states));
  parallel_for(total, parts, [&](unsigned part, std::size_t first, std::size_t last) {
    std::vector<std::int64_t> path;
    std::vector<std::size_t> multi(states.dims());
    const StateObserver observe = [&](unsigned, const double* state) {
      const auto cell = states.cell_of(state);
      path.push_back(cell ? std::int64_t(*cell) : kOutside);
    };
    for (std::size_t e = first; e < last; ++e) {
      std::mt19937_64 random(episode_seed(seed, e));
      path.clear();
      loop.run(point_in_cell(states, start_cells[e / per_start], random), random, observe);
      attribute_path(policy, path, weight, tables[part], multi);
    }
  });
  GapTable table = zero_table(states);
  for (const GapTable& part : tables) add_table(table, part);
  return table;
}

SplitChoice choose_splits(const GridSpec& current, const NoiseModel& noise, const GapTable& gap,
                          std::uint64_t max_cells) {
  SplitChoice choice;
  const Grid grid(current);
  const std::vector<Candidate> ranked = candidates(grid, noise, gap);
  if (ranked.empty()) {
    choice.why_none = "no interval to halve: no cell of a noisy state dimension adds to the gap (it comes from "
                      "noise-free dimensions, the noise's truncation or the sets)";
    return choice;
  }
  double total = 0, covered = 0;
  for (const Candidate& c : ranked) total += c.weight;
  std::vector<std::size_t> counts = grid.counts();
  std::uint64_t cells = grid.size();
  const auto cap = std::min<std::uint64_t>(max_cells, std::uint64_t(kRoundGrowth * double(cells)));
  std::vector<std::vector<char>> marked(grid.dims());
  for (std::size_t d = 0; d < grid.dims(); ++d) marked[d].assign(grid.count(d), 0);
  for (const Candidate& c : ranked) {
    if (covered >= kCoveredShare * total) break;
    const std::uint64_t next = cells / counts[c.dim] * (counts[c.dim] + 1);
    if (next > cap) continue;
    marked[c.dim][c.interval] = 1;
    counts[c.dim] += 1;
    cells = next;
    covered += c.weight;
    choice.splits += 1;
  }
  if (choice.splits == 0) {
    const Candidate& top = ranked.front();
    choice.why_none = "max_states " + std::to_string(max_cells) + " reached: halving the interval that adds most to "
                      "the gap (dimension " + std::to_string(top.dim) + ") would make " +
                      std::to_string(cells / counts[top.dim] * (counts[top.dim] + 1)) + " cells";
    return choice;
  }
  choice.states = halved(current, grid, marked);
  choice.cells = cells;
  return choice;
}

}  // namespace amytiss::detail
