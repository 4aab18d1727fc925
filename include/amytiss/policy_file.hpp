#pragma once
// Policy files (HDF5). Layout (format_version 1), all documented in README "Policy file":
//   attributes on /: format = "amytiss-policy", format_version = 1, config_hash (16 hex digits),
//                    computed_by, horizon, spec
//   /config            string: canonical YAML of the configuration (to_yaml)
//   /states/{lb,eta,counts}, /inputs/{lb,eta,counts}   float64 / uint64 vectors
//   /values            float64 (horizon+1, n0, n1, ...)   V_k(x)
//   /input_index       uint32  (horizon,   n0, n1, ...)   flat index of u*(x,k) in the input grid
//   /input_values      float64 (n_inputs, input_dims)      the input grid's points
//   /roles             uint8   (n0, n1, ...)  0 free, 1 fixed zero (avoid/unsafe), 2 fixed one (target)
// Files are written to "<path>.tmp.<pid>" and renamed, so a reader never sees half a file.
#include <string>

#include "amytiss/config.hpp"
#include "amytiss/policy.hpp"

namespace amytiss {

/// Writes atomically. Throws PolicyFileError on I/O failure.
void write_policy_file(const std::string& path, const Policy& policy, const Config& config);

struct LoadedPolicy {
  Policy policy;
  std::string config_yaml;
  std::string config_hash;
};

/// Reads a policy file. Throws PolicyFileError when the file is missing, truncated, corrupt, not
/// an amytiss policy or of another format version, with a message that says which.
LoadedPolicy read_policy_file(const std::string& path);
/// Reads and checks that the file was made from `config` (same config_hash); throws
/// PolicyFileError naming both hashes otherwise.
LoadedPolicy read_policy_file_for(const std::string& path, const Config& config);

namespace detail {
/// write_policy_file with a chosen format name and version and without the value checks (values
/// in [0, 1], input indices in range): only for tests of the reader's refusals.
void write_policy_file_as(const std::string& path, const Policy& policy, const Config& config,
                          const std::string& format, unsigned format_version);
}  // namespace detail

}  // namespace amytiss
