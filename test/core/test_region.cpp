// Specification sets given as unions of boxes (docs/configuration.md, docs/semantics.md): the
// cell roles of both guarantees, a one-dimensional chain computed by hand, and the reference and
// OpenCL engines against an independent dense recursion on two target and three avoid boxes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/engine.hpp"
#include "bounds/cell_roles.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using namespace test_support;
using detail::Bound;
using detail::robust_cell_roles;

// Values are stored in float on the OpenCL device (docs/engine.md bounds the error by
// horizon * (dims + 1) * 2^-24); the reference engine computes in double.
constexpr double kFloatTolerance = 1e-5;
constexpr double kDoubleTolerance = 1e-12;

Region region(std::vector<Box> boxes) { return Region(std::move(boxes)); }

SynthesisOptions cpu_options() {
  SynthesisOptions options;
  options.compute.device = DeviceKind::Cpu;
  return options;
}

// Membership by coordinates, written out here rather than through Grid::point_in_region.
bool contains(const std::vector<Box>& boxes, const std::vector<double>& point) {
  for (const Box& box : boxes) {
    bool inside = true;
    for (std::size_t d = 0; d < point.size(); ++d)
      inside = inside && point[d] >= box.lb[d] - 1e-9 && point[d] <= box.ub[d] + 1e-9;
    if (inside) return true;
  }
  return false;
}

TEST(RegionRoles, AbstractionCellIsInAUnionWhenItsPointIsInOneBox) {
  const Grid grid(grid_spec({0, 0}, {4, 4}, {1, 1}));
  const std::vector<Box> targets{box({0, 0}, {1, 1}), box({3, 3}, {4, 4})};
  const std::vector<Box> avoids{box({2, 0}, {2, 0}), box({0, 3}, {1, 4}), box({4, 0}, {4, 1})};
  const std::vector<CellRole> roles = cell_roles(grid, reach_avoid_spec(1, region(targets), region(avoids)));
  std::size_t fixed_one = 0, fixed_zero = 0;
  for (std::size_t cell = 0; cell < grid.size(); ++cell) {
    const std::vector<double> point = grid.point(cell);
    const CellRole expected = contains(avoids, point)    ? CellRole::FixedZero
                              : contains(targets, point) ? CellRole::FixedOne
                                                         : CellRole::Free;
    EXPECT_EQ(roles[cell], expected) << "cell " << cell;
    fixed_one += roles[cell] == CellRole::FixedOne;
    fixed_zero += roles[cell] == CellRole::FixedZero;
  }
  EXPECT_EQ(fixed_one, 4u + 4u);
  EXPECT_EQ(fixed_zero, 1u + 4u + 2u);

  const std::vector<CellRole> safety =
      cell_roles(grid, safety_spec(1, region({box({0, 0}, {1, 4}), box({3, 0}, {4, 0})})));
  EXPECT_EQ(std::count(safety.begin(), safety.end(), CellRole::Free), 10 + 2);
  EXPECT_EQ(safety[grid.flat_index(std::vector<std::size_t>{3, 0}.data())], CellRole::Free);
  EXPECT_EQ(safety[grid.flat_index(std::vector<std::size_t>{3, 1}.data())], CellRole::FixedZero);
}

// Cells of the points 0..8 (eta 1) are [k - 0.5, k + 0.5].
std::vector<CellRole> robust_roles(const SpecConfig& spec, Bound bound) {
  return robust_cell_roles(Grid(grid_spec({0}, {8}, {1})), spec, bound);
}

std::vector<std::size_t> cells_with(const std::vector<CellRole>& roles, CellRole role) {
  std::vector<std::size_t> cells;
  for (std::size_t cell = 0; cell < roles.size(); ++cell)
    if (roles[cell] == role) cells.push_back(cell);
  return cells;
}

using Cells = std::vector<std::size_t>;

