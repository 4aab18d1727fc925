#include "io/hdf5_reader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sstream>

#include "amytiss/errors.hpp"

namespace amytiss::detail {
namespace {

std::string shape_text(const std::vector<hsize_t>& shape) {
  std::ostringstream text;
  text << "(";
  for (std::size_t i = 0; i < shape.size(); ++i) text << (i ? ", " : "") << shape[i];
  if (shape.size() == 1) text << ",";
  text << ")";
  return text.str();
}

}  // namespace

Hdf5Handle open_hdf5_for_reading(const std::string& path, const std::string& label) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) {
    if (errno == ENOENT) throw PolicyFileError(label + " does not exist");
    throw PolicyFileError(label + " cannot be read: " + std::strerror(errno));
  }
  if (!S_ISREG(info.st_mode)) throw PolicyFileError(label + " is not a file");
  // HDF5 reports an unreadable file as an invalid one: ask the system first.
  const int descriptor = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (descriptor < 0) throw PolicyFileError(label + " cannot be read: " + std::strerror(errno));
  ::close(descriptor);
  if (H5Fis_hdf5(path.c_str()) <= 0)
    throw PolicyFileError(label + " is truncated or corrupt (not a readable HDF5 file)");
  Hdf5Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.valid()) throw PolicyFileError(label + " is truncated or corrupt (HDF5 cannot open it)");
  return file;
}

void Hdf5Reader::fail(const std::string& message) const { throw PolicyFileError(label_ + ": " + message); }

void Hdf5Reader::corrupt(const std::string& what) const { fail("truncated or corrupt: cannot read " + what); }

bool Hdf5Reader::has_attribute(const std::string& name) const { return H5Aexists(file_, name.c_str()) > 0; }

bool Hdf5Reader::has_object(const std::string& name) const {
  const htri_t exists = H5Lexists(file_, name.c_str(), H5P_DEFAULT);
  if (exists < 0) corrupt("link '" + name + "'");
  return exists > 0;
}

Hdf5Handle Hdf5Reader::attribute(const std::string& name) const {
  const htri_t exists = H5Aexists(file_, name.c_str());
  if (exists < 0) corrupt("attribute '" + name + "'");
  if (exists == 0) fail("missing attribute '" + name + "' on /");
  Hdf5Handle attribute(H5Aopen(file_, name.c_str(), H5P_DEFAULT), H5Aclose);
  if (!attribute.valid()) corrupt("attribute '" + name + "'");
  return attribute;
}

std::string Hdf5Reader::string_attribute(const std::string& name) const {
  Hdf5Handle attr = attribute(name);
  Hdf5Handle type(H5Aget_type(attr.get()), H5Tclose);
  if (!type.valid()) corrupt("attribute '" + name + "'");
  if (H5Tget_class(type.get()) != H5T_STRING) fail("attribute '" + name + "' is not a string");
  return read_string(type.get(), "attribute '" + name + "'", attr.get(), true);
}

std::uint64_t Hdf5Reader::unsigned_attribute(const std::string& name) const {
  Hdf5Handle attr = attribute(name);
  Hdf5Handle type(H5Aget_type(attr.get()), H5Tclose);
  if (!type.valid()) corrupt("attribute '" + name + "'");
  if (H5Tget_class(type.get()) != H5T_INTEGER) fail("attribute '" + name + "' is not an integer");
  std::uint64_t value = 0;
  if (H5Aread(attr.get(), H5T_NATIVE_UINT64, &value) < 0) corrupt("attribute '" + name + "'");
  return value;
}

