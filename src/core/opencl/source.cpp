// Why the generated source looks as it does; the contract it fulfils is in kernels/engine.cl.
#include "opencl/source.hpp"

#include <algorithm>
#include <cstdint>
#include <sstream>
#include <vector>

#include "amytiss/format.hpp"
#include "common/embedded_sources.hpp"

namespace amytiss::detail {
namespace {

template <typename T, typename F>
std::string constant_array(const char* type, const char* name, const std::vector<T>& values,
                           F format) {
  std::string text = std::string("__constant ") + type + " " + name + "[" +
                     std::to_string(std::max<std::size_t>(1, values.size())) + "] = {";
  if (values.empty()) text += format(T{});
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + format(values[i]);
  return text + "};\n";
}
std::string int_text(long long value) { return std::to_string(value); }

std::vector<long long> counts_of(const Grid& grid) {
  std::vector<long long> counts;
  for (std::size_t i = 0; i < grid.dims(); ++i) counts.push_back(static_cast<long long>(grid.count(i)));
  return counts;
}

// The separable contraction, generated with literal trip counts and offsets, nested outermost =
// dimension 0. Values are double; masses float, converted once. For a window narrower than
// kUnrollLimit in the last dimension, the last two dimensions are contracted as weighted rows:
// rows of the last dimension are accumulated with their dimension d-2 mass into double4 vectors
// (two independent sets, even and odd rows, to keep the FMA latency chains short), and the
// result is dotted once with the last dimension's masses. Lanes beyond the window carry mass 0
// (the value buffer has kValueSlack extra zero cells, so the over-read stays in bounds).
constexpr long long kUnrollLimit = 64;

// The last dimension's masses in double4 vectors inner_mass0.. (lanes past the window: 0).
void emit_inner_masses(std::ostringstream& s, const Layout& layout) {
  const std::size_t dims = layout.width.size();
  const long long inner_width = layout.width[dims - 1], inner_offset = layout.mass_offset[dims - 1];
  const long long vectors = (inner_width + 3) / 4;
  for (long long k = 0; k < vectors; ++k) {
    s << "  const double4 inner_mass" << k << " = ";
    if (4 * k + 4 <= inner_width) {
      s << "convert_double4(vload4(0, m + " << inner_offset + 4 * k << "));\n";
    } else {
      s << "(double4)(";
      for (long long lane = 0; lane < 4; ++lane) {
        const long long j = 4 * k + lane;
        s << (lane ? ", " : "") << (j < inner_width ? "(double)m[" + std::to_string(inner_offset + j) + "]" : "0.0");
      }
      s << ");\n";
    }
  }
}

// The rows of the last dimension at `pointer`, weighted by dimension d-2's masses (a single row
// of weight 1 when dims == 1), dotted with inner_mass*: the double `rows`.
void emit_row_contraction(std::ostringstream& s, const Layout& layout, const std::string& pointer,
                          const std::string& indent) {
  const std::size_t dims = layout.width.size();
  const long long vectors = (layout.width[dims - 1] + 3) / 4;
  auto row_load = [&](const std::string& row_pointer, long long k) {
    return "vload4(" + std::to_string(k) + ", " + row_pointer + ")";
  };
  std::vector<std::string> summed(vectors);
  if (dims == 1) {
    for (long long k = 0; k < vectors; ++k) summed[k] = row_load(pointer, k);
  } else {
    const std::size_t r = dims - 2;
    const long long row_width = layout.width[r], row_offset = layout.mass_offset[r],
                    row_stride = layout.padded_stride[r];
    const bool two_sets = row_width >= 2;
    for (long long k = 0; k < vectors; ++k) {
      s << indent << "double4 even" << k << " = 0.0;\n";
      if (two_sets) s << indent << "double4 odd" << k << " = 0.0;\n";
    }
    auto accumulate = [&](const std::string& set, const std::string& row) {
      s << indent << "  {\n" << indent << "    const double weight = m[" << row_offset << " + " << row << "];\n"
        << indent << "    __global const double* row = " << pointer << " + (" << row << ") * " << row_stride << ";\n";
      for (long long k = 0; k < vectors; ++k)
        s << indent << "    " << set << k << " = fma((double4)(weight), " << row_load("row", k) << ", " << set << k
          << ");\n";
      s << indent << "  }\n";
    };
    if (two_sets) {
      s << indent << "for (int r = 0; r + 1 < " << row_width << "; r += 2) {\n";
      accumulate("even", "r");
      accumulate("odd", "r + 1");
      s << indent << "}\n";
    }
    if (row_width % 2) {
      s << indent << "{\n" << indent << "  const int r = " << row_width - 1 << ";\n";
      accumulate("even", "r");
      s << indent << "}\n";
    }
    for (long long k = 0; k < vectors; ++k)
      summed[k] = two_sets ? "(even" + std::to_string(k) + " + odd" + std::to_string(k) + ")" : "even" + std::to_string(k);
  }
  std::vector<std::string> terms;
  for (long long k = 0; k < vectors; ++k) terms.push_back("inner_mass" + std::to_string(k) + " * " + summed[k]);
  while (terms.size() > 1) {
    std::vector<std::string> paired;
    for (std::size_t t = 0; t + 1 < terms.size(); t += 2) paired.push_back("(" + terms[t] + " + " + terms[t + 1] + ")");
    if (terms.size() % 2) paired.push_back(terms.back());
    terms = paired;
  }
  s << indent << "const double4 lanes = " << terms.front() << ";\n";
  s << indent << "const double2 halves = lanes.lo + lanes.hi;\n";
  s << indent << "const double rows = halves.x + halves.y;\n";
}

}  // namespace

std::string contraction_source(const Layout& layout, const std::string& name,
                               const std::string& mass_space) {
  const std::size_t dims = layout.width.size();
  std::ostringstream s;
  s << "double " << name << "(__global const double* v, " << mass_space << " const float* m) {\n";
  const long long inner_width = layout.width[dims - 1], inner_offset = layout.mass_offset[dims - 1];
  const bool rows = inner_width <= kUnrollLimit;
  const std::size_t outer_levels = rows ? (dims >= 2 ? dims - 2 : 0) : dims - 1;
  if (rows) emit_inner_masses(s, layout);
  // Opens the outer loops (scalar FMA chains, zero-mass rows skipped).
  std::string pointer = "v";
  for (std::size_t i = 0; i < outer_levels; ++i) {
    const std::string indent(2 * (i + 1), ' '), a = "a" + std::to_string(i);
    s << indent << "double acc" << i << " = 0.0;\n";
    s << indent << "for (int " << a << " = 0; " << a << " < " << layout.width[i] << "; ++" << a << ") {\n";
    s << indent << "  const double mass" << i << " = m[" << layout.mass_offset[i] << " + " << a << "];\n";
    s << indent << "  if (mass" << i << " == 0.0) continue;\n";
    s << indent << "  __global const double* v" << i << " = " << pointer << " + " << a << " * "
      << layout.padded_stride[i] << ";\n";
    pointer = "v" + std::to_string(i);
  }
  const std::string indent(2 * (outer_levels + 1), ' ');
  if (rows) {
    emit_row_contraction(s, layout, pointer, indent);
  } else {
    s << indent << "double rows = 0.0;\n";
    s << indent << "for (int j = 0; j < " << inner_width << "; ++j)\n";
    s << indent << "  rows = fma((double)m[" << inner_offset << " + j], " << pointer << "[j], rows);\n";
  }
  if (outer_levels == 0) {
    s << "  return rows;\n}\n";
    return s.str();
  }
  s << indent << "acc" << outer_levels - 1 << " = fma(mass" << outer_levels - 1 << ", rows, acc" << outer_levels - 1
    << ");\n";
  for (std::size_t i = outer_levels; i-- > 0;) {
    const std::string close_indent(2 * (i + 1), ' ');
    s << close_indent << "}\n";
    if (i > 0) s << close_indent << "acc" << i - 1 << " = fma(mass" << i - 1 << ", acc" << i << ", acc" << i - 1 << ");\n";
  }
  s << "  return acc0;\n}\n";
  return s.str();
}

namespace {

// A state grid with faces (kernels/engine.cl, FACED_STATES): per dimension whether it is given by
// its faces, where they start in STATE_FACES and its points in STATE_POINTS (count + 1 faces and
// count points each, dimension after dimension), and its kept radius (NoiseModel::window_radius).
std::string faced_prelude(const Abstraction& a) {
  std::vector<long long> faced, start;
  std::vector<double> faces, points;
  for (std::size_t d = 0; d < a.states.dims(); ++d) {
    faced.push_back(a.states.uniform(d) ? 0 : 1);
    start.push_back(static_cast<long long>(faces.size()));
    if (a.states.uniform(d)) continue;
    const std::vector<double> listed = a.states.faces(d);
    faces.insert(faces.end(), listed.begin(), listed.end());
    for (std::size_t k = 0; k < a.states.count(d); ++k) points.push_back(a.states.coordinate(d, k));
  }
  // A dimension's points start where its faces do, less one per faced dimension before it.
  std::vector<long long> point_start;
  long long before = 0;
  for (std::size_t d = 0; d < faced.size(); ++d) {
    point_start.push_back(start[d] - before);
    before += faced[d];
  }
  auto real = [](double v) { return c_double_literal(v); };
  auto integer = [](long long v) { return int_text(v); };
  return "#define FACED_STATES 1\n" + constant_array("int", "STATE_FACED", faced, integer) +
         constant_array("int", "FACE_START", start, integer) + constant_array("int", "POINT_START", point_start, integer) +
         constant_array("double", "STATE_FACES", faces, real) + constant_array("double", "STATE_POINTS", points, real) +
         constant_array("double", "KEEP_RADIUS", a.noise->window_radius(), real);
}

}  // namespace

std::string opencl_prelude(const Abstraction& a, const Layout& layout, bool on_the_fly, std::size_t group_size) {
  const NoiseModel& noise = *a.noise;
  std::ostringstream s;
  s << "// Generated by amytiss from the validated configuration\n"
    << "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n"
    // Post states and windows must match the C++ reference bit for bit: no fused double math.
    << "#pragma OPENCL FP_CONTRACT OFF\n"
    << "#define STATE_DIMS " << a.states.dims() << "\n"
    << "#define INPUT_DIMS " << a.inputs.dims() << "\n"
    << "#define DIST_DIMS " << a.disturbances.dims() << "\n"
    << "#define N_STATES " << a.states.size() << "u\n"
    << "#define N_INPUTS " << a.inputs.size() << "u\n"
    << "#define N_DISTS " << a.disturbances.size() << "u\n"
    << "#define MASS_RECORD " << layout.mass_record << "\n"
    << "#define BOUNDS_CAPACITY " << (*std::max_element(layout.width.begin(), layout.width.end()) + 1 + 7) / 8 * 8 << "\n"
    << "#define MULTIPLICATIVE " << (noise.type() == NoiseType::Multiplicative ? 1 : 0) << "\n"
    << "#define UNIFORM " << (noise.distribution() == Distribution::Uniform ? 1 : 0) << "\n"
    << "#define TRUNCATION_NONE " << (a.config.noise.truncation == Truncation::None ? 1 : 0) << "\n"
    << "#define ON_THE_FLY " << (on_the_fly ? 1 : 0) << "\n"
    << "#define GROUP_SIZE " << group_size << "\n"
    << "#define ROLE_FREE " << unsigned(CellRole::Free) << "\n"
    << "#define ROLE_FIXED_ZERO " << unsigned(CellRole::FixedZero) << "\n"
    << "#define ROLE_FIXED_ONE " << unsigned(CellRole::FixedOne) << "\n";
  std::vector<long long> keep_half;
  for (std::int64_t h : noise.window_half_cells())
    keep_half.push_back(std::min<std::int64_t>(h, std::int64_t(1) << 40));
  auto real = [](double v) { return c_double_literal(v); };
  auto integer = [](long long v) { return int_text(v); };
  s << constant_array("double", "STATE_LB", a.states.lb(), real)
    << constant_array("double", "STATE_ETA", a.states.eta(), real)
    << constant_array("int", "STATE_COUNT", counts_of(a.states), integer)
    << constant_array("int", "HALF_CELLS", layout.half, integer)
    << constant_array("int", "WHOLE_DIM", layout.whole, integer)
    << constant_array("long", "KEEP_HALF", keep_half, integer)
    << constant_array("int", "WIDTH", layout.width, integer)
    << constant_array("int", "MASS_OFFSET", layout.mass_offset, integer)
    << constant_array("int", "PADDED_STRIDE", layout.padded_stride, integer)
    << constant_array("double", "INPUT_LB", a.inputs.lb(), real)
    << constant_array("double", "INPUT_ETA", a.inputs.eta(), real)
    << constant_array("int", "INPUT_COUNT", counts_of(a.inputs), integer)
    << constant_array("double", "DIST_LB", a.disturbances.lb(), real)
    << constant_array("double", "DIST_ETA", a.disturbances.eta(), real)
    << constant_array("int", "DIST_COUNT", counts_of(a.disturbances), integer)
    << constant_array("double", "NOISE_SCALE", noise.base_scale(), real);
  if (!a.states.all_uniform()) s << faced_prelude(a);
  return s.str();
}

std::string opencl_program_source(const Abstraction& a, bool on_the_fly, std::size_t group_size) {
  const Layout layout(a);
  return opencl_prelude(a, layout, on_the_fly, group_size) + contraction_source(layout, "contract_global", "__global") +
         contraction_source(layout, "contract_private", "") + a.dynamics->opencl_source() + "\n" +
         (a.states.all_uniform() ? std::string() : embedded_source("faced_states.cl")) + embedded_source("engine.cl");
}

}  // namespace amytiss::detail
