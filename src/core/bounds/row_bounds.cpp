#include "bounds/row_bounds.hpp"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <unordered_map>
#include <unordered_set>

#include "bounds/lattice.hpp"
#include "common/parallel_for.hpp"

namespace amytiss::detail {

std::vector<std::vector<std::size_t>> bounds_reads(const Abstraction& a) {
  const auto uses = a.dynamics->dependencies();
  if (!uses) return {};
  std::vector<std::vector<std::size_t>> reads;
  for (std::size_t d = 0; d < a.states.dims(); ++d) {
    std::vector<std::size_t> dims = (*uses)[d].states;
    dims.push_back(d);  // the noise's scale may depend on it
    std::sort(dims.begin(), dims.end());
    dims.erase(std::unique(dims.begin(), dims.end()), dims.end());
    reads.push_back(dims);
  }
  return reads;
}

namespace {

using BoundsKey = RowBounds::BoundsKey;
// Keys compared bit for bit.
struct BoundsKeyEqual {
  bool operator()(const BoundsKey& a, const BoundsKey& b) const { return std::memcmp(&a, &b, sizeof(BoundsKey)) == 0; }
};
struct BoundsKeyHash {
  std::size_t operator()(const BoundsKey& key) const {
    std::uint64_t words[5];
    std::memcpy(words, &key, sizeof words);
    std::uint64_t hash = 0x9e3779b97f4a7c15ull;
    for (std::uint64_t word : words) hash = (hash ^ word) * 0x100000001b3ull + (hash >> 29);
    return std::size_t(hash);
  }
};

// One worker's distinct keys per dimension, in the order met, and the index of each.
struct WorkerTables {
  std::vector<std::vector<BoundsKey>> keys;
  std::vector<std::unordered_map<BoundsKey, std::uint32_t, BoundsKeyHash, BoundsKeyEqual>> index;
};

}  // namespace

RowBounds::BoundsKey bounds_key(const Grid& states, const MassBounds& mass, std::size_t d, std::size_t k, double lo,
                                double hi, double expansion) {
  const MassInterval scale = mass.scale_range(states.face(d, std::int64_t(k)), states.face(d, std::int64_t(k) + 1));
  return {lo, hi, scale.lo, scale.hi, expansion};
}

std::optional<std::vector<std::size_t>> count_distinct_bounds(const Abstraction& a, const MeanBox& mean_box,
                                                              unsigned threads, std::size_t max_keys) {
  const std::size_t dims = a.states.dims(), rows_per_cell = a.inputs.size() * a.disturbances.size();
  const std::vector<std::vector<std::size_t>> reads = bounds_reads(a);
  std::vector<std::size_t> distinct(dims);
  for (std::size_t d = 0; d < dims; ++d) {
    // A dimension's bounds depend only on the coordinates it reads: one cell per combination of
    // those (the others at index 0), every row of it.
    std::vector<std::size_t> read = reads.empty() ? std::vector<std::size_t>{} : reads[d];
    if (read.empty())
      for (std::size_t j = 0; j < dims; ++j) read.push_back(j);
    std::size_t tuples = 1;
    for (std::size_t j : read) tuples *= a.states.count(j);
    const MassBounds mass(*a.noise, d);
    using KeySet = std::unordered_set<BoundsKey, BoundsKeyHash, BoundsKeyEqual>;
    const unsigned workers = unsigned(std::max<std::size_t>(1, std::min<std::size_t>(threads, tuples)));
    const bool lattice_candidate = noise_free(*a.noise, d);
    std::vector<KeySet> sets(workers);
    std::atomic<bool> too_many{false};
    parallel_for(tuples, workers, [&](unsigned worker, std::size_t first, std::size_t last) {
      std::vector<double> lo(dims), hi(dims), expansion(dims);
      std::vector<std::size_t> multi(dims, 0);
      for (std::size_t tuple = first; tuple < last && !too_many; ++tuple) {
        for (std::size_t rest = tuple, j = read.size(); j-- > 0; rest /= a.states.count(read[j]))
          multi[read[j]] = rest % a.states.count(read[j]);
        const std::size_t cell = a.states.flat_index(multi.data());
        for (std::size_t r = 0; r < rows_per_cell; ++r) {
          mean_box(cell, r / a.disturbances.size(), r % a.disturbances.size(), lo.data(), hi.data(), expansion.data());
          sets[worker].insert(
              bounds_key(a.states, mass, d, multi[d], lo[d], hi[d], lattice_candidate ? expansion[d] : 0.0));
        }
        if (sets[worker].size() > max_keys) too_many = true;
      }
    });
    if (too_many) return std::nullopt;
    for (unsigned worker = 1; worker < workers; ++worker) sets[0].insert(sets[worker].begin(), sets[worker].end());
    distinct[d] = sets[0].size();
  }
  return distinct;
}

// Per dimension, the rows of one worker that share a mean box and scale: key = the cell's index
// over the dimensions read, times the rows per cell, plus the row within the cell.
class SharedBounds {
 public:
  static constexpr std::uint32_t kUnknown = ~std::uint32_t(0);
  // At most this many keys per dimension; beyond, the dimension shares nothing.
  static constexpr std::size_t kMaxKeys = std::size_t(1) << 22;

