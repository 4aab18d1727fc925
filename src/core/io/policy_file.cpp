#include "amytiss/policy_file.hpp"

#include <hdf5.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <sstream>

#include "amytiss/errors.hpp"
#include "amytiss/version.hpp"

namespace amytiss {
namespace {

constexpr const char* kFormatName = "amytiss-policy";
constexpr unsigned kFormatVersion = 2;
// Chunks of the checksummed arrays hold at most this many bytes (HDF5's limit is 4 GiB).
constexpr std::uint64_t kChunkBytes = 16u << 20;

// A 64-bit digest of everything the file says (attributes, the configuration text and every
// array), stored as the attribute content_digest and recomputed by the reader. Fed with 64-bit
// words, so it does not depend on the machine's byte order.
class ContentDigest {
 public:
  void add(std::uint64_t word) {
    state_ = (state_ ^ word) * 0x9e3779b97f4a7c15ull;
    state_ ^= state_ >> 29;
  }
  void add(const std::string& text) {
    add(std::uint64_t(text.size()));
    for (std::size_t at = 0; at < text.size(); at += 8) {
      std::uint64_t word = 0;
      for (std::size_t i = at; i < std::min(text.size(), at + 8); ++i)
        word |= std::uint64_t(static_cast<unsigned char>(text[i])) << (8 * (i - at));
      add(word);
    }
  }
  void add(const std::vector<double>& values) {
    add(std::uint64_t(values.size()));
    for (double value : values) {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &value, sizeof bits);
      add(bits);
    }
  }
  template <typename Unsigned>
  void add(const std::vector<Unsigned>& values) {
    add(std::uint64_t(values.size()));
    for (Unsigned value : values) add(std::uint64_t(value));
  }
  std::string hex() const {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(state_));
    return text;
  }

 private:
  std::uint64_t state_ = 0xcbf29ce484222325ull;
};

// The attributes in the order the digest takes them.
struct FileAttributes {
  std::string format;
  std::uint64_t format_version = 0;
  std::string config_hash, computed_by, run_id;
  std::uint64_t engine_version = 0, horizon = 0;
  std::string spec;
  std::uint64_t stationary = 0, iterations = 0, converged = 0;  // unbounded specifications only
};

void add_attributes(ContentDigest& digest, const FileAttributes& attributes) {
  digest.add(attributes.format);
  digest.add(attributes.format_version);
  digest.add(attributes.config_hash);
  digest.add(attributes.computed_by);
  digest.add(attributes.run_id);
  digest.add(attributes.engine_version);
  digest.add(attributes.horizon);
  digest.add(attributes.spec);
  // Present only in files of unbounded specifications: other files keep their digest.
  if (attributes.stationary) {
    digest.add(attributes.stationary);
    digest.add(attributes.iterations);
    digest.add(attributes.converged);
  }
}

void add_grid(ContentDigest& digest, const Grid& grid) {
  digest.add(grid.lb());
  digest.add(grid.eta());
  digest.add(std::vector<std::uint64_t>(grid.counts().begin(), grid.counts().end()));
}

std::vector<double> input_points(const Grid& inputs) {
  std::vector<double> points(inputs.size() * inputs.dims());
  for (std::size_t flat = 0; flat < inputs.size(); ++flat) inputs.point(flat, points.data() + flat * inputs.dims());
  return points;
}

std::string digest_of(const FileAttributes& attributes, const std::string& config_yaml, const Policy& policy) {
  ContentDigest digest;
  add_attributes(digest, attributes);
  digest.add(config_yaml);
  add_grid(digest, policy.states);
  add_grid(digest, policy.inputs);
  digest.add(policy.values);
  digest.add(policy.input_index);
  digest.add(input_points(policy.inputs));
  std::vector<std::uint8_t> roles(policy.roles.size());
  for (std::size_t i = 0; i < roles.size(); ++i) roles[i] = std::uint8_t(policy.roles[i]);
  digest.add(roles);
  if (policy.stationary) digest.add(policy.upper_values);
  return digest.hex();
}

