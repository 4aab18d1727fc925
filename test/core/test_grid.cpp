#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "amytiss/errors.hpp"
#include "amytiss/grid.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using test_support::box;
using test_support::grid_spec;

constexpr double kCoordinateTolerance = 1e-12;

TEST(Grid, CountsFollowSpecFormula) {
  EXPECT_EQ(grid_count(-10, 10, 0.5), 41u);
  EXPECT_EQ(grid_count(-1, 1, 0.2), 11u);
  EXPECT_EQ(grid_count(-1, 1, 0.1), 21u);
  EXPECT_EQ(grid_count(0, 0, 1.0), 1u);
  // ub not on the lattice: rounds to the nearest count (the last point may pass ub by < eta/2).
  EXPECT_EQ(grid_count(0, 1, 0.4), 4u);    // floor(2.5 + .5) + 1: points 0, .4, .8, 1.2
  EXPECT_EQ(grid_count(0, 0.9, 0.4), 3u); // floor(2.25 + .5) + 1 = 3
}

TEST(Grid, CaseStudyGrids) {
  // Robot: X [-10,10]^2 eta .5; U [-1,1]^2 eta .2 and .1.
  EXPECT_EQ(Grid(grid_spec({-10, -10}, {10, 10}, {0.5, 0.5})).size(), 41u * 41u);
  EXPECT_EQ(Grid(grid_spec({-1, -1}, {1, 1}, {0.2, 0.2})).size(), 11u * 11u);
  EXPECT_EQ(Grid(grid_spec({-1, -1}, {1, 1}, {0.1, 0.1})).size(), 21u * 21u);
  // Robot reach-avoid pairs: 1681 * 441 = 741,321; safety: 1681 * 121 = 203,401.
  EXPECT_EQ(Grid(grid_spec({-10, -10}, {10, 10}, {0.5, 0.5})).size() *
                Grid(grid_spec({-1, -1}, {1, 1}, {0.1, 0.1})).size(),
            741321u);
  EXPECT_EQ(1681u * Grid(grid_spec({-1, -1}, {1, 1}, {0.2, 0.2})).size(), 203401u);
  // BMW 320i paper grid: counts 6,6,5,5,7,5,5 -> 157,500 states; U 5 x 5 -> 3,937,500 pairs.
  const Grid bmw(grid_spec({-10, -10, -0.4, -2, -0.3, -0.4, -0.04}, {10, 10, 0.4, 2, 0.3, 0.4, 0.04},
                           {4, 4, 0.2, 1, 0.1, 0.2, 0.02}));
  const std::vector<std::size_t> expected_bmw{6, 6, 5, 5, 7, 5, 5};
  EXPECT_EQ(bmw.counts(), expected_bmw);
  EXPECT_EQ(bmw.size(), 157500u);
  const Grid bmw_inputs(grid_spec({-0.4, -4}, {0.4, 4}, {0.2, 2}));
  EXPECT_EQ(bmw.size() * bmw_inputs.size(), 3937500u);
  EXPECT_NEAR(bmw.coordinate(0, 5), 10.0, kCoordinateTolerance);
  EXPECT_NEAR(bmw.coordinate(0, 2), -2.0, kCoordinateTolerance);
  // Room temperature 5d: X [19,21]^5 eta .4 -> 6^5; U [0,1]^2 eta .2 -> 36; pairs 279,936.
  const Grid room(grid_spec(std::vector<double>(5, 19), std::vector<double>(5, 21), std::vector<double>(5, 0.4)));
  EXPECT_EQ(room.size() * Grid(grid_spec({0, 0}, {1, 1}, {0.2, 0.2})).size(), 279936u);
  // Room temperature 3d: 6^3 * 36 = 7,776.
  EXPECT_EQ(Grid(grid_spec({19, 19, 19}, {21, 21, 21}, {0.4, 0.4, 0.4})).size() * 36u, 7776u);
  // Traffic 3d: X [0,8]^3 eta .1 -> 81^3; U {0,1}^2 -> 4; pairs 2,125,764.
  EXPECT_EQ(Grid(grid_spec({0, 0, 0}, {8, 8, 8}, {0.1, 0.1, 0.1})).size() *
                Grid(grid_spec({0, 0}, {1, 1}, {1, 1})).size(),
            2125764u);
  // Traffic 5d: X [0,10]^5 eta 10/27 -> 28^5 states, 4 inputs: 68,841,472 pairs.
  EXPECT_EQ(Grid(grid_spec(std::vector<double>(5, 0), std::vector<double>(5, 10),
                           std::vector<double>(5, 10.0 / 27.0)))
                    .size() *
                4u,
            68841472u);
}

