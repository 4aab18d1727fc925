#include "io/policy_format.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "amytiss/errors.hpp"
#include "io/policy_digest.hpp"
#include "io/policy_storage.hpp"
#include "io/refinement_format.hpp"

namespace amytiss::detail {
namespace {

std::vector<hsize_t> cell_shape(const Grid& states, std::size_t leading) {
  std::vector<hsize_t> shape{hsize_t(leading)};
  for (std::size_t count : states.counts()) shape.push_back(hsize_t(count));
  return shape;
}

// (n0, n1, ...): one element per cell.
std::vector<hsize_t> per_cell_shape(const Grid& states) {
  std::vector<hsize_t> shape = cell_shape(states, 1);
  shape.erase(shape.begin());
  return shape;
}

// Stationary: one upper bound per cell; bounded horizons: one per value.
std::vector<hsize_t> upper_values_shape(const Policy& policy) {
  return policy.stationary ? per_cell_shape(policy.states) : cell_shape(policy.states, policy.horizon + 1);
}

// lb, eta and counts per dimension (eta NaN for a dimension given by its faces, lb its first
// point), and the faces of every dimension of the state grid, faces/<d>.
void write_grid(const Hdf5Writer& writer, const std::string& group_name, const Grid& grid, bool with_faces) {
  writer.group(group_name);
  const std::vector<hsize_t> shape{hsize_t(grid.dims())};
  std::vector<std::uint64_t> counts(grid.counts().begin(), grid.counts().end());
  std::vector<double> eta = grid.eta();
  for (std::size_t d = 0; d < grid.dims(); ++d)
    if (!grid.uniform(d)) eta[d] = std::numeric_limits<double>::quiet_NaN();
  writer.dataset(group_name + "/lb", shape, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, grid.lb().data());
  writer.dataset(group_name + "/eta", shape, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, eta.data());
  writer.dataset(group_name + "/counts", shape, H5T_STD_U64LE, H5T_NATIVE_UINT64, counts.data());
  if (!with_faces) return;
  writer.group(group_name + "/faces");
  for (std::size_t d = 0; d < grid.dims(); ++d) {
    const std::vector<double> faces = grid.faces(d);
    writer.dataset(group_name + "/faces/" + std::to_string(d), {hsize_t(faces.size())}, H5T_IEEE_F64LE,
                   H5T_NATIVE_DOUBLE, faces.data());
  }
}

void write_attributes(const Hdf5Writer& writer, const PolicyFileAttributes& attributes, const std::string& digest) {
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
  if (!attributes.guarantee.empty()) writer.string_attribute("guarantee", attributes.guarantee);
  writer.string_attribute("content_digest", digest);
}

// A dimension with eta NaN is given by its faces (faces/<d>, counts + 1 strictly increasing
// values); a uniform one by lb and eta, and its faces, where the file has them, must be those.
Grid read_grid(const Hdf5Reader& reader, const std::string& group_name) {
  const auto lb = reader.vector_dataset<double>(group_name + "/lb", H5T_FLOAT, H5T_NATIVE_DOUBLE);
  const auto eta = reader.vector_dataset<double>(group_name + "/eta", H5T_FLOAT, H5T_NATIVE_DOUBLE);
  const auto counts = reader.vector_dataset<std::uint64_t>(group_name + "/counts", H5T_INTEGER, H5T_NATIVE_UINT64);
  if (eta.size() != lb.size() || counts.size() != lb.size())
    reader.fail("'" + group_name + "' has lb, eta and counts of different lengths (" + std::to_string(lb.size()) +
                ", " + std::to_string(eta.size()) + ", " + std::to_string(counts.size()) + ")");
  const bool has_faces = reader.has_object(group_name + "/faces");
  std::vector<std::vector<double>> faces(lb.size());
  GridSpec spec;
  spec.lb = lb;
  spec.eta = eta;
  for (std::size_t dim = 0; dim < lb.size(); ++dim) {
    const std::string name = group_name + "/faces/" + std::to_string(dim);
    if (has_faces) faces[dim] = reader.vector_dataset<double>(name, H5T_FLOAT, H5T_NATIVE_DOUBLE);
    if (has_faces && faces[dim].size() != counts[dim] + 1)
      reader.fail("'" + name + "' has " + std::to_string(faces[dim].size()) + " faces, expected counts + 1 = " +
                  std::to_string(counts[dim] + 1));
    if (std::isnan(eta[dim]) && has_faces) {
      for (std::size_t k = 0; k < faces[dim].size(); ++k)
        if (!std::isfinite(faces[dim][k]) || (k > 0 && !(faces[dim][k - 1] < faces[dim][k])))
          reader.fail("'" + name + "' needs finite, strictly increasing faces");
      spec.faces.resize(lb.size());
      spec.faces[dim] = faces[dim];
      spec.ub.push_back(eta[dim]);
      continue;
    }
    if (!std::isfinite(lb[dim]) || !std::isfinite(eta[dim]) || !(eta[dim] > 0) || counts[dim] == 0)
      reader.fail("'" + group_name + "' dimension " + std::to_string(dim) +
                  " needs a finite lb, eta > 0 and counts >= 1 (or eta NaN and its faces in faces/" +
                  std::to_string(dim) + ")");
    spec.ub.push_back(lb[dim] + double(counts[dim] - 1) * eta[dim]);
  }
  Grid grid(spec);
  for (std::size_t dim = 0; dim < lb.size(); ++dim) {
    if (grid.count(dim) != counts[dim])
      reader.fail("'" + group_name + "/counts' does not match lb and eta in dimension " + std::to_string(dim));
    if (has_faces && grid.uniform(dim) && grid.faces(dim) != faces[dim])
      reader.fail("'" + group_name + "/faces/" + std::to_string(dim) + "' does not match lb and eta");
  }
  return grid;
}

// The attributes on /, after the format name and version are checked; fills the policy's.
PolicyFileAttributes read_attributes(const Hdf5Reader& reader, Policy& policy) {
  if (!reader.has_attribute("format")) reader.fail("not an amytiss policy (no 'format' attribute on /)");
  PolicyFileAttributes attributes;
  attributes.format = reader.string_attribute("format");
  if (attributes.format != kPolicyFormatName)
    reader.fail("not an amytiss policy (format is '" + attributes.format + "', expected '" + kPolicyFormatName +
                "')");
  attributes.format_version = reader.unsigned_attribute("format_version");
  if (attributes.format_version != kPolicyFormatVersion)
    reader.fail("format_version " + std::to_string(attributes.format_version) +
                " is not supported (this build reads " + std::to_string(kPolicyFormatVersion) + ")");
  attributes.config_hash = policy.config_hash = reader.string_attribute("config_hash");
  attributes.computed_by = policy.computed_by = reader.string_attribute("computed_by");
  attributes.run_id = policy.run_id = reader.string_attribute("run_id");
  attributes.engine_version = reader.unsigned_attribute("engine_version");
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
    if (attributes.converged > 1)
      reader.fail("converged is " + std::to_string(attributes.converged) + ", expected 0 or 1");
    policy.converged = attributes.converged == 1;
  }
  if (reader.has_attribute("guarantee")) {
    attributes.guarantee = reader.string_attribute("guarantee");
    if (attributes.guarantee != to_string(Guarantee::System))
      reader.fail("guarantee is '" + attributes.guarantee + "', expected 'system' (or no attribute: abstraction)");
    policy.guarantee = Guarantee::System;
  }
  return attributes;
}

void check_probabilities(const Hdf5Reader& reader, const std::string& name, const std::vector<double>& values) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!(values[i] >= 0.0 && values[i] <= 1.0))
      reader.fail("'" + name + "' element " + std::to_string(i) + " is " + std::to_string(values[i]) +
                  ", expected a probability in [0, 1]");
}

