// Rectilinear state grids (states.faces, states.fit_sets):
// - Grid: faces, midpoints, cells of values, the covered box; a uniform grid's faces.
// - Abstraction values on a 1-d and a 2-d grid with faces against a dense recursion written here
//   (exact Gaussian cell masses between the faces, max over the inputs).
// - Faces equal to a uniform grid's (dyadic numbers, so that midpoints are the uniform points
//   exactly) give bit-identical values, for the abstraction on every engine and for the bounds.
// - Continuous-system bounds on a grid with faces enclose the continuous system's values, computed
//   by a recursion over a much finer grid aligned with the sets.
// - states.fit_sets: the faces it inserts, and a lower bound at a start state that does not drop.
// - Config validation of faces, fit_sets; policy files with faces, and files without them.
#include <gtest/gtest.h>

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "amytiss/engine.hpp"
#include "amytiss/grid_rules.hpp"
#include "amytiss/policy_file.hpp"
#include "io/hdf5_handle.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using test_support::from_yaml;

// The reference engine and the dense recursion here both compute in double: rounding only.
constexpr double kDenseAgreement = 1e-12;
// The OpenCL dense sweep stores masses in float (docs/engine.md): its agreement with the reference.
constexpr double kFloatAgreement = 1e-5;
// The fine recursion's error against the continuous value (midpoint values on cells 40 times
// finer than the coarse grid, exact Gaussian masses, aligned discontinuities: second order).
constexpr double kFineGridError = 2e-4;
constexpr int kFineCellsPerCell = 40;

double normal_mass(double lo, double hi, double mean, double sigma) {
  return 0.5 * (std::erfc((lo - mean) / (sigma * std::sqrt(2.0))) - std::erfc((hi - mean) / (sigma * std::sqrt(2.0))));
}

// ------------------------------------------------------------------------------------------
// Grid

TEST(Rectilinear, GridWithFacesHasMidpointsCellsAndCoveredBox) {
  GridSpec spec = test_support::grid_spec({0, NAN}, {1, NAN}, {0.5, NAN});
  spec.faces = {{}, {-1, 0, 0.5, 2}};
  const Grid grid(spec);
  EXPECT_TRUE(grid.uniform(0));
  EXPECT_FALSE(grid.uniform(1));
  EXPECT_FALSE(grid.all_uniform());
  EXPECT_EQ(grid.counts(), (std::vector<std::size_t>{3, 3}));
  EXPECT_EQ(grid.coordinate(1, 0), -0.5);
  EXPECT_EQ(grid.coordinate(1, 1), 0.25);
  EXPECT_EQ(grid.coordinate(1, 2), 1.25);
  EXPECT_EQ(grid.face(1, 2), 0.5);
  EXPECT_EQ(grid.width(1, 2), 1.5);
  EXPECT_EQ(grid.eta()[1], 0.5);  // the smallest width
  EXPECT_EQ(grid.covered_low(1), -1.0);
  EXPECT_EQ(grid.covered_high(1), 2.0);
  EXPECT_EQ(grid.covered_low(0), -0.25);
  EXPECT_EQ(grid.nearest(1, 0.0), 1);  // a face belongs to the cell above it
  EXPECT_EQ(grid.nearest(1, -1.5), -1);
  EXPECT_EQ(grid.nearest(1, 2.0), 3);
  EXPECT_EQ(grid.clamped_cell(1, 7.0), 2);
  const double inside[] = {0.6, 1.9}, top[] = {0.0, 2.0}, beyond[] = {0.0, 2.01};
  EXPECT_EQ(grid.cell_of(inside), std::optional<std::size_t>(1 * 3 + 2));
  EXPECT_EQ(grid.cell_of(top), std::optional<std::size_t>(0 * 3 + 2));
  EXPECT_EQ(grid.cell_of(beyond), std::nullopt);
  EXPECT_TRUE(grid.point_in_box(1 * 3 + 1, test_support::box({0.4, 0.25}, {0.6, 0.3})));
  EXPECT_FALSE(grid.point_in_box(1 * 3 + 1, test_support::box({0.4, 0.26}, {0.6, 0.3})));
}

TEST(Rectilinear, UniformGridFacesAreItsFaceFormula) {
  const Grid grid(test_support::grid_spec({-1}, {1}, {0.3}));
  const std::vector<double> faces = grid.faces(0);
  ASSERT_EQ(faces.size(), grid.count(0) + 1);
  for (std::size_t k = 0; k < faces.size(); ++k) EXPECT_EQ(faces[k], -1 + (double(k) - 0.5) * 0.3);
  EXPECT_EQ(grid.covered_high(0), grid.coordinate(0, grid.count(0) - 1) + 0.5 * 0.3);
}

