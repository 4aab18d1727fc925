#pragma once
// Policy files (HDF5). Layout (format_version 2), all documented in docs/policy_file.md:
//   attributes on /: format = "amytiss-policy", format_version = 2, config_hash (16 hex digits),
//                    computed_by, run_id (16 hex digits), engine_version, horizon, spec,
//                    content_digest (16 hex digits over all attributes and datasets)
//   /config            string: canonical YAML of the configuration (to_yaml)
//   /states/{lb,eta,counts}, /inputs/{lb,eta,counts}   float64 / uint64 vectors (eta NaN for a
//                      state dimension given by its faces)
//   /states/faces/<d>  float64 (n_d + 1,) the cell faces of state dimension d (every dimension;
//                      absent in older files, whose grids are uniform)
//   /values            float64 (horizon+1, n0, n1, ...)   V_k(x); float32 rounded down with
//                      output.values: float32_lower
//   /input_index       uint8/16/32 (horizon, n0, n1, ...) flat index of u*(x,k) in the input grid,
//                      the narrowest type for the grid's inputs
//   /input_values      float64 (n_inputs, input_dims)      the input grid's points
//   /roles             uint8   (n0, n1, ...)  0 free, 1 fixed zero (avoid/unsafe), 2 fixed one (target)
// An unbounded specification's stationary policy (horizon 1) adds the attributes stationary = 1,
// iterations (interval iterations done) and converged, and /upper_values (n0, n1, ...), of the
// type of /values (float32 rounded up): the upper bound of the optimal value; /values[0]
// (= /values[1]) holds the certified lower bound. Continuous-system bounds (guarantee: system)
// add the attribute guarantee = "system" and /upper_values, of shape (horizon+1, n0, n1, ...) for
// a bounded horizon (stationary: (n0, n1, ...)): /values the lower, /upper_values the upper bounds.
// A refined synthesis (`refine`, docs/refinement.md) adds /refinement/{states, seconds, gap, at,
// lower, upper, served_round, stop}: its rounds; its grid is the served round's, /config the
// configuration as given.
// Every non-empty array is chunked with HDF5's Fletcher-32 checksum; the large ones are also
// shuffled and deflated. The file is built in memory,
// written to "<path>.tmp.<pid>", flushed and renamed, so a reader never sees half a file; a
// terminating signal during the write removes the temporary file, and every write first removes
// those of dead processes.
#include <string>

#include "amytiss/config.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/version.hpp"

namespace amytiss {

/// Writes atomically. Throws PolicyFileError on I/O failure, with the system's reason ("No space
/// left on device", "Permission denied", ...); then no temporary file is left and an older file
/// at `path` is intact.
/// Only a regular file is replaced: a symbolic link is followed (its target is replaced, the link
/// stays); a device, a FIFO or a socket at `path` (or as the link's target), or a link to a
/// missing file, is refused with PolicyFileError and left as it is.
void write_policy_file(const std::string& path, const Policy& policy, const Config& config);
/// The refusals of write_policy_file for what is at `path` now (a device, a FIFO, a socket, a
/// link to a missing file), as PolicyFileError: for a check before anything is computed.
void check_policy_file_path(const std::string& path);

struct LoadedPolicy {
  Policy policy;
  std::string config_yaml;
  std::string config_hash;
  unsigned engine_version = 0;  ///< kEngineVersion of the build that computed it
};

/// Reads a policy file and verifies its checksums (Fletcher-32 of each array, the content digest
/// of everything). Throws PolicyFileError when the file is missing, unreadable (with the system's
/// reason, e.g. "Permission denied"), truncated, corrupt (a checksum does not match), not an
/// amytiss policy or of another format version, with a message that says which.
LoadedPolicy read_policy_file(const std::string& path);
/// Reads and checks that the file was made from `config` (same config_hash) by this build's
/// engine version (kEngineVersion); throws PolicyFileError naming both otherwise. This decides
/// whether a stored policy may be reused.
LoadedPolicy read_policy_file_for(const std::string& path, const Config& config);

namespace detail {
/// write_policy_file with a chosen format name, format version and engine version and without the
/// value checks (values in [0, 1], input indices in range): only for tests of the reader's refusals.
void write_policy_file_as(const std::string& path, const Policy& policy, const Config& config,
                          const std::string& format, unsigned format_version,
                          unsigned engine_version = kEngineVersion);
}  // namespace detail

}  // namespace amytiss
