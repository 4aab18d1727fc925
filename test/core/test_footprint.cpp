// The car's footprint against obstacles (docs/semantics.md, "Obstacles and the footprint"): the
// footprint box holds the body at sampled poses of a cell, a case computed by hand, the cell roles
// of both guarantees, validation of the keys and the canonical text.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/footprint.hpp"
#include "bounds/cell_roles.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using namespace test_support;
using detail::Bound;
using detail::robust_cell_roles;

// A sampled body point is computed in double: it may sit a few ulps off the exact point the
// (outward rounded) box encloses.
constexpr double kSampleRounding = 1e-12;
// The hand-computed bounds below are sums of a few doubles.
constexpr double kHandTolerance = 1e-12;
constexpr std::uint64_t kSeed = 20261201;

TEST(FootprintBox, HoldsTheBodyAtSampledPosesOfTheCellAndSoDoThePieces) {
  std::mt19937_64 random(kSeed);
  auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
  for (int trial = 0; trial < 300; ++trial) {
    const double length = uniform(0.5, 6.0);
    const Footprint footprint = car(length, uniform(0.3, 3.0), uniform(0.0, 0.9 * length));
    const double x = uniform(-10, 10), y = uniform(-10, 10), yaw = uniform(-7, 7);
    const double hx = uniform(0.0, 1.0), hy = uniform(0.0, 1.0), hyaw = uniform(0.0, trial % 10 == 0 ? 4.0 : 0.8);
    const PlaneBox box = footprint_box(footprint, {x - hx, x + hx}, {y - hy, y + hy}, {yaw - hyaw, yaw + hyaw});
    std::vector<PlaneBox> piece_boxes;
    for (const BodyPiece& piece : body_pieces(footprint))
      piece_boxes.push_back(piece_box(piece, {x - hx, x + hx}, {y - hy, y + hy}, {yaw - hyaw, yaw + hyaw}));
    for (int sample = 0; sample < 200; ++sample) {
      const double px = uniform(x - hx, x + hx), py = uniform(y - hy, y + hy);
      const double heading = uniform(yaw - hyaw, yaw + hyaw);
      // A body point: a corner for the first samples, then anywhere on the rectangle.
      const double front = footprint.length - footprint.rear_overhang, half = 0.5 * footprint.width;
      const double along = sample < 4 ? (sample % 2 ? front : -footprint.rear_overhang)
                                      : uniform(-footprint.rear_overhang, front);
      const double across = sample < 4 ? (sample / 2 ? half : -half) : uniform(-half, half);
      const double bx = px + along * std::cos(heading) - across * std::sin(heading);
      const double by = py + along * std::sin(heading) + across * std::cos(heading);
      ASSERT_GE(bx, box.x.lo - kSampleRounding) << "trial " << trial << " sample " << sample;
      ASSERT_LE(bx, box.x.hi + kSampleRounding) << "trial " << trial << " sample " << sample;
      ASSERT_GE(by, box.y.lo - kSampleRounding) << "trial " << trial << " sample " << sample;
      ASSERT_LE(by, box.y.hi + kSampleRounding) << "trial " << trial << " sample " << sample;
      const bool in_a_piece = std::any_of(piece_boxes.begin(), piece_boxes.end(), [&](const PlaneBox& piece) {
        return bx >= piece.x.lo - kSampleRounding && bx <= piece.x.hi + kSampleRounding &&
               by >= piece.y.lo - kSampleRounding && by <= piece.y.hi + kSampleRounding;
      });
      ASSERT_TRUE(in_a_piece) << "trial " << trial << " sample " << sample;
    }
  }
}

