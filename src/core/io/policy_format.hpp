#pragma once
// The policy file format (docs/policy_file.md): which attributes and datasets a file holds, the
// checks of a policy before it is written, and the checks of everything read back. The HDF5
// mechanics are in hdf5_writer.hpp and hdf5_reader.hpp, the file handling in policy_file.cpp.
#include <string>

#include "amytiss/config.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/policy_file.hpp"
#include "io/hdf5_reader.hpp"
#include "io/hdf5_writer.hpp"

namespace amytiss::detail {

constexpr const char* kPolicyFormatName = "amytiss-policy";
constexpr unsigned kPolicyFormatVersion = 2;

/// Throws PolicyFileError when the array sizes disagree with the grids and the horizon.
void check_policy_consistent(const Policy& policy);
/// Throws PolicyFileError for values outside [0, 1] or NaN and input indices out of range: the
/// reader refuses such files, so the writer refuses to produce them.
void check_policy_values(const Policy& policy);

/// The attributes, the configuration text and every array, with the content digest.
/// `config_hash` is config_hash(config).
void write_policy_contents(const Hdf5Writer& writer, const Policy& policy, const Config& config,
                           const std::string& config_hash, const std::string& format, unsigned format_version,
                           unsigned engine_version);

/// Reads and checks everything write_policy_contents writes; throws PolicyFileError naming what
/// is missing, inconsistent or corrupt.
LoadedPolicy read_policy_contents(const Hdf5Reader& reader);

}  // namespace amytiss::detail