// Chunk extents for an array of `shape`: whole trailing dimensions while they fit kChunkBytes.
std::vector<hsize_t> chunk_shape(const std::vector<hsize_t>& shape, std::size_t element_bytes) {
  std::vector<hsize_t> chunk(shape.size(), 1);
  std::uint64_t bytes = element_bytes;
  for (std::size_t dim = shape.size(); dim-- > 0;) {
    const std::uint64_t fit = std::max<std::uint64_t>(1, kChunkBytes / bytes);
    chunk[dim] = hsize_t(std::min<std::uint64_t>(shape[dim], fit));
    bytes *= chunk[dim];
    if (chunk[dim] < shape[dim]) break;
  }
  return chunk;
}

// HDF5 prints its own error stack to stderr by default; we report through PolicyFileError only.
// H5Eset_auto is per thread in thread-safe builds, so it is silenced around every operation.
class SilenceHdf5Errors {
 public:
  SilenceHdf5Errors() {
    H5Eget_auto2(H5E_DEFAULT, &previous_function_, &previous_data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~SilenceHdf5Errors() { H5Eset_auto2(H5E_DEFAULT, previous_function_, previous_data_); }
  SilenceHdf5Errors(const SilenceHdf5Errors&) = delete;
  SilenceHdf5Errors& operator=(const SilenceHdf5Errors&) = delete;

 private:
  H5E_auto2_t previous_function_ = nullptr;
  void* previous_data_ = nullptr;
};

// Owns one HDF5 identifier and closes it with the matching close function.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Handle() {
    if (id_ >= 0) closer_(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept : id_(other.id_), closer_(other.closer_) { other.id_ = -1; }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_;
  Closer closer_;
};

// ---------------------------------------------------------------- writing

class Writer {
 public:
  explicit Writer(hid_t file) : file_(file) {}

  void check(herr_t status, const std::string& what) const {
    if (status < 0) throw PolicyFileError("cannot write " + what);
  }
  Handle checked(hid_t id, Handle::Closer closer, const std::string& what) const {
    if (id < 0) throw PolicyFileError("cannot write " + what);
    return Handle(id, closer);
  }

  Handle string_type(const std::string& what) const {
    Handle type = checked(H5Tcopy(H5T_C_S1), H5Tclose, what);
    check(H5Tset_size(type.get(), H5T_VARIABLE), what);
    check(H5Tset_cset(type.get(), H5T_CSET_UTF8), what);
    return type;
  }

  void string_attribute(const std::string& name, const std::string& value) const {
    Handle type = string_type("attribute " + name);
    Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, "attribute " + name);
    Handle attribute = checked(
        H5Acreate2(file_, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
        H5Aclose, "attribute " + name);
    const char* text = value.c_str();
    check(H5Awrite(attribute.get(), type.get(), &text), "attribute " + name);
  }

  void unsigned_attribute(const std::string& name, std::uint64_t value) const {
    Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, "attribute " + name);
    Handle attribute =
        checked(H5Acreate2(file_, name.c_str(), H5T_STD_U32LE, space.get(), H5P_DEFAULT,
                           H5P_DEFAULT),
                H5Aclose, "attribute " + name);
    check(H5Awrite(attribute.get(), H5T_NATIVE_UINT64, &value), "attribute " + name);
  }

  void string_dataset(const std::string& name, const std::string& value) const {
    Handle type = string_type(name);
    Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, name);
    Handle dataset = checked(H5Dcreate2(file_, name.c_str(), type.get(), space.get(),
                                        H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                             H5Dclose, name);
    const char* text = value.c_str();
    check(H5Dwrite(dataset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &text), name);
  }

  void group(const std::string& name) const {
    checked(H5Gcreate2(file_, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
            name);
  }

  // file_type: the stored type (little-endian, fixed); memory_type: the native type of `data`.
  void dataset(const std::string& name, const std::vector<hsize_t>& shape, hid_t file_type,
               hid_t memory_type, const void* data) const {
    Handle space = checked(
        H5Screate_simple(int(shape.size()), shape.empty() ? nullptr : shape.data(), nullptr),
        H5Sclose, name);
    hsize_t elements = 1;
    for (hsize_t extent : shape) elements *= extent;
    // Every non-empty array is chunked with HDF5's Fletcher-32 checksum, which any HDF5 reader
    // (h5py included) verifies on every read.
    Handle properties = checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, name);
    if (elements > 0) {
      const std::vector<hsize_t> chunk = chunk_shape(shape, H5Tget_size(file_type));
      check(H5Pset_chunk(properties.get(), int(chunk.size()), chunk.data()), name);
      check(H5Pset_fletcher32(properties.get()), name);
    }
    Handle dataset = checked(H5Dcreate2(file_, name.c_str(), file_type, space.get(), H5P_DEFAULT,
                                        properties.get(), H5P_DEFAULT),
                             H5Dclose, name);
    // A zero-sized dataset (the input grid of an autonomous system) has nothing to write, and
    // H5Dwrite refuses a null buffer.
    if (elements > 0)
      check(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), name);
  }