// Values are float64 (exact) or float32 (rounded outward), widened to double on reading.
void check_value_type(const Hdf5Reader& reader, const std::string& name) {
  const Hdf5Reader::ElementType type = reader.element_type(name);
  if (type.type_class != H5T_FLOAT || (type.bytes != 4 && type.bytes != 8))
    reader.fail("dataset '" + name + "' has the wrong element type (expected float64 or float32)");
}

// Input indices are uint8, uint16 or uint32 (the narrowest that holds the grid's inputs; files
// of older builds: always uint32), widened to uint32 on reading.
void check_index_type(const Hdf5Reader& reader) {
  const Hdf5Reader::ElementType type = reader.element_type("/input_index");
  if (type.type_class != H5T_INTEGER || type.is_signed || (type.bytes != 1 && type.bytes != 2 && type.bytes != 4))
    reader.fail("dataset '/input_index' has the wrong element type (expected uint8, uint16 or uint32)");
}

void read_input_arrays(const Hdf5Reader& reader, Policy& policy) {
  check_index_type(reader);
  policy.input_index = reader.numeric_dataset<std::uint32_t>("/input_index", H5T_INTEGER, H5T_NATIVE_UINT32,
                                                             cell_shape(policy.states, policy.horizon));
  for (std::size_t i = 0; i < policy.input_index.size(); ++i)
    if (policy.input_index[i] >= policy.inputs.size())
      reader.fail("'/input_index' element " + std::to_string(i) + " is " + std::to_string(policy.input_index[i]) +
                  ", expected below the " + std::to_string(policy.inputs.size()) + " inputs of the grid");
  const auto input_values = reader.numeric_dataset<double>(
      "/input_values", H5T_FLOAT, H5T_NATIVE_DOUBLE, {hsize_t(policy.inputs.size()), hsize_t(policy.inputs.dims())});
  const std::vector<double> expected = input_points(policy.inputs);
  for (std::size_t i = 0; i < expected.size(); ++i)
    if (input_values[i] != expected[i])
      reader.fail("'/input_values' row " + std::to_string(i / policy.inputs.dims()) +
                  " does not match the input grid");
}