TEST(FootprintBox, HeadingZeroAndNinetyDegreesByHand) {
  // Length 4 from 1 m behind the reference point, width 2: at heading 0 the body spans
  // x in [-1, 3], y in [-1, 1] around the reference point; at heading pi/2, x in [-1, 1], y in [-1, 3].
  const Footprint footprint = car(4.0, 2.0, 1.0);
  const PlaneBox east = footprint_box(footprint, {0, 1}, {0, 1}, Interval::point(0.0));
  EXPECT_NEAR(east.x.lo, -1.0, kHandTolerance);
  EXPECT_NEAR(east.x.hi, 4.0, kHandTolerance);
  EXPECT_NEAR(east.y.lo, -1.0, kHandTolerance);
  EXPECT_NEAR(east.y.hi, 2.0, kHandTolerance);
  const PlaneBox north = footprint_box(footprint, {0, 1}, {0, 1}, Interval::point(M_PI / 2));
  EXPECT_NEAR(north.x.lo, -1.0, kHandTolerance);
  EXPECT_NEAR(north.x.hi, 2.0, kHandTolerance);
  EXPECT_NEAR(north.y.lo, -1.0, kHandTolerance);
  EXPECT_NEAR(north.y.hi, 4.0, kHandTolerance);
  // An obstacle 0.1 m ahead of the front bumper is clear; one reaching 0.1 m into it is touched.
  EXPECT_FALSE(meets_obstacle(east, Region(box({4.1, 0}, {5, 1}))));
  EXPECT_TRUE(meets_obstacle(east, Region(box({3.9, 0}, {5, 1}))));
  EXPECT_TRUE(meets_obstacle(east, Region({box({-9, -9}, {-8, -8}), box({3.9, 1.9}, {5, 5})})));
}

TEST(FootprintBox, PiecesCoverTheBodyAndCutTheObliqueCorners) {
  // Length 4 from the reference point, width 2: 4 pieces along (side <= 1) times 2 across.
  const Footprint footprint = car(4.0, 2.0, 0.0);
  const std::vector<BodyPiece> pieces = body_pieces(footprint);
  ASSERT_EQ(pieces.size(), 8u);
  EXPECT_EQ(pieces.front().rear, 0.0);
  EXPECT_EQ(pieces.back().front, 4.0);
  // At 45 degrees the body lies along the diagonal y = x; its whole box reaches (3.54, -0.71), but
  // (3.3, -0.5) is 2.69 m from the diagonal, further than the half width of 1 m.
  const Interval origin = Interval::point(0.0), diagonal = Interval::point(M_PI / 4);
  const Region beside(box({3.2, -0.6}, {3.4, -0.4}));
  EXPECT_TRUE(meets_obstacle(footprint_box(footprint, origin, origin, diagonal), beside));
  EXPECT_FALSE(body_may_touch(pieces, origin, origin, diagonal, beside));
  EXPECT_TRUE(body_may_touch(pieces, origin, origin, diagonal, Region(box({1.9, 1.9}, {2.1, 2.1}))));
}

// States (x, y, yaw): x = 0..10 (eta 1), one y point 0 (cell [-0.5, 0.5]), one yaw point 0 (cell
// [-0.05, 0.05]). The body above reaches at most 3 cos(0) + 1 sin(0.05) < 3.05 m ahead of the
// reference point, so the cell of x = k reaches k + 0.5 + 3.05: the obstacle at x >= 8 is clear
// of the cells k <= 4 (0.45 m short) and met from k = 5 on (the rear, 1.55 m behind, stays left of x = 9).
const std::vector<std::size_t> kTouchedCells{5, 6, 7, 8, 9, 10};

SpecConfig with_obstacle(SpecConfig spec) {
  spec.obstacles = Region(box({8, -0.2}, {9, 0.2}));
  spec.footprint = car(4.0, 2.0, 1.0);
  return spec;
}

Grid lane() { return Grid(grid_spec({0, 0, 0}, {10, 0, 0}, {1, 1, 0.1})); }

std::vector<std::size_t> cells_with(const std::vector<CellRole>& roles, CellRole role) {
  std::vector<std::size_t> cells;
  for (std::size_t cell = 0; cell < roles.size(); ++cell)
    if (roles[cell] == role) cells.push_back(cell);
  return cells;
}

TEST(FootprintRoles, ObstacleCellsByHand) {
  const std::vector<bool> touched = obstacle_cells(lane(), with_obstacle(safety_spec(1)));
  for (std::size_t cell = 0; cell < touched.size(); ++cell)
    EXPECT_EQ(touched[cell], cell >= 5) << "cell " << cell;
  EXPECT_EQ(obstacle_cells(lane(), safety_spec(1)), std::vector<bool>(11, false));
}