  void grid(const std::string& group_name, const Grid& grid) const {
    group(group_name);
    const std::vector<hsize_t> shape{hsize_t(grid.dims())};
    std::vector<std::uint64_t> counts(grid.counts().begin(), grid.counts().end());
    dataset(group_name + "/lb", shape, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, grid.lb().data());
    dataset(group_name + "/eta", shape, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, grid.eta().data());
    dataset(group_name + "/counts", shape, H5T_STD_U64LE, H5T_NATIVE_UINT64, counts.data());
  }

 private:
  hid_t file_;
};

std::vector<hsize_t> cell_shape(const Grid& states, std::size_t leading) {
  std::vector<hsize_t> shape{hsize_t(leading)};
  for (std::size_t count : states.counts()) shape.push_back(hsize_t(count));
  return shape;
}

void write_contents(hid_t file, const Policy& policy, const Config& config, const std::string& hash,
                    const std::string& format, unsigned format_version, unsigned engine_version) {
  FileAttributes attributes;
  attributes.format = format;
  attributes.format_version = format_version;
  attributes.config_hash = hash;
  attributes.computed_by = policy.computed_by;
  attributes.run_id = policy.run_id;
  attributes.engine_version = engine_version;
  attributes.horizon = policy.horizon;
  attributes.spec = to_string(config.spec.type);
  attributes.stationary = policy.stationary ? 1 : 0;
  attributes.iterations = policy.stationary ? policy.iterations : 0;
  attributes.converged = policy.stationary && policy.converged ? 1 : 0;
  const std::string config_yaml = to_yaml(config);

  Writer writer(file);
  writer.string_attribute("format", attributes.format);
  writer.unsigned_attribute("format_version", attributes.format_version);
  writer.string_attribute("config_hash", attributes.config_hash);
  writer.string_attribute("computed_by", attributes.computed_by);
  writer.string_attribute("run_id", attributes.run_id);
  writer.unsigned_attribute("engine_version", attributes.engine_version);
  writer.unsigned_attribute("horizon", attributes.horizon);
  writer.string_attribute("spec", attributes.spec);
  if (attributes.stationary) {
    writer.unsigned_attribute("stationary", attributes.stationary);
    writer.unsigned_attribute("iterations", attributes.iterations);
    writer.unsigned_attribute("converged", attributes.converged);
  }
  writer.string_attribute("content_digest", digest_of(attributes, config_yaml, policy));
  writer.string_dataset("/config", config_yaml);
  writer.grid("/states", policy.states);
  writer.grid("/inputs", policy.inputs);

  writer.dataset("/values", cell_shape(policy.states, policy.horizon + 1), H5T_IEEE_F64LE,
                 H5T_NATIVE_DOUBLE, policy.values.data());
  writer.dataset("/input_index", cell_shape(policy.states, policy.horizon), H5T_STD_U32LE,
                 H5T_NATIVE_UINT32, policy.input_index.data());

  const std::vector<double> input_values = input_points(policy.inputs);
  writer.dataset("/input_values", {hsize_t(policy.inputs.size()), hsize_t(policy.inputs.dims())},
                 H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, input_values.data());

  std::vector<hsize_t> role_shape = cell_shape(policy.states, 1);
  role_shape.erase(role_shape.begin());
  static_assert(sizeof(CellRole) == sizeof(std::uint8_t), "roles are stored as uint8");
  writer.dataset("/roles", role_shape, H5T_STD_U8LE, H5T_NATIVE_UINT8, policy.roles.data());
  if (policy.stationary)
    writer.dataset("/upper_values", role_shape, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, policy.upper_values.data());
}