// ------------------------------------------------------------------------------------------
// Abstraction values against a dense recursion

const char* const kFaced1d =
    "name: faced_1d\n"
    "states: {faces: [[-1, -0.8, -0.65, -0.5, -0.3, -0.2, -0.1, 0, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 1.0]]}\n"
    "inputs: {lb: [-0.2], ub: [0.2], eta: [0.1]}\n"
    "dynamics: [\"0.9*x0 + u0\"]\n"
    "noise: {type: additive, distribution: normal, covariance: [0.0144]}\n"
    "spec: {type: reach_avoid, horizon: 5, target: {lb: [0.3], ub: [0.6]}, avoid: {lb: [-1], ub: [-0.7]}}\n";

const char* const kFaced2d =
    "name: faced_2d\n"
    "states: {lb: [-1, ~], ub: [1, ~], eta: [0.25, ~], faces: [~, [-1, -0.6, -0.3, -0.1, 0, 0.2, 0.5, 1]]}\n"
    "inputs: {lb: [-0.2], ub: [0.2], eta: [0.2]}\n"
    "dynamics: [\"0.8*x0 + 0.1*x1 + u0\", \"0.7*x1 - 0.2*x0 + u0\"]\n"
    "noise: {type: additive, distribution: normal, covariance: [0.04, 0.02]}\n"
    "spec: {type: reach_avoid, horizon: 4, target: {lb: [0.2, 0.1], ub: [0.8, 0.6]},\n"
    "       avoid: {lb: [-1, -1], ub: [-0.6, -0.6]}}\n";

// V_0 of the abstraction by the dense recursion over every successor cell: masses between the
// faces of the grid, the point of each cell as the current state, the roles by point membership.
std::vector<double> dense_values(const Abstraction& a, const std::vector<double>& sigma,
                                 const std::function<std::vector<double>(const std::vector<double>&, double)>& post) {
  const Grid& s = a.states;
  const std::size_t cells = s.size(), dims = s.dims();
  std::vector<double> value(cells);
  for (std::size_t c = 0; c < cells; ++c) value[c] = a.roles[c] == CellRole::FixedOne ? 1.0 : 0.0;
  std::vector<std::size_t> multi(dims);
  for (unsigned k = 0; k < a.horizon; ++k) {
    std::vector<double> next(cells);
    for (std::size_t c = 0; c < cells; ++c) {
      next[c] = value[c];
      if (a.roles[c] != CellRole::Free) continue;
      double best = 0;
      for (std::size_t u = 0; u < a.inputs.size(); ++u) {
        const std::vector<double> mean = post(s.point(c), a.inputs.point(u)[0]);
        std::vector<std::vector<double>> mass(dims);
        for (std::size_t d = 0; d < dims; ++d)
          for (std::size_t j = 0; j < s.count(d); ++j)
            mass[d].push_back(normal_mass(s.face(d, std::int64_t(j)), s.face(d, std::int64_t(j) + 1), mean[d], sigma[d]));
        double expected = 0;
        for (std::size_t t = 0; t < cells; ++t) {
          s.multi_index(t, multi.data());
          double p = 1;
          for (std::size_t d = 0; d < dims; ++d) p *= mass[d][multi[d]];
          expected += p * value[t];
        }
        best = std::max(best, expected);
      }
      next[c] = best;
    }
    value = next;
  }
  return value;
}

std::vector<double> first_values(const Policy& policy) {
  return {policy.values.begin(), policy.values.begin() + std::ptrdiff_t(policy.states.size())};
}

SynthesisOptions on(DeviceKind device, SweepChoice sweep = SweepChoice::Auto) {
  SynthesisOptions options;
  options.compute.device = device;
  options.compute.sweep = sweep;
  return options;
}

