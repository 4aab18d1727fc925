#pragma once
// The content digest of a policy file: 64 bits over every attribute, the configuration text and
// every array, in a fixed order, stored as the attribute content_digest (16 hex digits) and
// recomputed by the reader. Fed with 64-bit words, so it does not depend on the byte order.
#include <cstdint>
#include <string>

#include "amytiss/policy.hpp"

namespace amytiss::detail {

/// The attributes on / of a policy file, in the order the digest takes them.
struct PolicyFileAttributes {
  std::string format;
  std::uint64_t format_version = 0;
  std::string config_hash, computed_by, run_id;
  std::uint64_t engine_version = 0, horizon = 0;
  std::string spec;
  std::uint64_t stationary = 0, iterations = 0, converged = 0;  ///< unbounded specifications only
  std::string guarantee;  ///< "system" for continuous-system bounds; empty (not written) otherwise
};

/// The input grid's points, row i = input i (the /input_values dataset).
std::vector<double> input_points(const Grid& inputs);

/// A value array as the file stores it: the policy's float64 values or their float32 roundings;
/// element i reads as a double (float32 widens exactly), so a reader that widens what it reads
/// gets the writer's digest.
class StoredValues {
 public:
  StoredValues(const std::vector<double>& values) : doubles_(&values) {}
  StoredValues(const std::vector<float>& values) : floats_(&values) {}
  std::size_t size() const { return doubles_ ? doubles_->size() : floats_->size(); }
  double operator[](std::size_t i) const { return doubles_ ? (*doubles_)[i] : double((*floats_)[i]); }
  bool is_float32() const { return floats_ != nullptr; }
  const void* data() const { return doubles_ ? static_cast<const void*>(doubles_->data()) : floats_->data(); }

 private:
  const std::vector<double>* doubles_ = nullptr;
  const std::vector<float>* floats_ = nullptr;
};

/// 16 hex digits, over `values` and `upper_values` as stored (the policy's own or their float32
/// roundings) and every other array of `policy`.
std::string policy_digest(const PolicyFileAttributes& attributes, const std::string& config_yaml,
                          const Policy& policy, StoredValues values, StoredValues upper_values);

}  // namespace amytiss::detail