void check_policy_consistent(const Policy& policy) {
  const std::size_t cells = policy.states.size();
  if (policy.values.size() != (std::size_t(policy.horizon) + 1) * cells)
    throw PolicyFileError("cannot write a policy with " + std::to_string(policy.values.size()) +
                          " values: expected (horizon+1)*cells = " +
                          std::to_string((std::size_t(policy.horizon) + 1) * cells));
  if (policy.input_index.size() != std::size_t(policy.horizon) * cells)
    throw PolicyFileError("cannot write a policy with " +
                          std::to_string(policy.input_index.size()) +
                          " input indices: expected horizon*cells = " +
                          std::to_string(std::size_t(policy.horizon) * cells));
  if (policy.roles.size() != cells)
    throw PolicyFileError("cannot write a policy with " + std::to_string(policy.roles.size()) +
                          " cell roles: expected " + std::to_string(cells));
  if (policy.stationary && (policy.horizon != 1 || policy.upper_values.size() != cells))
    throw PolicyFileError("cannot write a stationary policy with horizon " + std::to_string(policy.horizon) + " and " +
                          std::to_string(policy.upper_values.size()) + " upper bounds: expected horizon 1 and " +
                          std::to_string(cells));
}

// The reader refuses such files, so the writer refuses to produce them.
void check_policy_values(const Policy& policy) {
  for (std::size_t i = 0; i < policy.values.size(); ++i)
    if (!(policy.values[i] >= 0.0 && policy.values[i] <= 1.0))
      throw PolicyFileError("cannot write a policy whose value " + std::to_string(i) + " is " +
                            std::to_string(policy.values[i]) + " (expected a probability)");
  for (std::size_t i = 0; i < policy.upper_values.size(); ++i)
    if (!(policy.upper_values[i] >= 0.0 && policy.upper_values[i] <= 1.0))
      throw PolicyFileError("cannot write a policy whose upper bound " + std::to_string(i) + " is " +
                            std::to_string(policy.upper_values[i]) + " (expected a probability)");
  for (std::size_t i = 0; i < policy.input_index.size(); ++i)
    if (policy.input_index[i] >= policy.inputs.size())
      throw PolicyFileError("cannot write a policy whose input index " + std::to_string(i) +
                            " is " + std::to_string(policy.input_index[i]) + " (the grid has " +
                            std::to_string(policy.inputs.size()) + " inputs)");
}

// ---------------------------------------------------------------- reading

