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

/// 16 hex digits.
std::string policy_digest(const PolicyFileAttributes& attributes, const std::string& config_yaml,
                          const Policy& policy);

}  // namespace amytiss::detail
