// Noise-free dimensions that move on the cells' lattice (bounds/lattice.hpp, docs/semantics.md
// "Noise-free dimensions on the lattice"):
// - a 1-d translation by whole cells (x + u, and the same step integrated by RK4 as the BMW's
//   steering angle) gets [1, 1] on its image cell (leave [1, 1] off the grid), and sampled states
//   of each cell land in that cell;
// - a 2-d system with a noisy dimension and a lattice dimension that the specification ignores
//   has the bounds of its noisy dimension alone (engine and oracle; bounded and unbounded);
// - a map that does not send each cell into one cell (1.5 x) keeps the spread over the cells its
//   mean box touches, the true cell always among them; lattice dimensions are decided one by one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "amytiss/enclosure.hpp"
#include "amytiss/engine.hpp"
#include "bounds/lattice.hpp"
#include "bounds/mean_box.hpp"
#include "bounds/row_bounds.hpp"
#include "robust_oracle.hpp"
#include "test_support.hpp"

namespace amytiss::detail {
namespace {

using namespace amytiss::test_support;

constexpr unsigned kSeed = 20261207;
constexpr int kSamplesPerRow = 200;
// The 2-d certificate is the 1-d one up to the O-maximisation's outward rounding per stage
// ((4K + 4) u per expectation, a few stages per step, 5 steps).
constexpr double kCertificateAgreement = 1e-12;
// Unbounded reachability: values below this (outside the target) are shaped by the noise and the
// grid's edges, not 1 by construction.
constexpr double kBelowOne = 0.99;

RowBounds all_rows(const Abstraction& a, const ImageEnclosure& enclosure) {
  return RowBounds(a.states, a.inputs, a.disturbances, *a.noise,
                   enclosure_mean_box(enclosure, a.states, a.inputs, a.disturbances),
                   std::vector<bool>(a.states.size(), true), 1, bounds_reads(a));
}

std::string one_dimension_yaml(const std::string& dynamics, const std::string& more = "") {
  return "name: lattice_1d\n"
         "states: {lb: [-0.6], ub: [0.6], eta: [0.2]}\n"
         "inputs: {lb: [-0.4], ub: [0.4], eta: [0.4]}\n"
         "dynamics: [\"" + dynamics + "\"]\n" + more +
         "noise: {type: additive, distribution: normal, covariance: [0]}\n"
         "spec: {type: safety, horizon: 3}\n";
}

// The grid index of a state coordinate the way the policy looks it up, or -1 / count off the grid.
std::int64_t cell_index(const Grid& grid, std::size_t dim, double value) {
  const std::int64_t k = grid.nearest(dim, value);
  return std::max<std::int64_t>(-1, std::min<std::int64_t>(k, std::int64_t(grid.count(dim))));
}

// Every row of dimension 0 is [1, 1] on the cell that sampled states of the cell go to.
void expect_point_masses_on_the_image(const Abstraction& a) {
  const ImageEnclosure enclosure(a.config);
  const RowBounds rows = all_rows(a, enclosure);
  ASSERT_TRUE(rows.lattice(0));
  std::mt19937_64 random(kSeed);
  const double eta = a.states.eta()[0];
  const auto count = std::int64_t(a.states.count(0));
  for (std::size_t cell = 0; cell < a.states.size(); ++cell)
    for (std::size_t u = 0; u < a.inputs.size(); ++u) {
      DimensionView view;
      rows.dimensions(rows.row(cell, u, 0), &view);
      std::uniform_real_distribution<double> inside(a.states.face(0, std::int64_t(cell)),
                                                    a.states.face(0, std::int64_t(cell) + 1));
      const std::vector<double> input = a.inputs.point(u);
      double post = 0, x = a.states.coordinate(0, cell);
      a.dynamics->evaluate(&x, input.data(), nullptr, &post);
      const std::int64_t target = cell_index(a.states, 0, post);
      if (target < 0 || target >= count) {
        EXPECT_EQ(view.count, 0u) << "cell " << cell << " input " << u;
        EXPECT_EQ(view.leave.lo, 1.0);
        EXPECT_EQ(view.leave.hi, 1.0);
      } else {
        ASSERT_EQ(view.count, 1u) << "cell " << cell << " input " << u;
        EXPECT_EQ(view.first, target);
        EXPECT_EQ(view.cells[0].lo, 1.0);
        EXPECT_EQ(view.cells[0].hi, 1.0);
        EXPECT_EQ(view.leave.hi, 0.0);
        EXPECT_EQ(view.cut.hi, 0.0);
      }
      for (int s = 0; s < kSamplesPerRow; ++s) {
        x = inside(random);
        a.dynamics->evaluate(&x, input.data(), nullptr, &post);
        EXPECT_EQ(cell_index(a.states, 0, post), target) << "x " << x << " eta " << eta;
      }
    }
}

TEST(LatticeBounds, ATranslationByWholeCellsIsAPointMassOnItsImage) {
  expect_point_masses_on_the_image(from_yaml(one_dimension_yaml("x0 + 0.5*u0")));
}

TEST(LatticeBounds, TheSteeringAngleStepOfRungeKuttaIsAPointMassOnItsImage) {
  // dx/dt = u0 over 0.5 s in two RK4 sub-steps: one cell of 0.2 per step at 0.4 rad/s, as the BMW's
  // steering angle (config/bmw_parking.yaml).
  expect_point_masses_on_the_image(
      from_yaml(one_dimension_yaml("u0", "integrator: {method: rk4, substeps: 2, tau: 0.5}\n")));
}

// x0' = 0.8 x0 + N(0, 0.01) must stay in [-0.5, 0.5]; x1' = x1 + u0 moves by a cell of 0.2 or
// stays, and the safe set holds all its cells.
std::string noisy_and_lattice_yaml() {
  return "name: noisy_and_lattice\n"
         "states: {lb: [-0.95, -0.6], ub: [0.95, 0.6], eta: [0.1, 0.2]}\n"
         "inputs: {lb: [-0.2], ub: [0.2], eta: [0.2]}\n"
         "dynamics: [\"0.8*x0\", \"x1 + u0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.01, 0]}\n"
         "spec: {type: safety, horizon: 5, safe: {lb: [-0.5, -0.7], ub: [0.5, 0.7]}}\n"
         "guarantee: system\n";
}

std::string noisy_alone_yaml() {
  return "name: noisy_alone\n"
         "states: {lb: [-0.95], ub: [0.95], eta: [0.1]}\n"
         "dynamics: [\"0.8*x0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.01]}\n"
         "spec: {type: safety, horizon: 5, safe: {lb: [-0.5], ub: [0.5]}}\n"
         "guarantee: system\n";
}

TEST(LatticeBounds, ALatticeDimensionTheSpecificationIgnoresCostsNothing) {
  const Abstraction both = from_yaml(noisy_and_lattice_yaml()), alone = from_yaml(noisy_alone_yaml());
  SynthesisReport report;
  const Policy engine = synthesize(both, SynthesisOptions{}, &report);
  const Policy single = synthesize(alone, SynthesisOptions{}, nullptr);
  const RobustValues oracle = robust_values_of(both, AmbiguitySet::Product);
  EXPECT_TRUE(has_note(report, "noise-free state dimension(s) 1 move on the cells' lattice"));
  double largest = 0, informative = 0;
  const std::size_t columns = both.states.count(1);
  for (std::size_t cell = 0; cell < both.states.size(); ++cell) {
    const std::size_t i = cell / columns;
    largest = std::max({largest, std::abs(engine.value(0, cell) - single.value(0, i)),
                        std::abs(engine.upper_value(0, cell) - single.upper_value(0, i)),
                        std::abs(oracle.lower[cell] - single.value(0, i))});
    informative = std::max(informative, single.value(0, i));
  }
  std::printf("[ figures  ] noisy + lattice dimension against the noisy one alone: max |difference| %.3e, "
              "largest 1-d lower bound %.4f\n",
              largest, informative);
  EXPECT_LE(largest, kCertificateAgreement);
  EXPECT_GT(informative, 0.5);  // the comparison is about informative bounds
}

TEST(LatticeBounds, ALatticeDimensionCostsNothingOverAnUnboundedHorizon) {
  // Reach [-0.15, 0.15] (cell faces) eventually: the interval iteration and the certification of
  // the stationary controller see the noisy dimension's bounds alone.
  auto unbounded = [](std::string yaml) {
    const std::string from = "spec: {type: safety, horizon: 5, safe: {lb: [-0.5";
    const std::size_t at = yaml.find(from);
    const std::size_t end = yaml.find('\n', at);
    const bool two = yaml.find("x1 + u0") != std::string::npos;
    return yaml.replace(at, end - at,
                        std::string("spec: {type: reach_avoid, horizon: infinite, target: {lb: [-0.15") +
                            (two ? ", -0.7" : "") + "], ub: [0.15" + (two ? ", 0.7" : "") + "]}}");
  };
  const Abstraction both = from_yaml(unbounded(noisy_and_lattice_yaml()));
  const Abstraction alone = from_yaml(unbounded(noisy_alone_yaml()));
  const Policy engine = synthesize(both, SynthesisOptions{}, nullptr);
  const Policy single = synthesize(alone, SynthesisOptions{}, nullptr);
  ASSERT_TRUE(engine.stationary);
  double largest = 0, informative = 0;
  const std::size_t columns = both.states.count(1);
  for (std::size_t cell = 0; cell < both.states.size(); ++cell) {
    const std::size_t i = cell / columns;
    largest = std::max({largest, std::abs(engine.value(0, cell) - single.value(0, i)),
                        std::abs(engine.upper_value(0, cell) - single.upper_value(0, i))});
    // Somewhere outside the target the value is neither 0 nor 1: the comparison is about values.
    const double v = single.value(0, i);
    if (std::abs(alone.states.coordinate(0, i)) > 0.2 && v < kBelowOne) informative = std::max(informative, v);
  }
  std::printf("[ figures  ] unbounded: noisy + lattice dimension against the noisy one alone: max |difference| "
              "%.3e, largest 1-d lower bound below %.4f outside the target %.4f\n",
              largest, kBelowOne, informative);
  EXPECT_LE(largest, kCertificateAgreement);
  EXPECT_GT(informative, 0.5);
}

TEST(LatticeBounds, AMapThatSpreadsACellKeepsTheSoundSpread) {
  const Abstraction a = from_yaml(
      "name: spread\n"
      "states: {lb: [-0.6, -0.6], ub: [0.6, 0.6], eta: [0.2, 0.2]}\n"
      "inputs: {lb: [-0.2], ub: [0.2], eta: [0.2]}\n"
      "dynamics: [\"x0 + u0\", \"1.5*x1\"]\n"
      "noise: {type: additive, distribution: normal, covariance: [0, 0]}\n"
      "spec: {type: safety, horizon: 2}\n");
  const ImageEnclosure enclosure(a.config);
  const RowBounds rows = all_rows(a, enclosure);
  EXPECT_TRUE(rows.lattice(0));   // decided per dimension
  EXPECT_FALSE(rows.lattice(1));
  std::mt19937_64 random(kSeed);
  std::size_t spread_rows = 0;
  const auto count = std::int64_t(a.states.count(1));
  for (std::size_t cell = 0; cell < a.states.size(); ++cell)
    for (std::size_t u = 0; u < a.inputs.size(); ++u) {
      DimensionView views[2];
      rows.dimensions(rows.row(cell, u, 0), views);
      const DimensionView& view = views[1];
      std::size_t possible = 0;
      for (std::size_t k = 0; k < view.count; ++k) possible += view.cells[k].hi == 1.0;
      spread_rows += possible >= 2;
      const std::int64_t k1 = std::int64_t(cell % a.states.count(1));
      std::uniform_real_distribution<double> inside(a.states.face(1, k1), a.states.face(1, k1 + 1));
      for (int s = 0; s < kSamplesPerRow; ++s) {
        const double x1 = inside(random), post = 1.5 * x1;
        const std::int64_t target = cell_index(a.states, 1, post);
        if (target < 0 || target >= count) {
          EXPECT_EQ(view.leave.hi, 1.0) << "x1 " << x1;
        } else {
          ASSERT_TRUE(target >= view.first && target < view.first + std::int64_t(view.count)) << "x1 " << x1;
          EXPECT_EQ(view.cells[target - view.first].hi, 1.0) << "x1 " << x1;
        }
      }
    }
  EXPECT_GT(spread_rows, 0u);
}

TEST(LatticeBounds, TheLossCountsTheOverhangAndTheShrinking) {
  const Grid grid(grid_spec({-0.6}, {0.6}, {0.2}));
  // The cell [0.1, 0.3] exactly, expanding by 1: no loss; sticking out by 1e-12: that loss.
  EXPECT_LE(lattice_loss(grid, 0, grid.face(0, 4), grid.face(0, 5), 1.0), 1e-16);
  EXPECT_NEAR(lattice_loss(grid, 0, grid.face(0, 4), grid.face(0, 5) + 1e-12, 1.0), 1e-12, 1e-15);
  // Contracting by 1/2 into the middle half of a cell loses nothing: 0.05 inside, 0.05 shrunk.
  EXPECT_NEAR(lattice_loss(grid, 0, 0.15, 0.25, 0.5), 0.0, 1e-15);
  // A constant map at the cell's middle loses what a state at the face gains: at most eta/2 - eta/2.
  EXPECT_NEAR(lattice_loss(grid, 0, 0.2, 0.2, 0.0), 0.0, 1e-15);
  EXPECT_FALSE(lattice_row(grid, 0, 0.15, 0.25, 0.0));
  // Beyond the grid's upper face: the half-line above it.
  EXPECT_TRUE(lattice_row(grid, 0, grid.face(0, 7), grid.face(0, 8), 1.0));
  EXPECT_TRUE(std::isinf(lattice_loss(grid, 0, 0.0, std::numeric_limits<double>::infinity(), 1.0)));
}

}  // namespace
}  // namespace amytiss::detail
