// Policy files: exact round trip and every refusal of the reader, each with its message.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/policy_file.hpp"
#include "io/hdf5_handle.hpp"

#include "policy_test_data.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;

constexpr unsigned kFormatVersion = 2;  // the version this build writes

using test_support::tiny_config;
using test_support::tiny_policy;
using test_support::refusal;

class PolicyFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = test_support::fresh_test_directory("amytiss_policy_file_test_");
  }
  void TearDown() override { fs::remove_all(directory_); }
  std::string path(const std::string& name) const { return (directory_ / name).string(); }

  fs::path directory_;
};


void expect_same_grid(const Grid& expected, const Grid& actual) {
  EXPECT_EQ(expected.lb(), actual.lb());
  EXPECT_EQ(expected.eta(), actual.eta());
  EXPECT_EQ(expected.counts(), actual.counts());
  EXPECT_EQ(expected.size(), actual.size());
}

void expect_same_policy(const Policy& expected, const Policy& actual) {
  expect_same_grid(expected.states, actual.states);
  expect_same_grid(expected.inputs, actual.inputs);
  EXPECT_EQ(expected.horizon, actual.horizon);
  EXPECT_EQ(expected.values, actual.values);  // bit-exact: float64 is stored as float64
  EXPECT_EQ(expected.input_index, actual.input_index);
  EXPECT_EQ(expected.roles, actual.roles);
  EXPECT_EQ(expected.computed_by, actual.computed_by);
  EXPECT_EQ(expected.config_hash, actual.config_hash);
  EXPECT_EQ(expected.run_id, actual.run_id);
}

TEST_F(PolicyFileTest, RoundTripGivesAnIdenticalPolicy) {
  const Config config = tiny_config();
  const Policy policy = tiny_policy(config);
  write_policy_file(path("p.h5"), policy, config);
  const LoadedPolicy loaded = read_policy_file(path("p.h5"));
  expect_same_policy(policy, loaded.policy);
  EXPECT_EQ(config_hash(config), loaded.config_hash);
  EXPECT_EQ(to_yaml(config), loaded.config_yaml);
  // No temporary file is left next to the result.
  EXPECT_EQ(1, std::distance(fs::directory_iterator(directory_), fs::directory_iterator()));
}

TEST_F(PolicyFileTest, RoundTripOfAnAutonomousSystem) {
  Config config = tiny_config();
  config.inputs.reset();
  config.dynamics = {"0.8*x0", "x1"};
  Policy policy = tiny_policy(config);
  std::fill(policy.input_index.begin(), policy.input_index.end(), 0u);
  write_policy_file(path("autonomous.h5"), policy, config);
  const LoadedPolicy loaded = read_policy_file(path("autonomous.h5"));
  EXPECT_EQ(0u, loaded.policy.inputs.dims());
  EXPECT_EQ(1u, loaded.policy.inputs.size());
  expect_same_policy(policy, loaded.policy);
}

// An unbounded specification's stationary policy: the flag, the iterations and the upper bound
// come back, the step is ignored by lookup, and a changed upper bound is refused by the digest.
TEST_F(PolicyFileTest, RoundTripOfAStationaryPolicy) {
  Config config = tiny_config();
  config.spec.unbounded = true;
  config.spec.horizon = 0;
  Policy policy = tiny_policy(config);
  policy.horizon = 1;
  policy.values.clear();
  policy.input_index.clear();
  Policy shape = tiny_policy(tiny_config());
  const std::size_t cells = policy.states.size();
  policy.values.assign(shape.values.begin(), shape.values.begin() + std::ptrdiff_t(cells));
  policy.values.insert(policy.values.end(), policy.values.begin(), policy.values.end());
  policy.input_index.assign(shape.input_index.begin(), shape.input_index.begin() + std::ptrdiff_t(cells));
  policy.stationary = true;
  policy.iterations = 321;
  for (std::size_t cell = 0; cell < cells; ++cell) policy.upper_values.push_back(std::min(1.0, policy.values[cell] + 1e-7));
  write_policy_file(path("stationary.h5"), policy, config);
  const LoadedPolicy loaded = read_policy_file_for(path("stationary.h5"), config);
  expect_same_policy(policy, loaded.policy);
  EXPECT_TRUE(loaded.policy.stationary);
  EXPECT_EQ(321u, loaded.policy.iterations);
  EXPECT_EQ(policy.upper_values, loaded.policy.upper_values);
  EXPECT_NEAR(loaded.policy.gap, 1e-7, 1e-12);
  const double state[] = {0.5, 1.0};
  double input[1], probability = -1;
  EXPECT_EQ(loaded.policy.lookup(state, 2, 7, input, &probability), LookupStatus::Ok);
  EXPECT_EQ(probability, loaded.policy.value(0, *loaded.policy.states.cell_of(state)));

  // A finite policy's file has no stationary attribute, and its reader stays non-stationary.
  write_policy_file(path("finite.h5"), tiny_policy(tiny_config()), tiny_config());
  EXPECT_FALSE(read_policy_file(path("finite.h5")).policy.stationary);

  Policy wrong = policy;
  wrong.upper_values.pop_back();
  EXPECT_NE(refusal([&] { write_policy_file(path("wrong.h5"), wrong, config); }).find("upper bounds"),
            std::string::npos);
}

