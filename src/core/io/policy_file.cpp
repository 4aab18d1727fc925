// Policy files: the file handling. The file is built in memory (hdf5_writer.hpp), then written
// under a temporary name and renamed (temporary_file.hpp); the format is in policy_format.cpp.
#include "amytiss/policy_file.hpp"

#include "amytiss/errors.hpp"
#include "amytiss/version.hpp"
#include "io/policy_format.hpp"
#include "io/temporary_file.hpp"

namespace amytiss {

void write_policy_file(const std::string& path, const Policy& policy, const Config& config) {
  detail::check_policy_values(policy);
  detail::write_policy_file_as(path, policy, config, detail::kPolicyFormatName, detail::kPolicyFormatVersion);
}

void check_policy_file_path(const std::string& path) {
  try {
    detail::replaceable_path(path);
  } catch (const detail::FileWriteError& error) {
    throw PolicyFileError(error.what());
  }
}

namespace detail {
void write_policy_file_as(const std::string& path, const Policy& policy, const Config& config,
                          const std::string& format, unsigned format_version, unsigned engine_version) {
  check_policy_consistent(policy);
  const std::string hash = config_hash(config);
  if (!policy.config_hash.empty() && policy.config_hash != hash)
    throw PolicyFileError("cannot write " + path + ": the policy was computed from configuration " +
                          policy.config_hash + " but the configuration given has hash " + hash);
  const std::string failure = "cannot write policy file " + path + ": ";
  SilenceHdf5Errors silence;
  try {
    Hdf5MemoryFile memory_file;
    write_policy_contents(Hdf5Writer(memory_file.id()), policy, config, hash, format, format_version,
                          engine_version);
    const Hdf5Image image = memory_file.close_to_image();
    TemporaryFile file(path);
    file.stream().write(image.data(), std::streamsize(image.size()));
    file.commit();
  } catch (const PolicyFileError& error) {
    throw PolicyFileError(failure + error.what());
  } catch (const FileWriteError& error) {
    throw PolicyFileError(failure + error.what());
  }
}
}  // namespace detail

LoadedPolicy read_policy_file(const std::string& path) {
  const std::string label = "policy file " + path;
  detail::SilenceHdf5Errors silence;
  detail::Hdf5Handle file = detail::open_hdf5_for_reading(path, label);
  return detail::read_policy_contents(detail::Hdf5Reader(file.get(), label));
}

LoadedPolicy read_policy_file_for(const std::string& path, const Config& config) {
  LoadedPolicy loaded = read_policy_file(path);
  const std::string expected = config_hash(config);
  if (loaded.config_hash != expected)
    throw PolicyFileError("policy file " + path + " was made from another configuration (its " +
                          "config_hash is " + loaded.config_hash + ", this configuration's is " + expected + ")");
  if (loaded.engine_version != kEngineVersion)
    throw PolicyFileError("policy file " + path + " was computed by engine version " +
                          std::to_string(loaded.engine_version) + "; this build computes version " +
                          std::to_string(kEngineVersion) + ", whose results may differ");
  return loaded;
}

}  // namespace amytiss
