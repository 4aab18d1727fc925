#pragma once
// How a policy file stores its large arrays (docs/policy_file.md, "Storage"): input indices in
// the narrowest unsigned type that holds them, value arrays as float64 or as float32 rounded
// outward (`output.values: float32_lower`), all chunked and compressed.
#include <hdf5.h>

#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/policy.hpp"
#include "io/hdf5_writer.hpp"
#include "io/policy_digest.hpp"

namespace amytiss::detail {

/// HDF5's little-endian uint8 for up to 256 inputs, uint16 up to 65536, else uint32.
hid_t input_index_file_type(std::size_t input_count);

/// Each value replaced by the largest float32 <= it (a lower bound stays one).
std::vector<float> round_down_to_float(const std::vector<double>& values);
/// Each value replaced by the smallest float32 >= it (an upper bound stays one).
std::vector<float> round_up_to_float(const std::vector<double>& values);

/// The policy's value arrays as `storage` stores them: its own (exact) or their float32
/// roundings, /values down and /upper_values up.
class StoredValueArrays {
 public:
  StoredValueArrays(const Policy& policy, ValueStorage storage);
  StoredValues values() const;
  StoredValues upper_values() const;
  /// Writes `stored` (values() or upper_values()) as a compressed dataset of `shape`.
  void write(const Hdf5Writer& writer, const std::string& name, const std::vector<hsize_t>& shape,
             StoredValues stored) const;

 private:
  const Policy& policy_;
  bool float32_;
  std::vector<float> values32_, upper_values32_;
};

}  // namespace amytiss::detail
