#include "io/policy_storage.hpp"

#include <cmath>
#include <limits>

namespace amytiss::detail {

hid_t input_index_file_type(std::size_t input_count) {
  if (input_count <= std::size_t(std::numeric_limits<std::uint8_t>::max()) + 1) return H5T_STD_U8LE;
  if (input_count <= std::size_t(std::numeric_limits<std::uint16_t>::max()) + 1) return H5T_STD_U16LE;
  return H5T_STD_U32LE;
}

std::vector<float> round_down_to_float(const std::vector<double>& values) {
  std::vector<float> rounded(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    float nearest = float(values[i]);
    if (double(nearest) > values[i]) nearest = std::nextafter(nearest, -std::numeric_limits<float>::infinity());
    rounded[i] = nearest;
  }
  return rounded;
}

std::vector<float> round_up_to_float(const std::vector<double>& values) {
  std::vector<float> rounded(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    float nearest = float(values[i]);
    if (double(nearest) < values[i]) nearest = std::nextafter(nearest, std::numeric_limits<float>::infinity());
    rounded[i] = nearest;
  }
  return rounded;
}

StoredValueArrays::StoredValueArrays(const Policy& policy, ValueStorage storage)
    : policy_(policy), float32_(storage == ValueStorage::Float32Lower) {
  if (!float32_) return;
  values32_ = round_down_to_float(policy.values);
  upper_values32_ = round_up_to_float(policy.upper_values);
}

StoredValues StoredValueArrays::values() const {
  return float32_ ? StoredValues(values32_) : StoredValues(policy_.values);
}

StoredValues StoredValueArrays::upper_values() const {
  return float32_ ? StoredValues(upper_values32_) : StoredValues(policy_.upper_values);
}

void StoredValueArrays::write(const Hdf5Writer& writer, const std::string& name, const std::vector<hsize_t>& shape,
                              StoredValues stored) const {
  if (stored.is_float32())
    writer.dataset(name, shape, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, stored.data(), Hdf5Writer::Filters::Compressed);
  else
    writer.dataset(name, shape, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, stored.data(), Hdf5Writer::Filters::Compressed);
}

}  // namespace amytiss::detail