class Reader {
 public:
  Reader(hid_t file, std::string path) : file_(file), path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& message) const {
    throw PolicyFileError("policy file " + path_ + ": " + message);
  }
  [[noreturn]] void corrupt(const std::string& what) const {
    fail("truncated or corrupt: cannot read " + what);
  }

  bool has_attribute(const std::string& name) const {
    return H5Aexists(file_, name.c_str()) > 0;
  }
  Handle attribute(const std::string& name) const {
    const htri_t exists = H5Aexists(file_, name.c_str());
    if (exists < 0) corrupt("attribute '" + name + "'");
    if (exists == 0) fail("missing attribute '" + name + "' on /");
    Handle attribute(H5Aopen(file_, name.c_str(), H5P_DEFAULT), H5Aclose);
    if (!attribute.valid()) corrupt("attribute '" + name + "'");
    return attribute;
  }

  std::string string_attribute(const std::string& name) const {
    Handle attr = attribute(name);
    Handle type(H5Aget_type(attr.get()), H5Tclose);
    if (!type.valid()) corrupt("attribute '" + name + "'");
    if (H5Tget_class(type.get()) != H5T_STRING) fail("attribute '" + name + "' is not a string");
    return read_string(type.get(), "attribute '" + name + "'",
                       [&](hid_t memory_type, void* buffer) {
                         return H5Aread(attr.get(), memory_type, buffer);
                       });
  }

  std::uint64_t unsigned_attribute(const std::string& name) const {
    Handle attr = attribute(name);
    Handle type(H5Aget_type(attr.get()), H5Tclose);
    if (!type.valid()) corrupt("attribute '" + name + "'");
    if (H5Tget_class(type.get()) != H5T_INTEGER) fail("attribute '" + name + "' is not an integer");
    std::uint64_t value = 0;
    if (H5Aread(attr.get(), H5T_NATIVE_UINT64, &value) < 0) corrupt("attribute '" + name + "'");
    return value;
  }

  Handle open_dataset(const std::string& name) const {
    // H5Lexists on a nested path needs every parent to exist, so walk the path.
    std::string prefix;
    std::size_t start = 1;
    while (start <= name.size()) {
      const std::size_t slash = name.find('/', start);
      prefix = name.substr(0, slash);
      const htri_t exists = H5Lexists(file_, prefix.c_str(), H5P_DEFAULT);
      if (exists < 0) corrupt("'" + name + "'");
      if (exists == 0) fail("missing dataset '" + name + "'");
      if (slash == std::string::npos) break;
      start = slash + 1;
    }
    Handle dataset(H5Dopen2(file_, name.c_str(), H5P_DEFAULT), H5Dclose);
    if (!dataset.valid()) corrupt("dataset '" + name + "'");
    return dataset;
  }

  std::string string_dataset(const std::string& name) const {
    Handle dataset = open_dataset(name);
    Handle type(H5Dget_type(dataset.get()), H5Tclose);
    if (!type.valid()) corrupt("dataset '" + name + "'");
    if (H5Tget_class(type.get()) != H5T_STRING) fail("dataset '" + name + "' is not a string");
    Handle space(H5Dget_space(dataset.get()), H5Sclose);
    if (!space.valid()) corrupt("dataset '" + name + "'");
    if (H5Sget_simple_extent_npoints(space.get()) != 1)
      fail("dataset '" + name + "' must hold one string");
    return read_string(type.get(), "dataset '" + name + "'", [&](hid_t memory_type, void* buffer) {
      return H5Dread(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer);
    });
  }

  // Reads a numeric dataset after checking its type class and its shape against `expected`.
  template <typename T>
  std::vector<T> numeric_dataset(const std::string& name, H5T_class_t expected_class,
                                 hid_t memory_type, const std::vector<hsize_t>& expected) const {
    Handle dataset = open_dataset(name);
    Handle type(H5Dget_type(dataset.get()), H5Tclose);
    if (!type.valid()) corrupt("dataset '" + name + "'");
    if (H5Tget_class(type.get()) != expected_class)
      fail("dataset '" + name + "' has the wrong element type (expected " +
           (expected_class == H5T_FLOAT ? "float64" : "unsigned integers") + ")");
    Handle space(H5Dget_space(dataset.get()), H5Sclose);
    if (!space.valid()) corrupt("dataset '" + name + "'");
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 0) corrupt("dataset '" + name + "'");
    std::vector<hsize_t> shape(static_cast<std::size_t>(rank));
    if (rank > 0 && H5Sget_simple_extent_dims(space.get(), shape.data(), nullptr) < 0)
      corrupt("dataset '" + name + "'");
    if (shape != expected)
      fail("dataset '" + name + "' has shape " + shape_text(shape) + ", expected " +
           shape_text(expected) + " from the grids and the horizon");
    std::size_t elements = 1;
    for (hsize_t extent : shape) elements *= std::size_t(extent);
    std::vector<T> data(elements);
    // HDF5 verifies the Fletcher-32 checksum of each chunk here.
    if (elements > 0 &&
        H5Dread(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
      corrupt("dataset '" + name + "' (its checksum does not match or its data is missing)");
    return data;
  }

  // Vector dataset whose length is not known in advance (the grid vectors).
  template <typename T>
  std::vector<T> vector_dataset(const std::string& name, H5T_class_t expected_class,
                                hid_t memory_type) const {
    Handle dataset = open_dataset(name);
    Handle space(H5Dget_space(dataset.get()), H5Sclose);
    if (!space.valid()) corrupt("dataset '" + name + "'");
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank != 1) fail("dataset '" + name + "' must be a vector");
    hsize_t length = 0;
    if (H5Sget_simple_extent_dims(space.get(), &length, nullptr) < 0)
      corrupt("dataset '" + name + "'");
    return numeric_dataset<T>(name, expected_class, memory_type, {length});
  }

  Grid grid(const std::string& group_name) const {
    const auto lb = vector_dataset<double>(group_name + "/lb", H5T_FLOAT, H5T_NATIVE_DOUBLE);
    const auto eta = vector_dataset<double>(group_name + "/eta", H5T_FLOAT, H5T_NATIVE_DOUBLE);
    const auto counts =
        vector_dataset<std::uint64_t>(group_name + "/counts", H5T_INTEGER, H5T_NATIVE_UINT64);
    if (eta.size() != lb.size() || counts.size() != lb.size())
      fail("'" + group_name + "' has lb, eta and counts of different lengths (" +
           std::to_string(lb.size()) + ", " + std::to_string(eta.size()) + ", " +
           std::to_string(counts.size()) + ")");
    GridSpec spec;
    spec.lb = lb;
    spec.eta = eta;
    for (std::size_t dim = 0; dim < lb.size(); ++dim) {
      if (!std::isfinite(lb[dim]) || !std::isfinite(eta[dim]) || !(eta[dim] > 0) ||
          counts[dim] == 0)
        fail("'" + group_name + "' dimension " + std::to_string(dim) +
             " needs a finite lb, eta > 0 and counts >= 1");
      spec.ub.push_back(lb[dim] + double(counts[dim] - 1) * eta[dim]);
    }
    Grid grid(spec);
    for (std::size_t dim = 0; dim < lb.size(); ++dim)
      if (grid.count(dim) != counts[dim])
        fail("'" + group_name + "/counts' does not match lb and eta in dimension " +
             std::to_string(dim));
    return grid;
  }

 private:
  static std::string shape_text(const std::vector<hsize_t>& shape) {
    std::ostringstream text;
    text << "(";
    for (std::size_t i = 0; i < shape.size(); ++i) text << (i ? ", " : "") << shape[i];
    if (shape.size() == 1) text << ",";
    text << ")";
    return text.str();
  }

  template <typename ReadFunction>
  std::string read_string(hid_t stored_type, const std::string& what, ReadFunction read) const {
    const htri_t variable = H5Tis_variable_str(stored_type);
    if (variable < 0) corrupt(what);
    Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose);
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

  hid_t file_;
  std::string path_;
};

