// The footprint at its limits: a body far thinner or longer than the cells still avoids every cell
// where it may touch, the work of its test is estimated and bounded before it is done, and a long
// test of the cells can be cancelled.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/footprint.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using namespace test_support;

constexpr std::uint64_t kSeed = 20261202;
// Poses sampled per cell of the lane below.
constexpr int kPosesPerCell = 200;
// A cancelled setup ends within this: the footprint's loop polls every kPollSeconds.
constexpr double kCancelSeconds = 0.5;

// The lane of test_footprint.cpp: x = 0..10 (eta 1), one y cell [-0.5, 0.5], one yaw cell
// [-0.05, 0.05]; the obstacle x in [8, 9], y in [-0.2, 0.2].
Grid lane() { return Grid(grid_spec({0, 0, 0}, {10, 0, 0}, {1, 1, 0.1})); }

SpecConfig lane_spec(const Footprint& footprint) {
  SpecConfig spec = safety_spec(1);
  spec.obstacles = Region(box({8, -0.2}, {9, 0.2}));
  spec.footprint = footprint;
  return spec;
}

// Whether a body point (along its first `reach` m at most) at a sampled pose of the cell lies in
// the obstacle: such a cell must be avoided.
bool sampled_touch(const Footprint& footprint, std::size_t cell, double reach, std::mt19937_64& random) {
  auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
  const double front = std::min(footprint.length - footprint.rear_overhang, reach);
  for (int sample = 0; sample < kPosesPerCell; ++sample) {
    const double x = uniform(double(cell) - 0.5, double(cell) + 0.5), y = uniform(-0.5, 0.5);
    const double yaw = uniform(-0.05, 0.05);
    for (double along = -footprint.rear_overhang; along <= front; along += 0.05) {
      const double bx = x + along * std::cos(yaw), by = y + along * std::sin(yaw);
      if (bx >= 8 && bx <= 9 && by >= -0.2 && by <= 0.2) return true;
    }
  }
  return false;
}

std::vector<std::size_t> touched_cells(const Footprint& footprint) {
  const std::vector<bool> touched = obstacle_cells(lane(), lane_spec(footprint));
  std::vector<std::size_t> cells;
  for (std::size_t cell = 0; cell < touched.size(); ++cell)
    if (touched[cell]) cells.push_back(cell);
  return cells;
}

TEST(FootprintLimits, AThinBodyAvoidsTheCellsItMayTouch) {
  std::mt19937_64 random(kSeed);
  for (double width : {1e-3, 1e-20}) {
    const Footprint thin = car(4.0, width, 1.0);
    const std::vector<bool> touched = obstacle_cells(lane(), lane_spec(thin));
    for (std::size_t cell = 0; cell < touched.size(); ++cell)
      EXPECT_TRUE(touched[cell] || !sampled_touch(thin, cell, 100, random)) << "width " << width << " cell " << cell;
    // The centre line reaches 3 m ahead, 1 m behind: the cells x = 5..10, as for a 2 m wide body.
    EXPECT_EQ(touched_cells(thin), (std::vector<std::size_t>{5, 6, 7, 8, 9, 10})) << "width " << width;
  }
}

