#pragma once
// Reading HDF5 files with checks: every failure throws PolicyFileError("<file>: <what is wrong>"),
// saying whether an item is missing, of the wrong type or shape, or unreadable ("truncated or
// corrupt: cannot read ...", which includes a Fletcher-32 checksum mismatch).
//
//   Hdf5Handle file = open_hdf5_for_reading(path, "policy file " + path);
//   Hdf5Reader reader(file.get(), "policy file " + path);
//   const std::string format = reader.string_attribute("format");
//   const auto values = reader.numeric_dataset<double>("/values", H5T_FLOAT, H5T_NATIVE_DOUBLE, shape);
#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

#include "io/hdf5_handle.hpp"

namespace amytiss::detail {

/// Opens `path` read-only. Refuses, naming `label`: a missing file, one that is not a regular
/// file, one the process may not read (with the system's reason, e.g. "Permission denied"), and one
/// HDF5 cannot open ("truncated or corrupt").
Hdf5Handle open_hdf5_for_reading(const std::string& path, const std::string& label);

class Hdf5Reader {
 public:
  /// `label` starts every message, e.g. "policy file out/p.h5".
  Hdf5Reader(hid_t file, std::string label) : file_(file), label_(std::move(label)) {}

  [[noreturn]] void fail(const std::string& message) const;
  [[noreturn]] void corrupt(const std::string& what) const;

  bool has_attribute(const std::string& name) const;
  /// Whether the file has a group or dataset at the absolute path `name` (its parent must exist).
  bool has_object(const std::string& name) const;
  std::string string_attribute(const std::string& name) const;
  std::uint64_t unsigned_attribute(const std::string& name) const;
  /// A scalar string dataset (variable or fixed length).
  std::string string_dataset(const std::string& name) const;

  /// A numeric dataset of element class `expected_class` and exactly the shape `expected`.
  template <typename T>
  std::vector<T> numeric_dataset(const std::string& name, H5T_class_t expected_class, hid_t memory_type,
                                 const std::vector<hsize_t>& expected) const {
    Hdf5Handle dataset = open_numeric(name, expected_class, expected);
    std::size_t elements = 1;
    for (hsize_t extent : expected) elements *= std::size_t(extent);
    std::vector<T> data(elements);
    read_numeric(dataset.get(), name, memory_type, data.data(), elements);
    return data;
  }
  /// The stored element type of a numeric dataset: its class, size in bytes and, for integers,
  /// whether it is signed.
  struct ElementType {
    H5T_class_t type_class;
    std::size_t bytes;
    bool is_signed;
  };
  ElementType element_type(const std::string& name) const;
  /// The extents of a dataset (empty for a scalar).
  std::vector<hsize_t> dataset_shape(const std::string& name) const;
  /// A numeric vector of any length.
  template <typename T>
  std::vector<T> vector_dataset(const std::string& name, H5T_class_t expected_class, hid_t memory_type) const {
    return numeric_dataset<T>(name, expected_class, memory_type, {vector_length(name)});
  }

 private:
  Hdf5Handle attribute(const std::string& name) const;
  Hdf5Handle open_dataset(const std::string& name) const;
  Hdf5Handle open_numeric(const std::string& name, H5T_class_t expected_class,
                          const std::vector<hsize_t>& expected) const;
  void read_numeric(hid_t dataset, const std::string& name, hid_t memory_type, void* data,
                    std::size_t elements) const;
  hsize_t vector_length(const std::string& name) const;
  std::vector<hsize_t> shape_of(hid_t dataset, const std::string& name) const;
  std::string read_string(hid_t stored_type, const std::string& what, hid_t object, bool is_attribute) const;

  hid_t file_;
  std::string label_;
};

}  // namespace amytiss::detail