Policy read_contents(hid_t file, const std::string& path, LoadedPolicy& loaded) {
  Reader reader(file, path);
  if (!reader.has_attribute("format"))
    reader.fail("not an amytiss policy (no 'format' attribute on /)");
  const std::string format = reader.string_attribute("format");
  if (format != kFormatName)
    reader.fail("not an amytiss policy (format is '" + format + "', expected '" + kFormatName +
                "')");
  const std::uint64_t version = reader.unsigned_attribute("format_version");
  if (version != kFormatVersion)
    reader.fail("format_version " + std::to_string(version) + " is not supported (this build reads " +
                std::to_string(kFormatVersion) + ")");

  Policy policy;
  FileAttributes attributes;
  attributes.format = format;
  attributes.format_version = version;
  attributes.config_hash = loaded.config_hash = policy.config_hash = reader.string_attribute("config_hash");
  attributes.computed_by = policy.computed_by = reader.string_attribute("computed_by");
  attributes.run_id = policy.run_id = reader.string_attribute("run_id");
  attributes.engine_version = loaded.engine_version = reader.unsigned_attribute("engine_version");
  attributes.horizon = reader.unsigned_attribute("horizon");
  if (attributes.horizon == 0 || attributes.horizon > std::numeric_limits<unsigned>::max())
    reader.fail("horizon " + std::to_string(attributes.horizon) + " is out of range (expected >= 1)");
  policy.horizon = unsigned(attributes.horizon);
  attributes.spec = reader.string_attribute("spec");
  if (reader.has_attribute("stationary")) {
    attributes.stationary = reader.unsigned_attribute("stationary");
    if (attributes.stationary != 1 || attributes.horizon != 1)
      reader.fail("stationary is " + std::to_string(attributes.stationary) + " with horizon " +
                  std::to_string(attributes.horizon) + ", expected stationary 1 with horizon 1");
    attributes.iterations = reader.unsigned_attribute("iterations");
    policy.stationary = true;
    policy.iterations = unsigned(std::min<std::uint64_t>(attributes.iterations, std::numeric_limits<unsigned>::max()));
    attributes.converged = reader.unsigned_attribute("converged");
    if (attributes.converged > 1) reader.fail("converged is " + std::to_string(attributes.converged) + ", expected 0 or 1");
    policy.converged = attributes.converged == 1;
  }
  const std::string stored_digest = reader.string_attribute("content_digest");
  loaded.config_yaml = reader.string_dataset("/config");

  policy.states = reader.grid("/states");
  policy.inputs = reader.grid("/inputs");
  if (policy.states.dims() == 0) reader.fail("'/states' has no dimensions");

  policy.values = reader.numeric_dataset<double>(
      "/values", H5T_FLOAT, H5T_NATIVE_DOUBLE, cell_shape(policy.states, policy.horizon + 1));
  for (std::size_t i = 0; i < policy.values.size(); ++i) {
    const double value = policy.values[i];
    if (!(value >= 0.0 && value <= 1.0))
      reader.fail("'/values' element " + std::to_string(i) + " is " + std::to_string(value) +
                  ", expected a probability in [0, 1]");
  }

  policy.input_index = reader.numeric_dataset<std::uint32_t>(
      "/input_index", H5T_INTEGER, H5T_NATIVE_UINT32, cell_shape(policy.states, policy.horizon));
  for (std::size_t i = 0; i < policy.input_index.size(); ++i)
    if (policy.input_index[i] >= policy.inputs.size())
      reader.fail("'/input_index' element " + std::to_string(i) + " is " +
                  std::to_string(policy.input_index[i]) + ", expected below the " +
                  std::to_string(policy.inputs.size()) + " inputs of the grid");

  const auto input_values = reader.numeric_dataset<double>(
      "/input_values", H5T_FLOAT, H5T_NATIVE_DOUBLE,
      {hsize_t(policy.inputs.size()), hsize_t(policy.inputs.dims())});
  std::vector<double> point(policy.inputs.dims());
  for (std::size_t flat = 0; flat < policy.inputs.size(); ++flat) {
    policy.inputs.point(flat, point.data());
    for (std::size_t dim = 0; dim < point.size(); ++dim)
      if (input_values[flat * point.size() + dim] != point[dim])
        reader.fail("'/input_values' row " + std::to_string(flat) +
                    " does not match the input grid");
  }

  std::vector<hsize_t> role_shape = cell_shape(policy.states, 1);
  role_shape.erase(role_shape.begin());
  const auto roles =
      reader.numeric_dataset<std::uint8_t>("/roles", H5T_INTEGER, H5T_NATIVE_UINT8, role_shape);
  policy.roles.reserve(roles.size());
  for (std::size_t i = 0; i < roles.size(); ++i) {
    if (roles[i] > std::uint8_t(CellRole::FixedOne))
      reader.fail("'/roles' element " + std::to_string(i) + " is " + std::to_string(roles[i]) +
                  ", expected 0 (free), 1 (fixed zero) or 2 (fixed one)");
    policy.roles.push_back(CellRole(roles[i]));
  }
  if (policy.stationary) {
    policy.upper_values =
        reader.numeric_dataset<double>("/upper_values", H5T_FLOAT, H5T_NATIVE_DOUBLE, role_shape);
    for (std::size_t i = 0; i < policy.upper_values.size(); ++i) {
      if (!(policy.upper_values[i] >= 0.0 && policy.upper_values[i] <= 1.0))
        reader.fail("'/upper_values' element " + std::to_string(i) + " is " + std::to_string(policy.upper_values[i]) +
                    ", expected a probability in [0, 1]");
      policy.gap = std::max(policy.gap, policy.upper_values[i] - policy.values[i]);
    }
  }
  const std::string digest = digest_of(attributes, loaded.config_yaml, policy);
  if (digest != stored_digest)
    reader.fail("corrupt: its contents give the digest " + digest + " but the file records " + stored_digest +
                " (modified or damaged after it was written)");
  return policy;
}

}  // namespace