TEST(RegionRoles, SystemLowerBoundNeedsTheCellInsideTheUnionUpperBoundAnyBoxMeetingIt) {
  // Target: cells 1, 2 inside the first box; cell 3 meets the second box but sticks out; cell 5
  // lies in the last two boxes together (in neither alone). Avoid: cell 7 meets [7.2, 7.4];
  // cell 6 lies in the union of the first two avoid boxes.
  const SpecConfig spec = reach_avoid_spec(
      1, region({box({0.5}, {2.5}), box({2.5}, {3.2}), box({4.5}, {5.0}), box({5.0}, {5.5})}),
      region({box({5.6}, {6.5}), box({5.5}, {6.0}), box({7.2}, {7.4})}));
  const std::vector<CellRole> lower = robust_roles(spec, Bound::Lower), upper = robust_roles(spec, Bound::Upper);
  EXPECT_EQ(cells_with(lower, CellRole::FixedOne), (Cells{1, 2, 5}));
  EXPECT_EQ(cells_with(upper, CellRole::FixedOne), (Cells{1, 2, 3, 5}));
  EXPECT_EQ(cells_with(lower, CellRole::FixedZero), (Cells{6, 7}));
  EXPECT_EQ(cells_with(upper, CellRole::FixedZero), (Cells{6}));

  // A gap between two boxes (wider than the face tolerance) leaves the cell outside the union.
  const SpecConfig gap = reach_avoid_spec(1, region({box({4.5}, {4.99}), box({5.0}, {5.5})}));
  EXPECT_EQ(cells_with(robust_roles(gap, Bound::Lower), CellRole::FixedOne), (Cells{}));
  EXPECT_EQ(cells_with(robust_roles(gap, Bound::Upper), CellRole::FixedOne), (Cells{5}));

  // Safety: lower keeps the cells inside the union, upper those meeting one of its boxes.
  const SpecConfig safety = safety_spec(1, region({box({-0.5}, {2.5}), box({2.5}, {3.0}), box({4.5}, {5.0})}));
  EXPECT_EQ(cells_with(robust_roles(safety, Bound::Lower), CellRole::Free), (Cells{0, 1, 2}));
  EXPECT_EQ(cells_with(robust_roles(safety, Bound::Upper), CellRole::Free), (Cells{0, 1, 2, 3, 5}));
}

TEST(RegionRoles, ACellCoveredByAnLShapeAndABoxIsInsideInEveryOrder) {
  // The cell of the point (0, 0) with eta 1 is [-0.5, 0.5]^2: a left half, a lower right and an
  // upper right quarter cover it; without the upper right quarter they do not.
  const Grid grid(grid_spec({0, 0}, {2, 2}, {1, 1}));
  std::vector<Box> pieces{box({-0.5, -0.5}, {0, 0.5}), box({0, -0.5}, {0.5, 0}), box({0, 0}, {0.5, 0.5})};
  for (int order = 0; order < 3; ++order) {
    std::rotate(pieces.begin(), pieces.begin() + 1, pieces.end());
    const std::vector<CellRole> whole =
        robust_cell_roles(grid, reach_avoid_spec(1, region(pieces)), Bound::Lower);
    EXPECT_EQ(cells_with(whole, CellRole::FixedOne), (Cells{0})) << "order " << order;
    const std::vector<Box> missing(pieces.begin(), pieces.begin() + 2);
    const std::vector<CellRole> part = robust_cell_roles(grid, reach_avoid_spec(1, region(missing)), Bound::Lower);
    EXPECT_EQ(cells_with(part, CellRole::FixedOne), (Cells{})) << "order " << order;
  }
}

// A chain x' = x + u + v on the points 0..8, u in {-1, 0, 1}, v uniform on [-1, 1]: from the post
// mean m the next cell is m with probability 1/2 and m -/+ 1 with 1/4 each. Targets {0, 1} and
// {7, 8}, avoid {3}, horizon 2.
const char* const kChain = R"(
name: chain_two_targets
states: {lb: [0], ub: [8], eta: [1]}
inputs: {lb: [-1], ub: [1], eta: [1]}
dynamics: ["x0 + u0"]
noise: {distribution: uniform, half_width: [1]}
spec:
  type: reach_avoid
  horizon: 2
  target: [{lb: [0], ub: [1]}, {lb: [7], ub: [8]}]
  avoid: {lb: [3], ub: [3]}
)";

TEST(RegionValues, OneDimensionalChainMatchesTheHandComputation) {
  // V_2: 1 on the targets, 0 elsewhere. V_1 (best input in brackets):
  //   x=2 (-1): 1/4*1 + 1/2*1 + 1/4*0 = 3/4;   x=4: every mean sees only 0s = 0;
  //   x=5 (+1): 1/4*0 + 1/2*0 + 1/4*1 = 1/4;   x=6 (+1): 1/4*0 + 1/2*1 + 1/4*1 = 3/4.
  // (Without the avoid cell, x=3 would reach 1/4 by -1.)
  const std::vector<double> v1{1, 1, 0.75, 0, 0, 0.25, 0.75, 1, 1};
  // V_0: x=2 (-1): 1/4*1 + 1/2*1 + 1/4*3/4; x=4 (+1): 1/4*0 + 1/2*1/4 + 1/4*3/4 (beats -1:
  // 1/4*3/4 + 1/2*0 + 1/4*0); x=5 (+1): 1/4*1/4 + 1/2*3/4 + 1/4*1; x=6 (+1): 1/4*3/4 + 1/2*1 + 1/4*1.
  const std::vector<double> v0{1, 1, 0.25 + 0.5 + 0.25 * 0.75, 0, 0.5 * 0.25 + 0.25 * 0.75,
                               0.25 * 0.25 + 0.5 * 0.75 + 0.25, 0.25 * 0.75 + 0.5 + 0.25, 1, 1};
  const std::vector<std::uint32_t> input0{0, 0, 0, 0, 2, 2, 2, 0, 0};  // index of u in {-1, 0, 1}; fixed cells: 0
  const Abstraction a = from_yaml(kChain);
  const Policy reference = synthesize_reference(a, {}, nullptr);
  const Policy opencl = synthesize(a, cpu_options());
  for (std::size_t cell = 0; cell < 9; ++cell) {
    EXPECT_NEAR(reference.value(0, cell), v0[cell], kDoubleTolerance) << "cell " << cell;
    EXPECT_NEAR(reference.value(1, cell), v1[cell], kDoubleTolerance) << "cell " << cell;
    EXPECT_NEAR(opencl.value(0, cell), v0[cell], kFloatTolerance) << "cell " << cell;
    EXPECT_NEAR(opencl.value(1, cell), v1[cell], kFloatTolerance) << "cell " << cell;
    if (a.roles[cell] == CellRole::Free) {
      EXPECT_EQ(reference.input(0, cell), input0[cell]) << "cell " << cell;
      EXPECT_EQ(opencl.input(0, cell), input0[cell]) << "cell " << cell;
    }
  }
}