TEST(FootprintLimits, ALongBodyAvoidsTheCellsItMayTouch) {
  std::mt19937_64 random(kSeed);
  const Footprint long_body = car(1e20, 1.61, 0.0);
  const std::vector<bool> touched = obstacle_cells(lane(), lane_spec(long_body));
  for (std::size_t cell = 0; cell < touched.size(); ++cell)
    EXPECT_TRUE(touched[cell] || !sampled_touch(long_body, cell, 100, random)) << "cell " << cell;
  // Every cell behind the obstacle's far side; the cell x = 10 starts past it and looks ahead.
  EXPECT_EQ(touched_cells(long_body), (std::vector<std::size_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
}

TEST(FootprintLimits, BodyPiecesAreBoundedByTheCellsAndTheReach) {
  // Thinner than half the cell side: pieces of half the cell side (0.5 m) along 4 m.
  EXPECT_EQ(body_pieces(car(4.0, 1e-20, 1.0), grid_body_cut(grid_spec({0, 0, 0}, {10, 0, 0}, {1, 1, 0.1}),
                                                             lane_spec(car(4.0, 1e-20, 1.0))))
                .size(),
            16u);
  // Longer than the reach from the lane to the obstacle: cut at the reach.
  const BodyCut cut = grid_body_cut(grid_spec({0, 0, 0}, {10, 0, 0}, {1, 1, 0.1}), lane_spec(car(1e20, 1.61, 0)));
  EXPECT_LT(cut.front, 20.0);
  EXPECT_EQ(cut.rear, 0.0);
}

// 1000 x 1000 cells of 1 mm, one obstacle.
std::string fine_grid_yaml(double length, double width) {
  return "name: fine_footprint\n"
         "states: {lb: [0, 0, 0], ub: [0.999, 0.999, 0], eta: [0.001, 0.001, 0.1]}\n"
         "inputs: {lb: [-1], ub: [1], eta: [1]}\n"
         "dynamics: [\"x0 + 0.001*u0\", \"x1\", \"x2\"]\n"
         "noise: {covariance: [1e-6, 1e-6, 1e-4]}\n"
         "spec:\n  type: safety\n  horizon: 1\n  obstacles: {lb: [0.4, 0.4], ub: [0.5, 0.5]}\n"
         "  footprint: {pose: [0, 1, 2], length: " + format_number(length) + ", width: " + format_number(width) +
         ", rear_overhang: 1}\n";
}

TEST(FootprintLimits, WorkPastTheBudgetIsRefusedNamingTheKeyAndTheEstimate) {
  expect_error(YAML::Load(fine_grid_yaml(4.0, 0.01)), "spec.footprint.width", "6.8e+08 box tests (680 pieces of the body");
  expect_error(YAML::Load(fine_grid_yaml(4.0, 0.01)), "spec.footprint.width", "got 0.01");
  expect_error(YAML::Load(fine_grid_yaml(1e20, 1e-20)), "spec.footprint.length", "box tests");
  EXPECT_NO_THROW(config_from_yaml(YAML::Load(fine_grid_yaml(4.0, 1.0))));
}

TEST(FootprintLimits, ThePlanEstimatesTheFootprintsWork) {
  const Abstraction a = from_yaml(fine_grid_yaml(4.0, 1.0));
  SynthesisOptions options;
  options.compute.device = DeviceKind::Reference;
  const std::vector<std::string> lines = describe_synthesis(a, options);
  bool found = false;
  for (const std::string& line : lines) found = found || line.find("footprint: 8e+06 box tests (8 pieces") != std::string::npos;
  EXPECT_TRUE(found) << ::testing::PrintToString(lines);
}

// 100 x 100 x 5 cells, 160 pieces, 5 obstacles: 4e7 box tests, seconds of setup.
std::string cancel_yaml(const std::string& guarantee) {
  return "name: footprint_cancel\n"
         "states: {lb: [0, 0, -0.5], ub: [9.9, 9.9, 0.5], eta: [0.1, 0.1, 0.25]}\n"
         "inputs: {lb: [-1], ub: [1], eta: [1]}\n"
         "dynamics: [\"x0 + 0.1*u0*cos(x2)\", \"x1 + 0.1*u0*sin(x2)\", \"x2\"]\n"
         "noise: {covariance: [0.01, 0.01, 0.01]}\n"
         "spec:\n  type: safety\n  horizon: 2\n"
         "  obstacles: [{lb: [1, 1], ub: [1.5, 1.5]}, {lb: [3, 7], ub: [3.5, 7.5]}, {lb: [5, 5], ub: [5.5, 5.5]},\n"
         "              {lb: [7, 2], ub: [7.5, 2.5]}, {lb: [9, 9], ub: [9.5, 9.5]}]\n"
         "  footprint: {pose: [0, 1, 2], length: 4, width: 0.1, rear_overhang: 1}\n"
         "guarantee: " + guarantee + "\n";
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(FootprintLimits, CancelDuringTheBoundsSetupEndsSynthesizeQuickly) {
  const Abstraction a = from_yaml(cancel_yaml("system"));
  SynthesisOptions options;
  unsigned calls = 0;
  // The first progress (set-up reached) passes; any later one during the set-up cancels.
  options.progress = [&](const Progress&) { return ++calls == 1; };
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(synthesize(a, options), Cancelled);
  EXPECT_LT(seconds_since(start), kCancelSeconds);
  EXPECT_EQ(calls, 2u);
}

TEST(FootprintLimits, CancelDuringTheAbstractionsSetupEndsItQuickly) {
  const Config config = config_from_yaml(YAML::Load(cancel_yaml("abstraction")));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(Abstraction::from_config(config, [](const Progress&) { return false; }), Cancelled);
  EXPECT_LT(seconds_since(start), kCancelSeconds);
}

}  // namespace
}  // namespace amytiss