void read_cell_arrays(const Hdf5Reader& reader, Policy& policy) {
  check_value_type(reader, "/values");
  policy.values = reader.numeric_dataset<double>("/values", H5T_FLOAT, H5T_NATIVE_DOUBLE,
                                                 cell_shape(policy.states, policy.horizon + 1));
  check_probabilities(reader, "/values", policy.values);
  read_input_arrays(reader, policy);
  const auto roles =
      reader.numeric_dataset<std::uint8_t>("/roles", H5T_INTEGER, H5T_NATIVE_UINT8, per_cell_shape(policy.states));
  policy.roles.reserve(roles.size());
  for (std::size_t i = 0; i < roles.size(); ++i) {
    if (roles[i] > std::uint8_t(CellRole::FixedOne))
      reader.fail("'/roles' element " + std::to_string(i) + " is " + std::to_string(roles[i]) +
                  ", expected 0 (free), 1 (fixed zero) or 2 (fixed one)");
    policy.roles.push_back(CellRole(roles[i]));
  }
  if (!policy.stationary && policy.guarantee != Guarantee::System) return;
  check_value_type(reader, "/upper_values");
  policy.upper_values = reader.numeric_dataset<double>("/upper_values", H5T_FLOAT, H5T_NATIVE_DOUBLE,
                                                       upper_values_shape(policy));
  check_probabilities(reader, "/upper_values", policy.upper_values);
  if (policy.stationary)
    for (std::size_t i = 0; i < policy.upper_values.size(); ++i)
      policy.gap = std::max(policy.gap, policy.upper_values[i] - policy.values[i]);
}

}  // namespace

void check_policy_consistent(const Policy& policy) {
  const std::size_t cells = policy.states.size();
  if (policy.values.size() != (std::size_t(policy.horizon) + 1) * cells)
    throw PolicyFileError("cannot write a policy with " + std::to_string(policy.values.size()) +
                          " values: expected (horizon+1)*cells = " +
                          std::to_string((std::size_t(policy.horizon) + 1) * cells));
  if (policy.input_index.size() != std::size_t(policy.horizon) * cells)
    throw PolicyFileError("cannot write a policy with " + std::to_string(policy.input_index.size()) +
                          " input indices: expected horizon*cells = " +
                          std::to_string(std::size_t(policy.horizon) * cells));
  if (policy.roles.size() != cells)
    throw PolicyFileError("cannot write a policy with " + std::to_string(policy.roles.size()) +
                          " cell roles: expected " + std::to_string(cells));
  if (policy.stationary && (policy.horizon != 1 || policy.upper_values.size() != cells))
    throw PolicyFileError("cannot write a stationary policy with horizon " + std::to_string(policy.horizon) +
                          " and " + std::to_string(policy.upper_values.size()) +
                          " upper bounds: expected horizon 1 and " + std::to_string(cells));
  if (!policy.stationary && policy.guarantee == Guarantee::System && policy.upper_values.size() != policy.values.size())
    throw PolicyFileError("cannot write continuous-system bounds with " + std::to_string(policy.upper_values.size()) +
                          " upper bounds: expected one per value, " + std::to_string(policy.values.size()));
  if (!policy.stationary && policy.guarantee == Guarantee::Abstraction && !policy.upper_values.empty())
    throw PolicyFileError("cannot write abstraction values with upper bounds (only unbounded specifications and "
                          "guarantee: system have them)");
}

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
      throw PolicyFileError("cannot write a policy whose input index " + std::to_string(i) + " is " +
                            std::to_string(policy.input_index[i]) + " (the grid has " +
                            std::to_string(policy.inputs.size()) + " inputs)");
}