TEST(FootprintRoles, AbstractionAvoidsEveryCellThatMayTouch) {
  const Grid grid = lane();
  EXPECT_EQ(cells_with(cell_roles(grid, with_obstacle(safety_spec(1))), CellRole::FixedZero), kTouchedCells);
  // Leaving `safe` (here x <= 3) and touching both make a cell FixedZero.
  EXPECT_EQ(cells_with(cell_roles(grid, with_obstacle(safety_spec(1, Region(box({0, 0, 0}, {3, 0, 0}))))),
                       CellRole::FixedZero),
            (std::vector<std::size_t>{4, 5, 6, 7, 8, 9, 10}));
  // reach_avoid: a touched cell is avoided even inside the target, like an `avoid` cell.
  const Region target({box({0, 0, 0}, {1, 0, 0}), box({6, 0, 0}, {6, 0, 0})});
  const SpecConfig reach = with_obstacle(reach_avoid_spec(1, target, Region(box({2, 0, 0}, {2, 0, 0}))));
  const std::vector<CellRole> roles = cell_roles(grid, reach);
  EXPECT_EQ(cells_with(roles, CellRole::FixedOne), (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(cells_with(roles, CellRole::FixedZero), (std::vector<std::size_t>{2, 5, 6, 7, 8, 9, 10}));
}

TEST(FootprintRoles, SystemLowerBoundAvoidsEveryCellThatMayTouchUpperBoundNone) {
  const Grid grid = lane();
  const SpecConfig safety = with_obstacle(safety_spec(1));
  EXPECT_EQ(cells_with(robust_cell_roles(grid, safety, Bound::Lower), CellRole::FixedZero), kTouchedCells);
  EXPECT_EQ(cells_with(robust_cell_roles(grid, safety, Bound::Upper), CellRole::FixedZero), std::vector<std::size_t>{});
  const SpecConfig reach = with_obstacle(reach_avoid_spec(1, Region(box({0, 0, 0}, {1, 0, 0}))));
  EXPECT_EQ(cells_with(robust_cell_roles(grid, reach, Bound::Lower), CellRole::FixedZero), kTouchedCells);
  EXPECT_EQ(cells_with(robust_cell_roles(grid, reach, Bound::Upper), CellRole::FixedZero), std::vector<std::size_t>{});
  EXPECT_EQ(cells_with(robust_cell_roles(grid, reach, Bound::Upper), CellRole::FixedOne),
            (std::vector<std::size_t>{0, 1}));
}

const char* const kCar = R"yaml(
name: car
states: {lb: [0, 0, -0.5], ub: [10, 4, 0.5], eta: [1, 1, 0.25]}
inputs: {lb: [-1, -0.5], ub: [1, 0.5], eta: [1, 0.5]}
dynamics: ["x0 + 0.5*u0*cos(x2)", "x1 + 0.5*u0*sin(x2)", "x2 + 0.5*u1"]
noise: {covariance: [0.1, 0.1, 0.01]}
spec:
  type: reach_avoid
  horizon: 4
  target: {lb: [0, 0, -0.5], ub: [1, 4, 0.5]}
  obstacles: [{lb: [8, 0], ub: [9, 1]}, {lb: [8, 3], ub: [9, 4]}]
  footprint: {pose: [0, 1, 2], length: 4.0, width: 2.0, rear_overhang: 1.0}
)yaml";


YAML::Node car_with(const std::string& key, const std::string& value) {
  YAML::Node root = YAML::Load(kCar);
  root["spec"]["footprint"][key] = YAML::Load(value);
  return root;
}

TEST(FootprintConfig, ValidConfigurationParses) {
  const Config config = config_from_yaml(YAML::Load(kCar));
  ASSERT_TRUE(config.spec.footprint && config.spec.obstacles);
  EXPECT_EQ(config.spec.footprint->pose, (std::vector<unsigned>{0, 1, 2}));
  EXPECT_EQ(config.spec.footprint->rear_overhang, 1.0);
  EXPECT_EQ(config.spec.obstacles->boxes.size(), 2u);
}

TEST(FootprintConfig, BadFootprintIsRefusedWithKeyValueAndExample) {
  expect_error(car_with("pose", "[0, 1, 3]"), "spec.footprint.pose[2]", "got 3");
  expect_error(car_with("pose", "[0, 1, 3]"), "spec.footprint.pose[2]", "footprint: {pose: [0, 1, 2]");
  expect_error(car_with("pose", "[0, 1, 1]"), "spec.footprint.pose[2]", "other than spec.footprint.pose[1]");
  expect_error(car_with("pose", "[0, 1]"), "spec.footprint.pose", "3 state indices");
  expect_error(car_with("pose", "[0, -1, 2]"), "spec.footprint.pose[1]",
               "got -1, expected a state index (an integer >= 0)");
  expect_error(car_with("length", "1.0"), "spec.footprint.length", "> spec.footprint.rear_overhang = 1");
  expect_error(car_with("rear_overhang", "-0.5"), "spec.footprint.rear_overhang", ">= 0");
  expect_error(car_with("width", "0"), "spec.footprint.width", "> 0");
  YAML::Node missing = YAML::Load(kCar);
  missing["spec"]["footprint"].remove("width");
  expect_error(missing, "spec.footprint.width", "width");
}

TEST(FootprintConfig, BadObstaclesAreRefused) {
  YAML::Node root = YAML::Load(kCar);
  root["spec"]["obstacles"] = YAML::Load("{lb: [8, 0, 0], ub: [9, 1, 0]}");
  expect_error(root, "spec.obstacles.lb", "2 values [x, y]");
  root["spec"]["obstacles"] = YAML::Load("[{lb: [8, 0], ub: [9, 1]}, {lb: [8, 3], ub: [7, 4]}]");
  expect_error(root, "spec.obstacles[1].ub[0]", "a number >= spec.obstacles[1].lb[0] = 8");
  root["spec"]["obstacles"] = YAML::Load("[]");
  expect_error(root, "spec.obstacles", "a non-empty list of boxes");
  YAML::Node alone = YAML::Load(kCar);
  alone["spec"].remove("footprint");
  expect_error(alone, "spec.footprint", "missing");
  alone = YAML::Load(kCar);
  alone["spec"].remove("obstacles");
  expect_error(alone, "spec.obstacles", "missing");
  YAML::Node reach = YAML::Load(kCar);
  reach["spec"]["type"] = "reachability";
  expect_error(reach, "spec.obstacles", "reach_avoid");
}

// Configurations without the keys keep their canonical text and hash.
TEST(FootprintConfig, CanonicalTextAndHash) {
  const Config plain = test_support::shipped_abstraction("robot_reach_avoid.yaml");
  EXPECT_EQ(to_yaml(plain).find("obstacles"), std::string::npos);
  EXPECT_EQ(to_yaml(plain).find("footprint"), std::string::npos);
  EXPECT_EQ(config_hash(plain), "de639acadc77740b");  // the hash this configuration has always had

  const Config config = config_from_yaml(YAML::Load(kCar));
  const std::string text = to_yaml(config);
  EXPECT_NE(text.find("\n  obstacles: [{lb: [8, 0], ub: [9, 1]}, {lb: [8, 3], ub: [9, 4]}]\n"
                      "  footprint: {pose: [0, 1, 2], length: 4, width: 2, rear_overhang: 1}\n"),
            std::string::npos)
      << text;
  const Config again = config_from_yaml(YAML::Load(text));
  EXPECT_EQ(to_yaml(again), text);
  Config wider = config;
  wider.spec.footprint->width = 2.1;
  EXPECT_NE(config_hash(wider), config_hash(config));
  Config moved = config;
  moved.spec.obstacles->boxes[1].lb[0] = 7.5;
  EXPECT_NE(config_hash(moved), config_hash(config));
}

}  // namespace
}  // namespace amytiss