  SharedBounds(const Grid& states, std::size_t rows_per_cell, const std::vector<std::vector<std::size_t>>& reads)
      : rows_per_cell_(rows_per_cell), reads_(reads), known_(states.dims()) {
    for (std::size_t d = 0; d < reads.size(); ++d) {
      std::size_t keys = rows_per_cell;
      for (std::size_t j : reads[d]) keys *= states.count(j);
      if (reads[d].size() < states.dims() && keys <= kMaxKeys) known_[d].assign(keys, kUnknown);
    }
  }
  // The cell's part of each dimension's key.
  void enter(const Grid& states, const std::size_t* multi) {
    cell_key_.assign(known_.size(), 0);
    for (std::size_t d = 0; d < known_.size(); ++d) {
      if (known_[d].empty()) continue;
      for (std::size_t j : reads_[d]) cell_key_[d] = cell_key_[d] * states.count(j) + multi[j];
    }
  }
  std::uint32_t* slot(std::size_t d, std::size_t row_in_cell) {
    return known_[d].empty() ? nullptr : &known_[d][cell_key_[d] * rows_per_cell_ + row_in_cell];
  }

 private:
  std::size_t rows_per_cell_;
  const std::vector<std::vector<std::size_t>>& reads_;
  std::vector<std::vector<std::uint32_t>> known_;
  std::vector<std::size_t> cell_key_;
};

RowBounds::RowBounds(const Grid& states, const Grid& inputs, const Grid& disturbances, const NoiseModel& noise,
                     const MeanBox& mean_box, const std::vector<bool>& needed, unsigned threads,
                     const std::vector<std::vector<std::size_t>>& reads)
    : dims_(states.dims()), inputs_(inputs.size()), disturbances_(disturbances.size()) {
  const std::size_t cells = states.size(), rows_per_cell = inputs_ * disturbances_;
  index_.assign(cells * rows_per_cell * dims_, 0);
  threads = unsigned(std::max<std::size_t>(1, std::min<std::size_t>(threads, cells)));
  std::vector<MassBounds> per_dimension;
  for (std::size_t d = 0; d < dims_; ++d) per_dimension.emplace_back(noise, d);
  std::vector<WorkerTables> tables(threads);
  parallel_for(cells, threads, [&](unsigned worker, std::size_t first_cell, std::size_t last_cell) {
    WorkerTables& table = tables[worker];
    table.keys.resize(dims_);
    table.index.resize(dims_);
    SharedBounds shared(states, rows_per_cell, reads);
    std::vector<double> lo(dims_), hi(dims_), expansion(dims_);
    std::vector<std::size_t> multi(dims_);
    std::vector<std::uint32_t*> slots(dims_);
    for (std::size_t cell = first_cell; cell < last_cell; ++cell) {
      if (!needed[cell]) continue;
      states.multi_index(cell, multi.data());
      shared.enter(states, multi.data());
      for (std::size_t r = row(cell, 0, 0); r < row(cell + 1, 0, 0); ++r) {
        bool known = true;
        for (std::size_t d = 0; d < dims_; ++d) {
          slots[d] = shared.slot(d, r - row(cell, 0, 0));
          if (slots[d] && *slots[d] != SharedBounds::kUnknown)
            index_[r * dims_ + d] = *slots[d];
          else
            known = false;
        }
        if (known) continue;
        std::fill(expansion.begin(), expansion.end(), 0.0);
        mean_box(cell, (r / disturbances_) % inputs_, r % disturbances_, lo.data(), hi.data(), expansion.data());
        for (std::size_t d = 0; d < dims_; ++d) {
          if (slots[d] && *slots[d] != SharedBounds::kUnknown) continue;
          const BoundsKey key =
              bounds_key(states, per_dimension[d], d, multi[d], lo[d], hi[d], noise_free(noise, d) ? expansion[d] : 0.0);
          const auto found = table.index[d].emplace(key, std::uint32_t(table.keys[d].size()));
          index_[r * dims_ + d] = found.first->second;
          if (slots[d]) *slots[d] = found.first->second;
          if (found.second) table.keys[d].push_back(key);
        }
      }
    }
  });
  // One entry per distinct key over all workers (a later worker's key that an earlier one has
  // takes that one's index), then the bounds of each once, on all workers.
  std::vector<std::vector<BoundsKey>> keys(dims_);
  std::vector<std::unordered_map<BoundsKey, std::uint32_t, BoundsKeyHash, BoundsKeyEqual>> merged(dims_);
  std::vector<std::vector<std::vector<std::uint32_t>>> global(threads, std::vector<std::vector<std::uint32_t>>(dims_));
  for (unsigned worker = 0; worker < threads; ++worker) {
    for (std::size_t d = 0; d < dims_ && !tables[worker].keys.empty(); ++d) {
      for (const BoundsKey& key : tables[worker].keys[d]) {
        const auto found = merged[d].emplace(key, std::uint32_t(keys[d].size()));
        global[worker][d].push_back(found.first->second);
        if (found.second) keys[d].push_back(key);
      }
    }
  }
  lattice_.assign(dims_, false);
  for (std::size_t d = 0; d < dims_; ++d) {
    lattice_[d] = noise_free(noise, d);
    for (const BoundsKey& key : keys[d])
      lattice_[d] = lattice_[d] && lattice_row(states, d, key.m_lo, key.m_hi, key.expansion);
  }
  compute_bounds(states, per_dimension, keys, threads);
  parallel_for(cells, threads, [&](unsigned worker, std::size_t first_cell, std::size_t last_cell) {
    for (std::size_t cell = first_cell; cell < last_cell; ++cell) {
      if (!needed[cell]) continue;
      for (std::size_t r = row(cell, 0, 0); r < row(cell + 1, 0, 0); ++r)
        for (std::size_t d = 0; d < dims_; ++d) index_[r * dims_ + d] = global[worker][d][index_[r * dims_ + d]];
    }
  });
  number_suffix_classes(needed);
}

void RowBounds::compute_bounds(const Grid& states, const std::vector<MassBounds>& per_dimension,
                               const std::vector<std::vector<BoundsKey>>& keys, unsigned threads) {
  std::vector<std::vector<DimensionBounds>> bounds(dims_);
  for (std::size_t d = 0; d < dims_; ++d) {
    bounds[d].resize(keys[d].size());
    parallel_for(keys[d].size(), threads, [&](unsigned, std::size_t first, std::size_t last) {
      for (std::size_t i = first; i < last; ++i)
        bounds[d][i] = lattice_[d] ? lattice_bounds(states, d, keys[d][i].m_lo, keys[d][i].m_hi)
                                   : per_dimension[d].dimension_bounds(states, keys[d][i].m_lo, keys[d][i].m_hi,
                                                                       keys[d][i].s_lo, keys[d][i].s_hi);
    });
    for (const DimensionBounds& one : bounds[d]) pool_size_ += one.cells.size();
  }
  // The views point into the pool once it is complete.
  pool_.reserve(pool_size_);
  distinct_.assign(dims_, {});
  for (std::size_t d = 0; d < dims_; ++d)
    for (const DimensionBounds& one : bounds[d]) {
      distinct_[d].push_back({one.first, one.cells.size(), nullptr, one.leave, one.cut});
      pool_.insert(pool_.end(), one.cells.begin(), one.cells.end());
    }
  std::size_t offset = 0;
  for (std::size_t d = 0; d < dims_; ++d)
    for (DimensionView& view : distinct_[d]) {
      view.cells = pool_.data() + offset;
      offset += view.count;
    }
}

void RowBounds::number_suffix_classes(const std::vector<bool>& needed) {
  // class_d(row) numbers the pairs (bounds of d, class_{d+1}(row)); the last dimension's class is
  // its bounds' index.
  suffix_classes_.assign(dims_, 0);
  suffix_parts_.assign(dims_, {});
  if (dims_ < 2) return;
  suffix_classes_[dims_ - 1] = distinct_[dims_ - 1].size();
  for (std::uint32_t b = 0; b < distinct_[dims_ - 1].size(); ++b) suffix_parts_[dims_ - 1].push_back({b, 0});
  const std::size_t rows_per_cell = inputs_ * disturbances_, middle = dims_ - 2;
  suffix_class_.assign(needed.size() * rows_per_cell * middle, 0);
  for (std::size_t d = dims_ - 1; d-- > 1;) {
    std::unordered_map<std::uint64_t, std::uint32_t> classes;
    for (std::size_t cell = 0; cell < needed.size(); ++cell) {
      if (!needed[cell]) continue;
      for (std::size_t r = cell * rows_per_cell; r < (cell + 1) * rows_per_cell; ++r) {
        const std::uint64_t next = suffix_class(r, d + 1);
        const std::uint64_t pair = (next << 32) | index_[r * dims_ + d];
        const auto found = classes.emplace(pair, std::uint32_t(classes.size()));
        suffix_class_[r * middle + d - 1] = found.first->second;
        if (found.second) suffix_parts_[d].push_back({index_[r * dims_ + d], std::uint32_t(next)});
      }
    }
    suffix_classes_[d] = classes.size();
  }
}

std::size_t RowBounds::bytes() const {
  std::size_t views = 0;
  for (const auto& table : distinct_) views += table.size();
  return (index_.size() + suffix_class_.size()) * sizeof(std::uint32_t) + views * sizeof(DimensionView) + pool_size_ * sizeof(MassInterval);
}

}  // namespace amytiss::detail