TEST_F(PolicyFileTest, OverwritesAnExistingFile) {
  const Config config = tiny_config();
  Policy policy = tiny_policy(config);
  write_policy_file(path("p.h5"), policy, config);
  policy.values[0] = 0.25;
  write_policy_file(path("p.h5"), policy, config);
  EXPECT_EQ(0.25, read_policy_file(path("p.h5")).policy.values[0]);
}

TEST_F(PolicyFileTest, ReadForTheSameConfigurationAccepts) {
  const Config config = tiny_config();
  write_policy_file(path("p.h5"), tiny_policy(config), config);
  EXPECT_EQ(config_hash(config), read_policy_file_for(path("p.h5"), config).config_hash);
}

TEST_F(PolicyFileTest, RefusesAFileOfAnotherConfigurationNamingBothHashes) {
  const Config config = tiny_config();
  write_policy_file(path("p.h5"), tiny_policy(config), config);
  Config other = config;
  other.noise.covariance = {0.2, 0.1};
  ASSERT_NE(config_hash(config), config_hash(other));
  const std::string message = refusal([&] { read_policy_file_for(path("p.h5"), other); });
  EXPECT_NE(std::string::npos, message.find("another configuration")) << message;
  EXPECT_NE(std::string::npos, message.find(config_hash(config))) << message;
  EXPECT_NE(std::string::npos, message.find(config_hash(other))) << message;
}

TEST_F(PolicyFileTest, RefusesAMissingFile) {
  const std::string message = refusal([&] { read_policy_file(path("absent.h5")); });
  EXPECT_NE(std::string::npos, message.find("does not exist")) << message;
  EXPECT_NE(std::string::npos, message.find("absent.h5")) << message;
}

TEST_F(PolicyFileTest, RefusesATruncatedFile) {
  const Config config = tiny_config();
  write_policy_file(path("p.h5"), tiny_policy(config), config);
  fs::resize_file(path("p.h5"), fs::file_size(path("p.h5")) / 2);
  const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(std::string::npos, message.find("truncated or corrupt")) << message;
}

TEST_F(PolicyFileTest, RefusesCorruptBytes) {
  const Config config = tiny_config();
  write_policy_file(path("p.h5"), tiny_policy(config), config);
  {
    // Overwrite the superblock (signature and addresses) with garbage.
    std::fstream file(path("p.h5"), std::ios::in | std::ios::out | std::ios::binary);
    const std::string garbage(64, '\x5a');
    file.write(garbage.data(), std::streamsize(garbage.size()));
  }
  const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(std::string::npos, message.find("truncated or corrupt")) << message;
}

TEST_F(PolicyFileTest, RefusesAFileThatIsNotHdf5) {
  std::ofstream(path("text.h5")) << "name: not a policy\n";
  const std::string message = refusal([&] { read_policy_file(path("text.h5")); });
  EXPECT_NE(std::string::npos, message.find("truncated or corrupt")) << message;
}

TEST_F(PolicyFileTest, RefusesAnotherFormat) {
  const Config config = tiny_config();
  detail::write_policy_file_as(path("p.h5"), tiny_policy(config), config, "someone-else", 1);
  const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(std::string::npos, message.find("not an amytiss policy")) << message;
  EXPECT_NE(std::string::npos, message.find("someone-else")) << message;
}

TEST_F(PolicyFileTest, RefusesAnotherFormatVersion) {
  const Config config = tiny_config();
  detail::write_policy_file_as(path("p.h5"), tiny_policy(config), config, "amytiss-policy", 1);
  const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(std::string::npos, message.find("format_version 1 is not supported")) << message;
}