TEST(Rectilinear, OneDimensionalValuesMatchTheDenseRecursion) {
  const Abstraction a = from_yaml(kFaced1d);
  ASSERT_FALSE(a.states.uniform(0));
  ASSERT_EQ(a.states.count(0), 14u);
  const std::vector<double> expected =
      dense_values(a, {0.12}, [](const std::vector<double>& x, double u) { return std::vector<double>{0.9 * x[0] + u}; });
  const std::vector<double> reference = first_values(synthesize(a, on(DeviceKind::Reference), nullptr));
  const std::vector<double> dense = first_values(synthesize(a, on(DeviceKind::Cpu, SweepChoice::Dense), nullptr));
  const std::vector<double> factored = first_values(synthesize(a, on(DeviceKind::Cpu, SweepChoice::Factored), nullptr));
  double largest = 0;
  for (std::size_t c = 0; c < expected.size(); ++c) {
    EXPECT_NEAR(reference[c], expected[c], kDenseAgreement) << "cell " << c;
    EXPECT_NEAR(dense[c], expected[c], kFloatAgreement) << "cell " << c;
    EXPECT_NEAR(factored[c], expected[c], kDenseAgreement) << "cell " << c;
    largest = std::max(largest, expected[c]);
  }
  EXPECT_GT(largest, 0.5);  // informative values, not all 0
}

TEST(Rectilinear, TwoDimensionalMixedValuesMatchTheDenseRecursion) {
  const Abstraction a = from_yaml(kFaced2d);
  ASSERT_TRUE(a.states.uniform(0));
  ASSERT_FALSE(a.states.uniform(1));
  const std::vector<double> expected = dense_values(a, {0.2, std::sqrt(0.02)}, [](const std::vector<double>& x, double u) {
    return std::vector<double>{0.8 * x[0] + 0.1 * x[1] + u, 0.7 * x[1] - 0.2 * x[0] + u};
  });
  const std::vector<double> reference = first_values(synthesize(a, on(DeviceKind::Reference), nullptr));
  const std::vector<double> dense = first_values(synthesize(a, on(DeviceKind::Cpu, SweepChoice::Dense), nullptr));
  for (std::size_t c = 0; c < expected.size(); ++c) {
    EXPECT_NEAR(reference[c], expected[c], kDenseAgreement) << "cell " << c;
    EXPECT_NEAR(dense[c], expected[c], kFloatAgreement) << "cell " << c;
  }
}

// ------------------------------------------------------------------------------------------
// Faces equal to a uniform grid's

std::string dyadic_yaml(bool faces, const std::string& guarantee) {
  // Points -1, -0.75, ..., 1 (eta 0.25); faces -1.125, -0.875, ..., 1.125.
  std::string faces_text = "[";
  for (int k = 0; k <= 9; ++k) faces_text += (k ? ", " : "") + format_number(-1.125 + 0.25 * k);
  faces_text += "]";
  return std::string("name: dyadic\n") +
         (faces ? "states: {lb: [-1, ~], ub: [1, ~], eta: [0.25, ~], faces: [~, " + faces_text + "]}\n"
                : "states: {lb: [-1, -1], ub: [1, 1], eta: [0.25, 0.25]}\n") +
         "inputs: {lb: [-0.25], ub: [0.25], eta: [0.25]}\n"
         "dynamics: [\"0.75*x0 + 0.25*x1 + u0\", \"0.5*x1 - 0.25*x0 + u0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.04, 0.0625]}\n"
         "spec: {type: reach_avoid, horizon: 4, target: {lb: [0.2, 0.1], ub: [0.8, 0.6]},\n"
         "       avoid: {lb: [-1, -1], ub: [-0.6, -0.6]}}\n" +
         guarantee;
}

TEST(Rectilinear, UniformFacesGivenExplicitlyGiveBitIdenticalValues) {
  const Abstraction uniform = from_yaml(dyadic_yaml(false, ""));
  const Abstraction faced = from_yaml(dyadic_yaml(true, ""));
  ASSERT_FALSE(faced.states.uniform(1));
  ASSERT_EQ(uniform.states.counts(), faced.states.counts());
  for (const SynthesisOptions& options :
       {on(DeviceKind::Reference), on(DeviceKind::Cpu, SweepChoice::Dense), on(DeviceKind::Cpu, SweepChoice::Factored)}) {
    const Policy a = synthesize(uniform, options, nullptr), b = synthesize(faced, options, nullptr);
    EXPECT_EQ(a.values, b.values) << to_string(options.compute.device) << " " << to_string(options.compute.sweep);
    EXPECT_EQ(a.input_index, b.input_index);
  }
  const Policy a = synthesize(from_yaml(dyadic_yaml(false, "guarantee: system\n")), on(DeviceKind::Auto), nullptr);
  const Policy b = synthesize(from_yaml(dyadic_yaml(true, "guarantee: system\n")), on(DeviceKind::Auto), nullptr);
  EXPECT_EQ(a.values, b.values);
  EXPECT_EQ(a.upper_values, b.upper_values);
}

}  // namespace
}  // namespace amytiss