TEST(Grid, PointsAreLbPlusKEta) {
  const Grid grid(grid_spec({-10, 0}, {10, 1}, {0.5, 0.25}));
  ASSERT_EQ(grid.counts(), (std::vector<std::size_t>{41, 5}));
  // Last dimension fastest: flat 1 is (k0 = 0, k1 = 1).
  const auto p1 = grid.point(1);
  EXPECT_NEAR(p1[0], -10.0, kCoordinateTolerance);
  EXPECT_NEAR(p1[1], 0.25, kCoordinateTolerance);
  const auto p5 = grid.point(5);
  EXPECT_NEAR(p5[0], -9.5, kCoordinateTolerance);
  EXPECT_NEAR(p5[1], 0.0, kCoordinateTolerance);
  const auto last = grid.last_point();
  EXPECT_NEAR(last[0], 10.0, kCoordinateTolerance);
  EXPECT_NEAR(last[1], 1.0, kCoordinateTolerance);
}

TEST(Grid, FlatMultiRoundTrip) {
  const Grid grid(grid_spec({0, 0, 0}, {3, 4, 2}, {1, 1, 1}));
  ASSERT_EQ(grid.size(), 4u * 5u * 3u);
  std::size_t multi[3];
  for (std::size_t flat = 0; flat < grid.size(); ++flat) {
    grid.multi_index(flat, multi);
    EXPECT_EQ(multi[0], flat / 15);
    EXPECT_EQ(multi[1], (flat / 3) % 5);
    EXPECT_EQ(multi[2], flat % 3);
    EXPECT_EQ(grid.flat_index(multi), flat);
    // The point of a flat index lies in its own cell.
    const auto point = grid.point(flat);
    ASSERT_TRUE(grid.cell_of(point.data()).has_value());
    EXPECT_EQ(*grid.cell_of(point.data()), flat);
  }
}

TEST(Grid, ZeroDimensionalGridHasOnePoint) {
  const Grid grid;
  EXPECT_EQ(grid.dims(), 0u);
  EXPECT_EQ(grid.size(), 1u);
  EXPECT_EQ(grid.point(0).size(), 0u);
  EXPECT_EQ(grid.flat_index(nullptr), 0u);
  ASSERT_TRUE(grid.cell_of(nullptr).has_value());
  EXPECT_EQ(*grid.cell_of(nullptr), 0u);
}

TEST(Grid, CellOfCoveredSetBoundaries) {
  const Grid grid(grid_spec({-10}, {10}, {0.5}));
  auto cell = [&](double value) { return grid.cell_of(&value); };
  EXPECT_EQ(cell(-10.25), std::optional<std::size_t>(0));
  EXPECT_EQ(cell(10.25), std::optional<std::size_t>(40));
  EXPECT_EQ(cell(0.1), std::optional<std::size_t>(20));
  EXPECT_EQ(cell(0.26), std::optional<std::size_t>(21));
  EXPECT_FALSE(cell(-10.2500001).has_value());
  EXPECT_FALSE(cell(10.2500001).has_value());
  EXPECT_FALSE(cell(1e300).has_value());
  EXPECT_FALSE(cell(-1e300).has_value());
  EXPECT_FALSE(cell(std::numeric_limits<double>::quiet_NaN()).has_value());
  EXPECT_FALSE(cell(std::numeric_limits<double>::infinity()).has_value());
  EXPECT_EQ(grid.nearest(0, -11.0), -2);
  EXPECT_EQ(grid.nearest(0, 11.0), 42);
}

TEST(Grid, PointInClosedBox) {
  const Grid grid(grid_spec({-10, -10}, {10, 10}, {0.5, 0.5}));
  const Box target = box({5, 5}, {7, 7});
  std::size_t inside = 0;
  for (std::size_t flat = 0; flat < grid.size(); ++flat) inside += grid.point_in_box(flat, target);
  EXPECT_EQ(inside, 25u);  // 5, 5.5, 6, 6.5, 7 in each dimension
  // Rounding error in the box bound is tolerated (1e-9 * eta).
  EXPECT_EQ([&] {
    std::size_t count = 0;
    const Box shifted = box({5 + 1e-12, 5}, {7 - 1e-12, 7});
    for (std::size_t flat = 0; flat < grid.size(); ++flat) count += grid.point_in_box(flat, shifted);
    return count;
  }(), 25u);
}

TEST(Grid, RejectsBadSpecs) {
  EXPECT_THROW(Grid(grid_spec({0}, {1}, {0})), std::logic_error);
  EXPECT_THROW(Grid(grid_spec({0}, {1}, {-0.5})), std::logic_error);
  EXPECT_THROW(Grid(grid_spec({1}, {0}, {0.5})), std::logic_error);
  EXPECT_THROW(Grid(grid_spec({0, 0}, {1}, {0.5})), std::logic_error);
  EXPECT_THROW(Grid(grid_spec({0}, {1e300}, {1e-300})), std::logic_error);
}

}  // namespace
}  // namespace amytiss