TEST_F(PolicyFileTest, RefusesValuesOutsideTheUnitIntervalOrNaN) {
  const Config config = tiny_config();
  for (double bad : {1.5, -0.25, std::numeric_limits<double>::quiet_NaN()}) {
    Policy policy = tiny_policy(config);
    policy.values[7] = bad;
    EXPECT_THROW(write_policy_file(path("p.h5"), policy, config), PolicyFileError);
    detail::write_policy_file_as(path("p.h5"), policy, config, "amytiss-policy", kFormatVersion);
    const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
    EXPECT_NE(std::string::npos, message.find("'/values' element 7")) << message;
    EXPECT_NE(std::string::npos, message.find("[0, 1]")) << message;
  }
}

TEST_F(PolicyFileTest, RefusesAnInputIndexOutOfRange) {
  const Config config = tiny_config();
  Policy policy = tiny_policy(config);
  policy.input_index[4] = 3;  // the input grid has 3 points
  EXPECT_THROW(write_policy_file(path("p.h5"), policy, config), PolicyFileError);
  detail::write_policy_file_as(path("p.h5"), policy, config, "amytiss-policy", kFormatVersion);
  const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(std::string::npos, message.find("'/input_index' element 4 is 3")) << message;
}

TEST_F(PolicyFileTest, RefusesArraysWhoseShapeDisagreesWithTheGrid) {
  const Config config = tiny_config();
  write_policy_file(path("p.h5"), tiny_policy(config), config);
  // Patch the dataspace of /values from (4, 5, 4) to (3, 5, 4): the file stays readable, the
  // shape no longer matches (horizon+1, n0, n1).
  std::string bytes;
  {
    std::ifstream file(path("p.h5"), std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
  }
  const std::string shape("\x04\0\0\0\0\0\0\0\x05\0\0\0\0\0\0\0\x04\0\0\0\0\0\0\0", 24);
  // The dataspace message stores the dimensions and the maximum dimensions (HDF5 may keep more
  // copies); patch every occurrence.
  std::size_t patched = 0;
  for (std::size_t at = bytes.find(shape); at != std::string::npos; at = bytes.find(shape, at + 1)) {
    bytes[at] = '\x03';
    ++patched;
  }
  ASSERT_GE(patched, 1u);
  std::ofstream(path("p.h5"), std::ios::binary | std::ios::trunc) << bytes;
  const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(std::string::npos, message.find("'/values' has shape (3, 5, 4), expected (4, 5, 4)"))
      << message;
}

TEST_F(PolicyFileTest, WriterRefusesArraysOfTheWrongSizeAndLeavesNoFile) {
  const Config config = tiny_config();
  Policy policy = tiny_policy(config);
  policy.values.pop_back();
  const std::string message = refusal([&] { write_policy_file(path("p.h5"), policy, config); });
  EXPECT_NE(std::string::npos, message.find("(horizon+1)*cells")) << message;
  EXPECT_TRUE(fs::is_empty(directory_));
}

TEST_F(PolicyFileTest, FailedWriteLeavesNoTemporaryFile) {
  const Config config = tiny_config();
  // The target is an existing directory: creating the temporary works, the rename cannot.
  fs::create_directories(path("occupied.h5/inside"));
  const std::string message =
      refusal([&] { write_policy_file(path("occupied.h5"), tiny_policy(config), config); });
  EXPECT_NE(std::string::npos, message.find("cannot write policy file")) << message;
  EXPECT_EQ(1, std::distance(fs::directory_iterator(directory_), fs::directory_iterator()));
}

TEST_F(PolicyFileTest, RefusesAPolicyOfAnotherConfigurationAtWriteTime) {
  const Config config = tiny_config();
  Policy policy = tiny_policy(config);
  policy.config_hash = "0123456789abcdef";
  const std::string message = refusal([&] { write_policy_file(path("p.h5"), policy, config); });
  EXPECT_NE(std::string::npos, message.find("0123456789abcdef")) << message;
  EXPECT_TRUE(fs::is_empty(directory_));
}

// ---------------------------------------------------------------- integrity (checksums)

std::string file_bytes(const std::string& file_path) {
  std::ifstream file(file_path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

// Where `pattern` first occurs in the file.
std::size_t offset_of(const std::string& file_path, const std::string& pattern) {
  const std::size_t at = file_bytes(file_path).find(pattern);
  EXPECT_NE(std::string::npos, at) << "pattern not found";
  return at == std::string::npos ? 0 : at;
}

// Where the first chunk of dataset `name` lies in the file: its offset and its stored (checksummed,
// possibly compressed) size in bytes.
std::pair<std::size_t, std::size_t> first_chunk(const std::string& file_path, const std::string& name) {
  detail::Hdf5Handle file(H5Fopen(file_path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  detail::Hdf5Handle dataset(H5Dopen2(file.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
  detail::Hdf5Handle space(H5Dget_space(dataset.get()), H5Sclose);
  haddr_t address = HADDR_UNDEF;
  hsize_t size = 0;
  unsigned filter_mask = 0;
  EXPECT_GE(H5Dget_chunk_info(dataset.get(), space.get(), 0, nullptr, &filter_mask, &address, &size), 0) << name;
  return {std::size_t(address), std::size_t(size)};
}

void overwrite(const std::string& file_path, std::size_t offset, const std::string& bytes) {
  std::fstream file(file_path, std::ios::in | std::ios::out | std::ios::binary);
  file.seekp(std::streamoff(offset));
  file.write(bytes.data(), std::streamsize(bytes.size()));
}

void flip_bit(const std::string& file_path, std::size_t offset) {
  std::string byte = file_bytes(file_path).substr(offset, 1);
  byte[0] = char(byte[0] ^ 0x10);
  overwrite(file_path, offset, byte);
}

TEST_F(PolicyFileTest, ZeroedValuesAreRefused) {
  const Config config = tiny_config();
  const Policy policy = tiny_policy(config);
  write_policy_file(path("p.h5"), policy, config);
  // Zeros are valid probabilities: only the checksum can tell.
  const auto [at, size] = first_chunk(path("p.h5"), "/values");
  overwrite(path("p.h5"), at, std::string(size / 2, '\0'));
  const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(std::string::npos, message.find("'/values' (its checksum does not match")) << message;
}

TEST_F(PolicyFileTest, ZeroedInputIndicesAreRefused) {
  const Config config = tiny_config();
  const Policy policy = tiny_policy(config);
  write_policy_file(path("p.h5"), policy, config);
  const auto [at, size] = first_chunk(path("p.h5"), "/input_index");
  overwrite(path("p.h5"), at, std::string(size, '\0'));
  const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(std::string::npos, message.find("'/input_index' (its checksum does not match")) << message;
}

TEST_F(PolicyFileTest, OneFlippedBitInAnyArrayIsRefused) {
  const Config config = tiny_config();
  const Policy policy = tiny_policy(config);
  // Compressed (/values, /input_index, /roles) or not (/states/lb).
  for (const std::string name : {"/values", "/input_index", "/roles", "/states/lb"}) {
    write_policy_file(path("p.h5"), policy, config);
    const auto [at, size] = first_chunk(path("p.h5"), name);
    flip_bit(path("p.h5"), at + size / 2);
    const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
    EXPECT_NE(std::string::npos, message.find("'" + name + "' (its checksum does not match")) << message;
  }
}

TEST_F(PolicyFileTest, AChangedConfigurationTextOrAttributeIsRefusedByTheDigest) {
  const Config config = tiny_config();
  const Policy policy = tiny_policy(config);
  for (const std::string& text : {std::string("name: \"policy_file_test\""), std::string("hand-made (test)"),
                                 std::string("0123456789abcdef")}) {
    write_policy_file(path("p.h5"), policy, config);
    flip_bit(path("p.h5"), offset_of(path("p.h5"), text) + text.size() - 2);
    const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
    EXPECT_NE(std::string::npos, message.find("corrupt: its contents give the digest")) << text << ": " << message;
  }
}

TEST_F(PolicyFileTest, TruncationAnywhereIsRefused) {
  const Config config = tiny_config();
  write_policy_file(path("p.h5"), tiny_policy(config), config);
  const std::uintmax_t size = fs::file_size(path("p.h5"));
  for (std::uintmax_t kept : {size / 10, size / 2, size * 9 / 10, size - 1}) {
    write_policy_file(path("p.h5"), tiny_policy(config), config);
    fs::resize_file(path("p.h5"), kept);
    const std::string message = refusal([&] { read_policy_file(path("p.h5")); });
    EXPECT_NE(std::string::npos, message.find("truncated or corrupt")) << kept << ": " << message;
  }
}

TEST_F(PolicyFileTest, ReuseNeedsThisEngineVersion) {
  const Config config = tiny_config();
  detail::write_policy_file_as(path("p.h5"), tiny_policy(config), config, "amytiss-policy", kFormatVersion,
                               kEngineVersion + 1);
  EXPECT_EQ(kEngineVersion + 1, read_policy_file(path("p.h5")).engine_version);
  const std::string message = refusal([&] { read_policy_file_for(path("p.h5"), config); });
  EXPECT_NE(std::string::npos, message.find("engine version " + std::to_string(kEngineVersion + 1))) << message;
  write_policy_file(path("p.h5"), tiny_policy(config), config);
  EXPECT_EQ(kEngineVersion, read_policy_file_for(path("p.h5"), config).engine_version);
}

}  // namespace
}  // namespace amytiss