// Two target boxes and three avoid boxes on a 2-d integrator with normal noise and nothing cut,
// so that every next cell carries mass.
const char* const kTwoTargetsThreeAvoids = R"(
name: two_targets_three_avoids
states: {lb: [-2, -2], ub: [2, 2], eta: [0.5, 0.5]}
inputs: {lb: [-0.5, -0.5], ub: [0.5, 0.5], eta: [0.5, 0.5]}
dynamics: ["0.9*x0 + u0", "0.9*x1 + u1"]
noise: {covariance: [0.2, 0.3]}
spec:
  type: reach_avoid
  horizon: 4
  target: [{lb: [1.5, 1.5], ub: [2, 2]}, {lb: [-2, 1], ub: [-1.5, 2]}]
  avoid: [{lb: [0, 0], ub: [0.5, 0.5]}, {lb: [-1, 1.5], ub: [-1, 2]}, {lb: [1, -2], ub: [2, -1]}]
)";

// The recursion written out densely: every input, every next cell, membership by coordinates.
std::vector<double> dense_values(const Abstraction& a, const std::vector<Box>& targets, const std::vector<Box>& avoids,
                                 unsigned horizon) {
  const std::size_t cells = a.states.size();
  std::vector<double> value(cells);
  auto role_value = [&](std::size_t cell, double free_value) {
    const std::vector<double> x = a.states.point(cell);
    if (contains(avoids, x)) return 0.0;
    if (contains(targets, x)) return 1.0;
    return free_value;
  };
  for (std::size_t cell = 0; cell < cells; ++cell) value[cell] = role_value(cell, 0.0);
  for (unsigned k = horizon; k-- > 0;) {
    std::vector<double> next(cells);
    for (std::size_t cell = 0; cell < cells; ++cell) {
      const std::vector<double> x = a.states.point(cell);
      double best = 0;
      for (std::size_t input = 0; input < a.inputs.size(); ++input) {
        const std::vector<double> u = a.inputs.point(input), w;
        std::vector<double> mean(2);
        a.dynamics->evaluate(x.data(), u.data(), w.data(), mean.data());
        double expected = 0;
        for (std::size_t target = 0; target < cells; ++target) {
          std::vector<std::size_t> multi(2);
          a.states.multi_index(target, multi.data());
          expected += a.noise->cell_mass(0, multi[0], mean[0], a.noise->scale(0, x.data())) *
                      a.noise->cell_mass(1, multi[1], mean[1], a.noise->scale(1, x.data())) * value[target];
        }
        best = std::max(best, expected);
      }
      next[cell] = role_value(cell, best);
    }
    value = std::move(next);
  }
  return value;
}

TEST(RegionValues, TwoTargetAndThreeAvoidBoxesMatchADenseRecursionOnBothEngines) {
  const Abstraction a = from_yaml(kTwoTargetsThreeAvoids);
  const std::vector<Box>& targets = a.config.spec.target->boxes;
  const std::vector<Box>& avoids = a.config.spec.avoid->boxes;
  ASSERT_EQ(targets.size(), 2u);
  ASSERT_EQ(avoids.size(), 3u);
  const std::vector<double> expected = dense_values(a, targets, avoids, a.horizon);
  const Policy reference = synthesize_reference(a, {}, nullptr);
  const Policy opencl = synthesize(a, cpu_options());
  double largest_free = 0;
  for (std::size_t cell = 0; cell < a.states.size(); ++cell) {
    EXPECT_NEAR(reference.value(0, cell), expected[cell], kDoubleTolerance) << "cell " << cell;
    EXPECT_NEAR(opencl.value(0, cell), expected[cell], kFloatTolerance) << "cell " << cell;
    if (a.roles[cell] == CellRole::Free) largest_free = std::max(largest_free, expected[cell]);
  }
  // Not a trivial problem: some free cell reaches a target with a fair probability.
  EXPECT_GT(largest_free, 0.5);
}

}  // namespace
}  // namespace amytiss
