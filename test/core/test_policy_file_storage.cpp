// Policy file storage: input indices in the narrowest unsigned type, value arrays as float64 or
// float32 rounded outward (output.values), compressed chunks, and files of the older layout
// (uint32 indices, float64 values, contiguous) still read.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/policy_file.hpp"
#include "io/hdf5_handle.hpp"

#include "policy_test_data.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;
using detail::Hdf5Handle;
using test_support::tiny_config;
using test_support::tiny_policy;
using test_support::refusal;

class PolicyFileStorageTest : public ::testing::Test {
 protected:
  void SetUp() override { directory_ = test_support::fresh_test_directory("amytiss_policy_storage_test_"); }
  void TearDown() override { fs::remove_all(directory_); }
  std::string path(const std::string& name) const { return (directory_ / name).string(); }

  fs::path directory_;
};


Hdf5Handle open_file(const std::string& file, unsigned flags) {
  Hdf5Handle handle(H5Fopen(file.c_str(), flags, H5P_DEFAULT), H5Fclose);
  EXPECT_TRUE(handle.valid()) << file;
  return handle;
}

// The stored element type of a dataset: (class, bytes, signed).
struct StoredType {
  H5T_class_t type_class;
  std::size_t bytes;
  bool is_signed;
};
StoredType stored_type(const std::string& file, const std::string& name) {
  Hdf5Handle handle = open_file(file, H5F_ACC_RDONLY);
  Hdf5Handle dataset(H5Dopen2(handle.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
  Hdf5Handle type(H5Dget_type(dataset.get()), H5Tclose);
  return {H5Tget_class(type.get()), H5Tget_size(type.get()), H5Tget_sign(type.get()) == H5T_SGN_2};
}

// Replaces dataset `name` by a contiguous one (no filters) of `file_type` holding `data`.
template <typename T>
void replace_dataset(const std::string& file, const std::string& name, hid_t file_type, hid_t memory_type,
                     const std::vector<T>& data) {
  Hdf5Handle handle = open_file(file, H5F_ACC_RDWR);
  std::vector<hsize_t> shape;
  {
    Hdf5Handle dataset(H5Dopen2(handle.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
    Hdf5Handle space(H5Dget_space(dataset.get()), H5Sclose);
    shape.resize(std::size_t(H5Sget_simple_extent_ndims(space.get())));
    H5Sget_simple_extent_dims(space.get(), shape.data(), nullptr);
  }
  ASSERT_GE(H5Ldelete(handle.get(), name.c_str(), H5P_DEFAULT), 0);
  Hdf5Handle space(H5Screate_simple(int(shape.size()), shape.data(), nullptr), H5Sclose);
  Hdf5Handle dataset(
      H5Dcreate2(handle.get(), name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  ASSERT_TRUE(dataset.valid());
  ASSERT_GE(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), 0);
}

// Rewrites element `index` of dataset `name` through HDF5, so its checksum and compression stay
// valid and only the content digest can tell.
template <typename T>
void rewrite_element(const std::string& file, const std::string& name, hid_t memory_type, std::size_t index,
                     T value) {
  Hdf5Handle handle = open_file(file, H5F_ACC_RDWR);
  Hdf5Handle dataset(H5Dopen2(handle.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
  Hdf5Handle space(H5Dget_space(dataset.get()), H5Sclose);
  std::vector<T> data(std::size_t(H5Sget_simple_extent_npoints(space.get())));
  ASSERT_GE(H5Dread(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), 0);
  data.at(index) = value;
  ASSERT_GE(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), 0);
}

// A policy over `inputs` inputs (a 1-D input grid) whose indices reach the last input.
std::pair<Config, Policy> policy_with_inputs(std::size_t inputs) {
  Config config = tiny_config();
  config.inputs = GridSpec{{0.0}, {double(inputs - 1)}, {1.0}};
  Policy policy = tiny_policy(config);
  for (std::size_t i = 0; i < policy.input_index.size(); ++i)
    policy.input_index[i] = std::uint32_t((i * 7919 + inputs - 1) % inputs);
  policy.input_index.back() = std::uint32_t(inputs - 1);
  return {config, policy};
}

TEST_F(PolicyFileStorageTest, InputIndicesAreStoredInTheNarrowestUnsignedType) {
  const std::vector<std::pair<std::size_t, std::size_t>> inputs_and_bytes = {
      {3, 1}, {256, 1}, {257, 2}, {65536, 2}, {65537, 4}};
  for (const auto& [inputs, bytes] : inputs_and_bytes) {
    const auto [config, policy] = policy_with_inputs(inputs);
    write_policy_file(path("p.h5"), policy, config);
    const StoredType type = stored_type(path("p.h5"), "/input_index");
    EXPECT_EQ(type.type_class, H5T_INTEGER) << inputs;
    EXPECT_EQ(type.bytes, bytes) << inputs;
    EXPECT_FALSE(type.is_signed) << inputs;
    const LoadedPolicy loaded = read_policy_file(path("p.h5"));
    EXPECT_EQ(loaded.policy.input_index, policy.input_index) << inputs;
    EXPECT_EQ(loaded.policy.values, policy.values) << inputs;  // exact by default
  }
}

// float32_lower: /values rounded down, /upper_values up, each by less than one float32 step;
// the hash is the exact configuration's, so the file is reused for it.
TEST_F(PolicyFileStorageTest, Float32LowerKeepsEveryBoundOnItsSide) {
  Config config = tiny_config();
  config.guarantee = Guarantee::System;
  Policy policy = tiny_policy(config);
  policy.guarantee = Guarantee::System;
  for (double value : policy.values) policy.upper_values.push_back(std::min(1.0, value + 1e-7));
  policy.values[3] = 1.0;  // representable values stay
  policy.values[4] = 0.0;
  Config float32 = config;
  float32.output.values = ValueStorage::Float32Lower;
  write_policy_file(path("p.h5"), policy, float32);
  EXPECT_EQ(stored_type(path("p.h5"), "/values").bytes, 4u);
  EXPECT_EQ(stored_type(path("p.h5"), "/upper_values").bytes, 4u);
  const LoadedPolicy loaded = read_policy_file_for(path("p.h5"), config);
  EXPECT_EQ(read_stored_config(loaded.config_yaml).output.values, ValueStorage::Float32Lower);
  ASSERT_EQ(loaded.policy.values.size(), policy.values.size());
  ASSERT_EQ(loaded.policy.upper_values.size(), policy.upper_values.size());
  std::size_t rounded = 0;
  for (std::size_t i = 0; i < policy.values.size(); ++i) {
    const double lower = loaded.policy.values[i], upper = loaded.policy.upper_values[i];
    const double step = double(std::numeric_limits<float>::epsilon());  // one float32 step at 1
    EXPECT_LE(lower, policy.values[i]) << i;
    EXPECT_LE(policy.values[i] - lower, step) << i;
    EXPECT_EQ(double(float(lower)), lower) << i;
    EXPECT_GE(upper, policy.upper_values[i]) << i;
    EXPECT_LE(upper - policy.upper_values[i], step) << i;
    rounded += lower != policy.values[i] ? 1 : 0;
  }
  EXPECT_GT(rounded, policy.values.size() / 2);  // the hand-made values are not round in binary
  EXPECT_EQ(loaded.policy.values[3], 1.0);
  EXPECT_EQ(loaded.policy.values[4], 0.0);
  EXPECT_EQ(loaded.policy.input_index, policy.input_index);
}

// A file of the older layout: uint32 indices, float64 values, contiguous without filters.
TEST_F(PolicyFileStorageTest, ReadsTheOlderUncompressedLayout) {
  const Config config = tiny_config();
  const Policy policy = tiny_policy(config);
  write_policy_file(path("p.h5"), policy, config);
  replace_dataset(path("p.h5"), "/values", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, policy.values);
  replace_dataset(path("p.h5"), "/input_index", H5T_STD_U32LE, H5T_NATIVE_UINT32, policy.input_index);
  EXPECT_EQ(stored_type(path("p.h5"), "/input_index").bytes, 4u);
  const LoadedPolicy loaded = read_policy_file_for(path("p.h5"), config);
  EXPECT_EQ(loaded.policy.values, policy.values);
  EXPECT_EQ(loaded.policy.input_index, policy.input_index);
}

TEST_F(PolicyFileStorageTest, RefusesSignedIndicesAndIntegerValues) {
  const Config config = tiny_config();
  const Policy policy = tiny_policy(config);
  write_policy_file(path("p.h5"), policy, config);
  replace_dataset(path("p.h5"), "/input_index", H5T_STD_I32LE, H5T_NATIVE_UINT32, policy.input_index);
  std::string message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(message.find("'/input_index' has the wrong element type (expected uint8, uint16 or uint32)"),
            std::string::npos)
      << message;
  write_policy_file(path("p.h5"), policy, config);
  const std::vector<std::uint8_t> bytes(policy.values.size());
  replace_dataset(path("p.h5"), "/values", H5T_STD_U8LE, H5T_NATIVE_UINT8, bytes);
  message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(message.find("'/values' has the wrong element type (expected float64 or float32)"), std::string::npos)
      << message;
}

// A compressed dataset changed through HDF5 keeps valid checksums: the digest refuses it.
TEST_F(PolicyFileStorageTest, DigestRefusesAChangedCompressedDataset) {
  Config config = tiny_config();
  config.output.values = ValueStorage::Float32Lower;
  const Policy policy = tiny_policy(config);
  write_policy_file(path("p.h5"), policy, config);
  ASSERT_NO_THROW(read_policy_file(path("p.h5")));
  const float stored = float(read_policy_file(path("p.h5")).policy.values[5]);
  rewrite_element(path("p.h5"), "/values", H5T_NATIVE_FLOAT, 5,
                  std::nextafter(stored, -std::numeric_limits<float>::infinity()));
  std::string message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(message.find("corrupt: its contents give the digest"), std::string::npos) << message;

  write_policy_file(path("p.h5"), policy, config);
  rewrite_element(path("p.h5"), "/input_index", H5T_NATIVE_UINT8, 2, std::uint8_t((policy.input_index[2] + 1) % 3));
  message = refusal([&] { read_policy_file(path("p.h5")); });
  EXPECT_NE(message.find("corrupt: its contents give the digest"), std::string::npos) << message;
}

}  // namespace
}  // namespace amytiss