void write_policy_contents(const Hdf5Writer& writer, const Policy& policy, const Config& config,
                           const std::string& config_hash, const std::string& format, unsigned format_version,
                           unsigned engine_version) {
  PolicyFileAttributes attributes;
  attributes.format = format;
  attributes.format_version = format_version;
  attributes.config_hash = config_hash;
  attributes.computed_by = policy.computed_by;
  attributes.run_id = policy.run_id;
  attributes.engine_version = engine_version;
  attributes.horizon = policy.horizon;
  attributes.spec = to_string(config.spec.type);
  attributes.stationary = policy.stationary ? 1 : 0;
  attributes.iterations = policy.stationary ? policy.iterations : 0;
  attributes.converged = policy.stationary && policy.converged ? 1 : 0;
  if (policy.guarantee == Guarantee::System) attributes.guarantee = to_string(Guarantee::System);
  const std::string config_yaml = to_yaml(config);
  const StoredValueArrays stored(policy, config.output.values);

  write_attributes(writer, attributes,
                   policy_digest(attributes, config_yaml, policy, stored.values(), stored.upper_values()));
  writer.string_dataset("/config", config_yaml);
  write_grid(writer, "/states", policy.states, true);
  write_grid(writer, "/inputs", policy.inputs, false);
  stored.write(writer, "/values", cell_shape(policy.states, policy.horizon + 1), stored.values());
  writer.dataset("/input_index", cell_shape(policy.states, policy.horizon), input_index_file_type(policy.inputs.size()),
                 H5T_NATIVE_UINT32, policy.input_index.data(), Hdf5Writer::Filters::Compressed);
  const std::vector<double> input_values = input_points(policy.inputs);
  writer.dataset("/input_values", {hsize_t(policy.inputs.size()), hsize_t(policy.inputs.dims())}, H5T_IEEE_F64LE,
                 H5T_NATIVE_DOUBLE, input_values.data());
  static_assert(sizeof(CellRole) == sizeof(std::uint8_t), "roles are stored as uint8");
  writer.dataset("/roles", per_cell_shape(policy.states), H5T_STD_U8LE, H5T_NATIVE_UINT8, policy.roles.data(),
                 Hdf5Writer::Filters::Compressed);
  if (policy.stationary || policy.guarantee == Guarantee::System)
    stored.write(writer, "/upper_values", upper_values_shape(policy), stored.upper_values());
  write_refinement(writer, policy.refinement);
}

LoadedPolicy read_policy_contents(const Hdf5Reader& reader) {
  LoadedPolicy loaded;
  Policy& policy = loaded.policy;
  const PolicyFileAttributes attributes = read_attributes(reader, policy);
  loaded.config_hash = attributes.config_hash;
  loaded.engine_version = unsigned(attributes.engine_version);
  const std::string stored_digest = reader.string_attribute("content_digest");
  loaded.config_yaml = reader.string_dataset("/config");
  policy.states = read_grid(reader, "/states");
  policy.inputs = read_grid(reader, "/inputs");
  if (policy.states.dims() == 0) reader.fail("'/states' has no dimensions");
  read_cell_arrays(reader, policy);
  policy.refinement = read_refinement(reader, policy.states.dims());
  const std::string digest = policy_digest(attributes, loaded.config_yaml, policy, policy.values, policy.upper_values);
  if (digest != stored_digest)
    reader.fail("corrupt: its contents give the digest " + digest + " but the file records " + stored_digest +
                " (modified or damaged after it was written)");
  return loaded;
}

}  // namespace amytiss::detail
