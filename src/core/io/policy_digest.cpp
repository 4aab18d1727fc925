#include "io/policy_digest.hpp"

#include "amytiss/format.hpp"
#include "io/refinement_format.hpp"

#include <algorithm>
#include <cstring>

namespace amytiss::detail {
namespace {

class ContentDigest {
 public:
  void add(std::uint64_t word) {
    state_ = (state_ ^ word) * 0x9e3779b97f4a7c15ull;
    state_ ^= state_ >> 29;
  }
  void add(const std::string& text) {
    add(std::uint64_t(text.size()));
    for (std::size_t at = 0; at < text.size(); at += 8) {
      std::uint64_t word = 0;
      for (std::size_t i = at; i < std::min(text.size(), at + 8); ++i)
        word |= std::uint64_t(static_cast<unsigned char>(text[i])) << (8 * (i - at));
      add(word);
    }
  }
  void add(StoredValues values) {
    add(std::uint64_t(values.size()));
    for (std::size_t i = 0; i < values.size(); ++i) {
      const double value = values[i];
      std::uint64_t bits = 0;
      std::memcpy(&bits, &value, sizeof bits);
      add(bits);
    }
  }
  void add(const std::vector<double>& values) { add(StoredValues(values)); }
  template <typename Unsigned>
  void add(const std::vector<Unsigned>& values) {
    add(std::uint64_t(values.size()));
    for (Unsigned value : values) add(std::uint64_t(value));
  }
  std::string hex() const { return hex16(state_); }

 private:
  std::uint64_t state_ = 0xcbf29ce484222325ull;
};

void add_attributes(ContentDigest& digest, const PolicyFileAttributes& attributes) {
  digest.add(attributes.format);
  digest.add(attributes.format_version);
  digest.add(attributes.config_hash);
  digest.add(attributes.computed_by);
  digest.add(attributes.run_id);
  digest.add(attributes.engine_version);
  digest.add(attributes.horizon);
  digest.add(attributes.spec);
  // Present only in files of unbounded specifications: other files keep their digest.
  if (attributes.stationary) {
    digest.add(attributes.stationary);
    digest.add(attributes.iterations);
    digest.add(attributes.converged);
  }
  // Present only in files of continuous-system bounds: other files keep their digest.
  if (!attributes.guarantee.empty()) digest.add(attributes.guarantee);
}

void add_grid(ContentDigest& digest, const Grid& grid) {
  digest.add(grid.lb());
  digest.add(grid.eta());
  digest.add(std::vector<std::uint64_t>(grid.counts().begin(), grid.counts().end()));
  // Only a grid with faces adds them: uniform grids keep their digest (their faces follow from lb and eta).
  if (!grid.all_uniform())
    for (std::size_t d = 0; d < grid.dims(); ++d) digest.add(grid.faces(d));
}

}  // namespace

std::vector<double> input_points(const Grid& inputs) {
  std::vector<double> points(inputs.size() * inputs.dims());
  for (std::size_t flat = 0; flat < inputs.size(); ++flat) inputs.point(flat, points.data() + flat * inputs.dims());
  return points;
}

std::string policy_digest(const PolicyFileAttributes& attributes, const std::string& config_yaml,
                          const Policy& policy, StoredValues values, StoredValues upper_values) {
  ContentDigest digest;
  add_attributes(digest, attributes);
  digest.add(config_yaml);
  add_grid(digest, policy.states);
  add_grid(digest, policy.inputs);
  digest.add(values);
  digest.add(policy.input_index);
  digest.add(input_points(policy.inputs));
  std::vector<std::uint8_t> roles(policy.roles.size());
  for (std::size_t i = 0; i < roles.size(); ++i) roles[i] = std::uint8_t(policy.roles[i]);
  digest.add(roles);
  if (policy.stationary || policy.guarantee == Guarantee::System) digest.add(upper_values);
  // Present only in files of a refined synthesis: other files keep their digest.
  if (!policy.refinement.rounds.empty()) digest.add(refinement_words(policy.refinement));
  return digest.hex();
}

}  // namespace amytiss::detail
