// The robust reference (bounds/cell_roles.hpp): on 1-d linear Gaussian systems the continuous
// value, computed independently by quadrature at 101 points per cell, lies between the lower and
// the upper bound; on 2-d and 3-d systems the orthogonal (product) bounds are at least as tight as
// the joint interval MDP's, and in 1-d they are equal.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "robust_oracle.hpp"
#include "bounds/cell_roles.hpp"
#include "test_support.hpp"

namespace amytiss::detail {
namespace {

using namespace amytiss::test_support;

// Composite Simpson on 100 intervals per cell of 0.1, for densities with sigma >= 0.1: error far
// below this.
constexpr double kQuadratureTolerance = 1e-8;
constexpr int kIntervalsPerCell = 100;
constexpr double kOrthogonalSlack = 1e-12;
// Cells of 0.1 against noise of 0.1 to 0.15: the interval MDP's gap stays below this, its lower
// bound reaches above the other.
constexpr double kInformativeGap = 0.75;
constexpr double kInformativeLower = 0.5;

// post = slope * x + drift + u (1-d; u = 0 without inputs), the mean box of a cell from its
// faces, rounded outward.
struct LinearSystem {
  double slope, drift, sigma;
  std::vector<double> inputs;  ///< the input grid's points (empty: autonomous)
  double input(std::size_t index) const { return inputs.empty() ? 0.0 : inputs[index]; }
  void box(double x_lo, double x_hi, std::size_t u, double* lo, double* hi) const {
    const double p = slope * x_lo + drift + input(u), q = slope * x_hi + drift + input(u);
    *lo = round_down(std::min(p, q), 3);
    *hi = round_up(std::max(p, q), 3);
  }
};

// The continuous value V_0 at the Simpson nodes of each cell (value[cell][j] at x = face + j h)
// under the cell-based controller (controller[k * cells + cell]; empty: input 0):
// V_T = terminal on Free points, 1 on the target, 0 on the avoid set and off the grid [-1, 1];
// V_k(x) = integral over the grid of N(y; slope x + drift + u, sigma^2) V_{k+1}(y) dy on Free points.
std::vector<std::vector<double>> continuous_value(const Grid& grid, const LinearSystem& system,
                                                  const std::vector<CellRole>& roles, double terminal,
                                                  unsigned horizon, const std::vector<std::uint32_t>& controller) {
  const std::size_t cells = grid.size();
  const double eta = grid.eta()[0], h = eta / kIntervalsPerCell;
  auto node = [&](std::size_t cell, int j) { return grid.coordinate(0, cell) - 0.5 * eta + j * h; };
  auto fixed = [&](std::size_t cell) { return roles[cell] == CellRole::FixedOne ? 1.0 : 0.0; };
  std::vector<std::vector<double>> value(cells, std::vector<double>(kIntervalsPerCell + 1));
  for (std::size_t c = 0; c < cells; ++c)
    for (double& v : value[c]) v = roles[c] == CellRole::Free ? terminal : fixed(c);
  for (unsigned k = horizon; k-- > 0;) {
    std::vector<std::vector<double>> next = value;
    for (std::size_t c = 0; c < cells; ++c) {
      if (roles[c] != CellRole::Free) continue;
      const double u = system.input(controller.empty() ? 0 : controller[std::size_t(k) * cells + c]);
      for (int i = 0; i <= kIntervalsPerCell; ++i) {
        const double mean = system.slope * node(c, i) + system.drift + u;
        double integral = 0;
        // Each cell integrated on its own (the value may jump at the faces of fixed cells).
        for (std::size_t t = 0; t < cells; ++t) {
          for (int j = 0; j <= kIntervalsPerCell; ++j) {
            const double weight = (j == 0 || j == kIntervalsPerCell) ? 1.0 : (j % 2 ? 4.0 : 2.0);
            const double z = (node(t, j) - mean) / system.sigma;
            integral += weight * std::exp(-0.5 * z * z) * value[t][j];
          }
        }
        next[c][i] = integral * h / 3.0 / (system.sigma * std::sqrt(2 * M_PI));
      }
    }
    value = std::move(next);
  }
  return value;
}

RobustValues robust_1d(const Grid& grid, const LinearSystem& system, const SpecConfig& spec, AmbiguitySet set,
                       const NoiseModel& noise) {
  const Grid none;
  const Grid inputs = system.inputs.empty()
                          ? Grid()
                          : Grid(grid_spec({system.inputs.front()}, {system.inputs.back()},
                                           {system.inputs[1] - system.inputs[0]}));
  RobustProblem problem{grid, inputs, none, noise, nullptr, spec.type, spec.horizon,
                        robust_cell_roles(grid, spec, Bound::Lower), robust_cell_roles(grid, spec, Bound::Upper)};
  problem.mean_box = [&](std::size_t cell, std::size_t u, std::size_t, double* lo, double* hi, double*) {
    const double centre = grid.coordinate(0, cell), half = 0.5 * grid.eta()[0];
    system.box(centre - half, centre + half, u, lo, hi);
  };
  return robust_values(problem, set);
}

// `fixed_region`: empty, no truncation; else the window the bounds use (the continuous system
// has none: the cut mass must count as the best value in the upper bound).
void expect_brackets_continuous_value(const SpecConfig& spec, const LinearSystem& system,
                                      std::vector<double> fixed_region = {}) {
  const Grid grid(grid_spec({-0.95}, {0.95}, {0.1}));  // cells cover [-1, 1]
  const Truncation truncation = fixed_region.empty() ? Truncation::None : Truncation::FixedRegion;
  const NoiseModel noise(normal_noise({system.sigma * system.sigma}, truncation, 1e-3, fixed_region), grid);
  const RobustValues bounds = robust_1d(grid, system, spec, AmbiguitySet::Joint, noise);
  // The sets are unions of cells: both bounds' roles agree with the continuous ones.
  const std::vector<CellRole> roles = cell_roles(grid, spec);
  ASSERT_EQ(roles, robust_cell_roles(grid, spec, Bound::Lower));
  ASSERT_EQ(roles, robust_cell_roles(grid, spec, Bound::Upper));
  const double terminal = spec.type == SpecType::Safety ? 1.0 : 0.0;
  const auto value = continuous_value(grid, system, roles, terminal, spec.horizon, bounds.controller);
  double widest = 0, best_lower = 0;
  for (std::size_t c = 0; c < grid.size(); ++c) {
    for (double v : value[c]) {
      EXPECT_LE(bounds.lower[c], v + kQuadratureTolerance) << "cell " << c;
      EXPECT_GE(bounds.upper[c], v - kQuadratureTolerance) << "cell " << c;
    }
    widest = std::max(widest, bounds.upper[c] - bounds.lower[c]);
    if (roles[c] == CellRole::Free) best_lower = std::max(best_lower, bounds.lower[c]);
  }
  // Informative bounds: never the trivial [0, 1], and a lower bound well above 0 somewhere.
  EXPECT_LT(widest, kInformativeGap);
  EXPECT_GT(best_lower, kInformativeLower);
}

TEST(RobustReference, SafetyBracketsTheContinuousValue) {
  expect_brackets_continuous_value(safety_spec(6), LinearSystem{0.8, 0.1, 0.15, {}});
}

TEST(RobustReference, ReachAvoidBracketsTheContinuousValue) {
  expect_brackets_continuous_value(reach_avoid_spec(6, box({0.4}, {0.8}), box({-0.5}, {-0.3})),
                                   LinearSystem{0.9, 0.12, 0.1, {}});
}

TEST(RobustReference, ControllerOfTheLowerBoundBracketsItsContinuousValue) {
  // The lower bound holds for the stored controller's continuous value, and the upper bound
  // for any controller's (here the same one).
  expect_brackets_continuous_value(reach_avoid_spec(5, box({0.4}, {0.8}), box({-0.5}, {-0.3})),
                                   LinearSystem{0.9, 0.0, 0.1, {-0.1, 0.0, 0.1}});
}

TEST(RobustReference, ControllerMaximisesTheLowerBound) {
  const Grid grid(grid_spec({-0.95}, {0.95}, {0.1}));
  const LinearSystem system{1.0, 0.0, 0.05, {-0.1, 0.0, 0.1}};
  const NoiseModel noise(normal_noise({system.sigma * system.sigma}), grid);
  const RobustValues bounds = robust_1d(grid, system, reach_avoid_spec(3, box({-0.2}, {0.2})), AmbiguitySet::Joint, noise);
  // Next to the target on either side the best input steps towards it.
  EXPECT_EQ(bounds.controller[grid.nearest(0, -0.25)], 2u);
  EXPECT_EQ(bounds.controller[grid.nearest(0, 0.25)], 0u);
}

TEST(RobustReference, TruncatedWindowsStillBracketTheContinuousValue) {
  // Windows of 5 cells (plus the box's spread) against a standard deviation of 1.5 cells.
  expect_brackets_continuous_value(reach_avoid_spec(4, box({0.4}, {0.8}), box({-0.5}, {-0.3})),
                                   LinearSystem{0.9, 0.12, 0.15, {}}, {0.25});
}

TEST(RobustReference, OneDimensionOrthogonalEqualsJoint) {
  const Grid grid(grid_spec({-0.95}, {0.95}, {0.1}));
  const LinearSystem system{0.9, 0.05, 0.2, {}};
  const NoiseModel noise(normal_noise({0.04}, Truncation::FixedRegion, 1e-3, {0.35}), grid);
  const SpecConfig spec = reach_avoid_spec(4, box({0.4}, {0.8}));
  const RobustValues joint = robust_1d(grid, system, spec, AmbiguitySet::Joint, noise);
  const RobustValues product = robust_1d(grid, system, spec, AmbiguitySet::Product, noise);
  EXPECT_EQ(joint.lower, product.lower);
  EXPECT_EQ(joint.upper, product.upper);
  EXPECT_EQ(joint.controller, product.controller);
}

// x' = A x + B u (+ noise), the mean box by interval arithmetic over the cell, rounded outward.
void compare_orthogonal_with_joint(const Grid& states, const Grid& inputs, const NoiseConfig& noise_config,
                                   const std::vector<double>& a, const SpecConfig& spec) {
  const std::size_t n = states.dims();
  const NoiseModel noise(noise_config, states);
  const Grid none;
  RobustProblem problem{states, inputs, none, noise, nullptr, spec.type, spec.horizon,
                        robust_cell_roles(states, spec, Bound::Lower), robust_cell_roles(states, spec, Bound::Upper)};
  problem.mean_box = [&](std::size_t cell, std::size_t input, std::size_t, double* lo, double* hi, double*) {
    const std::vector<double> centre = states.point(cell), u = inputs.point(input);
    for (std::size_t i = 0; i < n; ++i) {
      double low = i == 0 && !u.empty() ? u[0] : 0.0, high = low;
      for (std::size_t j = 0; j < n; ++j) {
        const double half = 0.5 * states.eta()[j];
        const double p = a[i * n + j] * (centre[j] - half), q = a[i * n + j] * (centre[j] + half);
        low += std::min(p, q);
        high += std::max(p, q);
      }
      lo[i] = round_down(low, 2 * int(n) + 2);
      hi[i] = round_up(high, 2 * int(n) + 2);
    }
  };
  const RobustValues joint = robust_values(problem, AmbiguitySet::Joint);
  const RobustValues product = robust_values(problem, AmbiguitySet::Product);
  bool tighter_somewhere = false;
  for (std::size_t c = 0; c < states.size(); ++c) {
    EXPECT_GE(product.lower[c], joint.lower[c] - kOrthogonalSlack) << "cell " << c;
    // With truncation the product set may value differently the mass one dimension cuts and
    // another sends off the grid: only the lower bounds compare then.
    if (noise_config.truncation == Truncation::None) {
      EXPECT_LE(product.upper[c], joint.upper[c] + kOrthogonalSlack) << "cell " << c;
    }
    EXPECT_LE(product.lower[c], product.upper[c]) << "cell " << c;
    tighter_somewhere = tighter_somewhere || product.lower[c] > joint.lower[c] + kOrthogonalSlack;
  }
  EXPECT_TRUE(tighter_somewhere);
}

TEST(RobustReference, TwoDimensionsOrthogonalAtLeastAsTightAsJoint) {
  compare_orthogonal_with_joint(Grid(grid_spec({-0.875, -0.875}, {0.875, 0.875}, {0.25, 0.25})),
                                Grid(grid_spec({-0.1}, {0.1}, {0.2})), normal_noise({0.04, 0.09}),
                                {0.8, 0.1, -0.1, 0.7}, reach_avoid_spec(3, box({0.0, 0.0}, {0.5, 0.5})));
}

TEST(RobustReference, ThreeDimensionsWithTruncationOrthogonalAtLeastAsTightAsJoint) {
  compare_orthogonal_with_joint(Grid(grid_spec({-0.8, -0.8, -0.8}, {0.8, 0.8, 0.8}, {0.4, 0.4, 0.4})), Grid(),
                                normal_noise({0.04, 0.04, 0.02}, Truncation::FixedRegion, 1e-3, {0.5, 0.5, 0.5}),
                                {0.7, 0.1, 0.0, 0.0, 0.6, 0.1, 0.1, 0.0, 0.5}, safety_spec(3));
}

}  // namespace
}  // namespace amytiss::detail