Hdf5Handle Hdf5Reader::open_dataset(const std::string& name) const {
  // H5Lexists on a nested path needs every parent to exist, so walk the path.
  std::size_t start = 1;
  while (start <= name.size()) {
    const std::size_t slash = name.find('/', start);
    const htri_t exists = H5Lexists(file_, name.substr(0, slash).c_str(), H5P_DEFAULT);
    if (exists < 0) corrupt("'" + name + "'");
    if (exists == 0) fail("missing dataset '" + name + "'");
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  Hdf5Handle dataset(H5Dopen2(file_, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!dataset.valid()) corrupt("dataset '" + name + "'");
  return dataset;
}

std::string Hdf5Reader::string_dataset(const std::string& name) const {
  Hdf5Handle dataset = open_dataset(name);
  Hdf5Handle type(H5Dget_type(dataset.get()), H5Tclose);
  if (!type.valid()) corrupt("dataset '" + name + "'");
  if (H5Tget_class(type.get()) != H5T_STRING) fail("dataset '" + name + "' is not a string");
  Hdf5Handle space(H5Dget_space(dataset.get()), H5Sclose);
  if (!space.valid()) corrupt("dataset '" + name + "'");
  if (H5Sget_simple_extent_npoints(space.get()) != 1) fail("dataset '" + name + "' must hold one string");
  return read_string(type.get(), "dataset '" + name + "'", dataset.get(), false);
}

std::vector<hsize_t> Hdf5Reader::shape_of(hid_t dataset, const std::string& name) const {
  Hdf5Handle space(H5Dget_space(dataset), H5Sclose);
  if (!space.valid()) corrupt("dataset '" + name + "'");
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) corrupt("dataset '" + name + "'");
  std::vector<hsize_t> shape(static_cast<std::size_t>(rank));
  if (rank > 0 && H5Sget_simple_extent_dims(space.get(), shape.data(), nullptr) < 0)
    corrupt("dataset '" + name + "'");
  return shape;
}

Hdf5Handle Hdf5Reader::open_numeric(const std::string& name, H5T_class_t expected_class,
                                    const std::vector<hsize_t>& expected) const {
  Hdf5Handle dataset = open_dataset(name);
  Hdf5Handle type(H5Dget_type(dataset.get()), H5Tclose);
  if (!type.valid()) corrupt("dataset '" + name + "'");
  if (H5Tget_class(type.get()) != expected_class)
    fail("dataset '" + name + "' has the wrong element type (expected " +
         (expected_class == H5T_FLOAT ? "float64" : "unsigned integers") + ")");
  const std::vector<hsize_t> shape = shape_of(dataset.get(), name);
  if (shape != expected)
    fail("dataset '" + name + "' has shape " + shape_text(shape) + ", expected " + shape_text(expected) +
         " from the grids and the horizon");
  return dataset;
}

Hdf5Reader::ElementType Hdf5Reader::element_type(const std::string& name) const {
  Hdf5Handle dataset = open_dataset(name);
  Hdf5Handle type(H5Dget_type(dataset.get()), H5Tclose);
  if (!type.valid()) corrupt("dataset '" + name + "'");
  const H5T_class_t type_class = H5Tget_class(type.get());
  const bool is_signed = type_class == H5T_INTEGER && H5Tget_sign(type.get()) != H5T_SGN_NONE;
  return {type_class, H5Tget_size(type.get()), is_signed};
}

void Hdf5Reader::read_numeric(hid_t dataset, const std::string& name, hid_t memory_type, void* data,
                              std::size_t elements) const {
  // HDF5 verifies the Fletcher-32 checksum of each chunk here.
  if (elements > 0 && H5Dread(dataset, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    corrupt("dataset '" + name + "' (its checksum does not match or its data is missing)");
}

std::vector<hsize_t> Hdf5Reader::dataset_shape(const std::string& name) const {
  Hdf5Handle dataset = open_dataset(name);
  return shape_of(dataset.get(), name);
}

hsize_t Hdf5Reader::vector_length(const std::string& name) const {
  Hdf5Handle dataset = open_dataset(name);
  const std::vector<hsize_t> shape = shape_of(dataset.get(), name);
  if (shape.size() != 1) fail("dataset '" + name + "' must be a vector");
  return shape[0];
}

std::string Hdf5Reader::read_string(hid_t stored_type, const std::string& what, hid_t object,
                                    bool is_attribute) const {
  const auto read = [&](hid_t memory_type, void* buffer) {
    return is_attribute ? H5Aread(object, memory_type, buffer)
                        : H5Dread(object, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer);
  };
  const htri_t variable = H5Tis_variable_str(stored_type);
  if (variable < 0) corrupt(what);
  Hdf5Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!memory_type.valid()) corrupt(what);
  // HDF5 converts no strings between character sets, so read in the stored one.
  const H5T_cset_t character_set = H5Tget_cset(stored_type);
  if (character_set < 0 || H5Tset_cset(memory_type.get(), character_set) < 0) corrupt(what);
  if (variable > 0) {
    H5Tset_size(memory_type.get(), H5T_VARIABLE);
    char* text = nullptr;
    if (read(memory_type.get(), &text) < 0) corrupt(what);
    std::string value = text ? text : "";
    H5free_memory(text);
    return value;
  }
  // Fixed-length strings (as MATLAB or h5py may write them): read with room for a terminator.
  const std::size_t size = H5Tget_size(stored_type);
  H5Tset_size(memory_type.get(), size + 1);
  std::string buffer(size + 1, '\0');
  if (read(memory_type.get(), buffer.data()) < 0) corrupt(what);
  return std::string(buffer.c_str());
}

}  // namespace amytiss::detail
