// Supports, attractors and end components of the abstraction's game (serial/game_graph.hpp).
#include "serial/game_graph.hpp"

#include <algorithm>
#include <cassert>
#include <utility>

namespace amytiss::detail {

namespace {

// Whether the whole law of one dimension (the unit support [lo, hi] scaled by `scale` around
// `mean`, or the point `mean` when the scale is 0) falls in the cells first..last: decided from the
// support's ends against the same cell faces the masses use, not from a sum of masses (laws whose
// masses sum to 1 - 1e-16 in double keep their whole mass all the same).
bool support_kept(const Grid& states, std::size_t dim, std::int64_t first, std::int64_t last, double mean,
                  double scale, std::pair<double, double> unit_support) {
  const double lo = states.face(dim, first);
  const double hi = states.face(dim, last + 1);
  if (scale == 0.0) return lo <= mean && mean < hi;
  return mean + scale * unit_support.first >= lo && mean + scale * unit_support.second <= hi;
}

}  // namespace

GameSupports::GameSupports(const Abstraction& a)
    : a_(a), dims_(a.states.dims()), inputs_(a.inputs.size()), disturbances_(a.disturbances.size()) {
  for (std::size_t x = 0; x < a.states.size(); ++x)
    if (a.roles[x] == CellRole::Free) free_list_.push_back(x);
  const std::size_t rows = free_list_.size() * inputs_ * disturbances_;
  boxes_.assign(rows * 2 * dims_, 0);
  leaks_.assign(rows, 1);
  empty_.assign(rows, 1);
  const NoiseModel& noise = *a.noise;
  std::vector<double> x(dims_), mean(dims_), masses;
  std::vector<std::int64_t> first(dims_), last(dims_);
  for (std::size_t rank = 0; rank < free_list_.size(); ++rank) {
    a.states.point(free_list_[rank], x.data());
    for (std::size_t u = 0; u < inputs_; ++u) {
      const std::vector<double> input = a.inputs.point(u);
      for (std::size_t w = 0; w < disturbances_; ++w) {
        const std::size_t r = row(rank, u, w);
        const std::vector<double> disturbance = a.disturbances.point(w);
        a.dynamics->evaluate(x.data(), input.data(), disturbance.data(), mean.data());
        if (!noise.window(a.states, mean.data(), first.data(), last.data())) continue;
        std::uint32_t* box = &boxes_[r * 2 * dims_];
        bool empty = false;
        // A full covariance's rows always lose their tails.
        bool kept = noise.separable();
        for (std::size_t d = 0; d < dims_ && !empty; ++d) {
          if (!noise.separable()) {
            box[2 * d] = std::uint32_t(first[d]);
            box[2 * d + 1] = std::uint32_t(last[d]);
            continue;
          }
          masses.resize(std::size_t(last[d] - first[d] + 1));
          const double scale = noise.scale(d, x.data());
          noise.cell_masses(d, first[d], last[d], mean[d], scale, masses.data());
          std::int64_t lo = -1, hi = -1;
          for (std::size_t k = 0; k < masses.size(); ++k)
            if (masses[k] > 0) {
              if (lo < 0) lo = std::int64_t(k);
              hi = std::int64_t(k);
            }
          if (lo < 0) {
            empty = true;
            break;
          }
          box[2 * d] = std::uint32_t(first[d] + lo);
          box[2 * d + 1] = std::uint32_t(first[d] + hi);
          kept = kept && support_kept(a.states, d, first[d] + lo, first[d] + hi, mean[d], scale, noise.unit_support(d));
        }
        empty_[r] = empty;
        leaks_[r] = empty || !kept;
      }
    }
  }
  prefix_strides_.assign(dims_, 1);
  std::size_t stride = 1;
  for (std::size_t d = dims_; d-- > 0;) {
    prefix_strides_[d] = stride;
    stride *= a.states.count(d) + 1;
  }
  prefix_.assign(stride, 0);
}

void GameSupports::for_each_cell(std::size_t r, const std::function<void(std::size_t)>& visit) const {
  const std::uint32_t* b = box(r);
  std::vector<std::size_t> multi(dims_);
  for (std::size_t d = 0; d < dims_; ++d) multi[d] = b[2 * d];
  while (true) {
    visit(a_.states.flat_index(multi.data()));
    std::size_t d = dims_;
    while (d-- > 0) {
      if (++multi[d] <= b[2 * d + 1]) break;
      multi[d] = b[2 * d];
    }
    if (d == std::size_t(-1)) return;
  }
}

void GameSupports::set_members(const std::vector<char>& member) {
  std::fill(prefix_.begin(), prefix_.end(), 0);
  std::vector<std::size_t> multi(dims_);
  for (std::size_t cell = 0; cell < member.size(); ++cell) {
    if (!member[cell]) continue;
    a_.states.multi_index(cell, multi.data());
    std::size_t at = 0;
    for (std::size_t d = 0; d < dims_; ++d) at += (multi[d] + 1) * prefix_strides_[d];
    prefix_[at] = 1;
  }
  // Running sums along each dimension turn the indicator into inclusive prefix counts.
  for (std::size_t d = 0; d < dims_; ++d) {
    const std::size_t step = prefix_strides_[d], extent = a_.states.count(d) + 1;
    for (std::size_t at = 0; at < prefix_.size(); ++at)
      if ((at / step) % extent != 0) prefix_[at] += prefix_[at - step];
  }
}

std::size_t GameSupports::members_in(std::size_t r) const {
  if (empty(r)) return 0;
  const std::uint32_t* b = box(r);
  std::int64_t total = 0;
  for (std::size_t corner = 0; corner < (std::size_t(1) << dims_); ++corner) {
    std::size_t at = 0;
    int sign = 1;
    for (std::size_t d = 0; d < dims_; ++d) {
      if (corner >> d & 1) {
        at += std::size_t(b[2 * d]) * prefix_strides_[d];  // just before the box's first cell
        sign = -sign;
      } else {
        at += (std::size_t(b[2 * d + 1]) + 1) * prefix_strides_[d];
      }
    }
    total += sign * std::int64_t(prefix_[at]);
  }
  return std::size_t(total);
}

std::size_t GameSupports::box_cells(std::size_t r) const {
  if (empty(r)) return 0;
  std::size_t cells = 1;
  for (std::size_t d = 0; d < dims_; ++d) cells *= std::size_t(box(r)[2 * d + 1] - box(r)[2 * d] + 1);
  return cells;
}

std::vector<char> positive_attractor(const Abstraction& a, GameSupports& supports) {
  std::vector<char> member(a.states.size(), 0);
  for (std::size_t x = 0; x < member.size(); ++x) member[x] = a.roles[x] == CellRole::FixedOne;
  for (bool changed = true; changed;) {
    changed = false;
    supports.set_members(member);
    for (std::size_t rank = 0; rank < supports.free_cells(); ++rank) {
      const std::size_t x = supports.free_cell(rank);
      if (member[x]) continue;
      for (std::size_t u = 0; u < supports.inputs() && !member[x]; ++u) {
        bool every = true;
        for (std::size_t w = 0; w < supports.disturbances() && every; ++w)
          every = supports.members_in(supports.row(rank, u, w)) > 0;
        if (every) member[x] = changed = true;
      }
    }
  }
  return member;
}

std::vector<char> sure_safe_set(const Abstraction& a, GameSupports& supports, std::vector<std::uint32_t>& sure_input) {
  std::vector<char> member(a.states.size(), 0);
  sure_input.assign(a.states.size(), 0);
  for (std::size_t x = 0; x < member.size(); ++x) member[x] = a.roles[x] == CellRole::Free;
  for (bool changed = true; changed;) {
    changed = false;
    supports.set_members(member);
    for (std::size_t rank = 0; rank < supports.free_cells(); ++rank) {
      const std::size_t x = supports.free_cell(rank);
      if (!member[x]) continue;
      bool kept = false;
      for (std::size_t u = 0; u < supports.inputs() && !kept; ++u) {
        bool every = true;
        for (std::size_t w = 0; w < supports.disturbances() && every; ++w) {
          const std::size_t r = supports.row(rank, u, w);
          every = !supports.leaks(r) && supports.members_in(r) == supports.box_cells(r);
        }
        if (every) {
          kept = true;
          sure_input[x] = std::uint32_t(u);
        }
      }
      if (!kept) member[x] = 0, changed = true;
    }
  }
  return member;
}

namespace {

// Tarjan's strongly connected components, iterative; nodes with in[node] only.
std::vector<std::int64_t> strongly_connected(const std::vector<std::vector<std::size_t>>& successors,
                                             const std::vector<char>& in, std::int64_t* count) {
  const std::size_t n = successors.size();
  std::vector<std::int64_t> component(n, -1), index(n, -1), low(n, 0);
  std::vector<char> on_stack(n, 0);
  std::vector<std::size_t> stack;
  std::vector<std::pair<std::size_t, std::size_t>> calls;  // node, next successor position
  std::int64_t next_index = 0;
  *count = 0;
  for (std::size_t root = 0; root < n; ++root) {
    if (!in[root] || index[root] >= 0) continue;
    calls.push_back({root, 0});
    index[root] = low[root] = next_index++;
    stack.push_back(root);
    on_stack[root] = 1;
    while (!calls.empty()) {
      auto& [node, position] = calls.back();
      if (position < successors[node].size()) {
        const std::size_t next = successors[node][position++];
        if (!in[next]) continue;
        if (index[next] < 0) {
          index[next] = low[next] = next_index++;
          stack.push_back(next);
          on_stack[next] = 1;
          calls.push_back({next, 0});
        } else if (on_stack[next]) {
          low[node] = std::min(low[node], index[next]);
        }
        continue;
      }
      const std::size_t done = node;
      calls.pop_back();
      if (!calls.empty()) low[calls.back().first] = std::min(low[calls.back().first], low[done]);
      if (low[done] == index[done]) {
        std::size_t member;
        do {
          member = stack.back();
          stack.pop_back();
          on_stack[member] = 0;
          component[member] = *count;
        } while (member != done);
        ++*count;
      }
    }
  }
  return component;
}

}  // namespace

bool row_stays(const GameSupports& supports, const std::vector<std::int64_t>& component, std::size_t rank,
               std::size_t input, std::size_t disturbance) {
  const std::size_t r = supports.row(rank, input, disturbance);
  const std::int64_t own = component[supports.free_cell(rank)];
  if (own < 0 || supports.leaks(r) || supports.empty(r)) return false;
  bool inside = true;
  supports.for_each_cell(r, [&](std::size_t cell) { inside = inside && component[cell] == own; });
  return inside;
}

std::vector<std::int64_t> end_components(const GameSupports& supports, std::size_t cells,
                                         const std::vector<char>& candidate, const InputFilter& input_allowed,
                                         const RowFilter& row_allowed) {
  std::vector<char> in = candidate;
  std::vector<std::int64_t> component(cells, -1);
  for (std::size_t x = 0; x < cells; ++x)
    if (in[x]) component[x] = 0;
  std::int64_t components = 1;
  while (true) {
    // Rows that stay in their cell's current component; cells without one leave.
    std::vector<std::vector<std::size_t>> successors(cells);
    bool removed = false;
    for (std::size_t rank = 0; rank < supports.free_cells(); ++rank) {
      const std::size_t x = supports.free_cell(rank);
      if (!in[x]) continue;
      bool stays = false;
      for (std::size_t u = 0; u < supports.inputs(); ++u) {
        if (!input_allowed(x, u)) continue;
        for (std::size_t w = 0; w < supports.disturbances(); ++w) {
          if (!row_allowed(x, u, w) || !row_stays(supports, component, rank, u, w)) continue;
          stays = true;
          supports.for_each_cell(supports.row(rank, u, w), [&](std::size_t cell) { successors[x].push_back(cell); });
        }
      }
      if (!stays) {
        in[x] = 0;
        component[x] = -1;
        removed = true;
      }
    }
    if (removed) continue;
    for (auto& list : successors) {
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
    }
    std::int64_t count = 0;
    const std::vector<std::int64_t> refined = strongly_connected(successors, in, &count);
    // Components only split: the same count means the same partition.
    const bool stable = count == components;
    component = refined;
    components = count;
    if (stable) return component;
  }
}

}  // namespace amytiss::detail