void write_policy_file(const std::string& path, const Policy& policy, const Config& config) {
  check_policy_values(policy);
  detail::write_policy_file_as(path, policy, config, kFormatName, kFormatVersion);
}

namespace detail {
void write_policy_file_as(const std::string& path, const Policy& policy, const Config& config,
                          const std::string& format, unsigned format_version, unsigned engine_version) {
  check_policy_consistent(policy);
  const std::string hash = config_hash(config);
  if (!policy.config_hash.empty() && policy.config_hash != hash)
    throw PolicyFileError("cannot write " + path + ": the policy was computed from configuration " +
                          policy.config_hash + " but the configuration given has hash " + hash);
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  SilenceHdf5Errors silence;
  try {
    Handle file(H5Fcreate(temporary.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
    if (!file.valid()) throw PolicyFileError("cannot create " + temporary);
    write_contents(file.get(), policy, config, hash, format, format_version, engine_version);
    if (H5Fflush(file.get(), H5F_SCOPE_GLOBAL) < 0) throw PolicyFileError("cannot flush");
  } catch (const PolicyFileError& error) {
    std::remove(temporary.c_str());
    throw PolicyFileError("cannot write policy file " + path + ": " + error.what());
  } catch (...) {
    std::remove(temporary.c_str());
    throw;
  }
  // The file is closed (Handle destroyed) before the rename, so readers see it complete.
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    std::remove(temporary.c_str());
    throw PolicyFileError("cannot write policy file " + path + ": rename from " + temporary +
                          " failed");
  }
}
}  // namespace detail

LoadedPolicy read_policy_file(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0)
    throw PolicyFileError("policy file " + path + " does not exist");
  if (!S_ISREG(info.st_mode)) throw PolicyFileError("policy file " + path + " is not a file");
  SilenceHdf5Errors silence;
  if (H5Fis_hdf5(path.c_str()) <= 0)
    throw PolicyFileError("policy file " + path +
                          " is truncated or corrupt (not a readable HDF5 file)");
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.valid())
    throw PolicyFileError("policy file " + path +
                          " is truncated or corrupt (HDF5 cannot open it)");
  LoadedPolicy loaded;
  loaded.policy = read_contents(file.get(), path, loaded);
  return loaded;
}

LoadedPolicy read_policy_file_for(const std::string& path, const Config& config) {
  LoadedPolicy loaded = read_policy_file(path);
  const std::string expected = config_hash(config);
  if (loaded.config_hash != expected)
    throw PolicyFileError("policy file " + path + " was made from another configuration (its " +
                          "config_hash is " + loaded.config_hash + ", this configuration's is " +
                          expected + ")");
  if (loaded.engine_version != kEngineVersion)
    throw PolicyFileError("policy file " + path + " was computed by engine version " +
                          std::to_string(loaded.engine_version) + "; this build computes version " +
                          std::to_string(kEngineVersion) + ", whose results may differ");
  return loaded;
}

}  // namespace amytiss
