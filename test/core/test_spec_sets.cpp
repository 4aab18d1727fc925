// The specification's sets as a concrete state meets them (spec_sets.hpp): the body's exact
// rectangle against obstacle boxes (against a dense sampling of the body), closed boxes, unions,
// the order of the verdicts.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/spec_sets.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using test_support::box;
using test_support::car;

constexpr int kBodySamples = 120;   // per side of the body, for the sampled reference
constexpr double kSampleMargin = 0.1;  // m: boxes this far from or into the body decide the sampling

// Whether a sampled point of the body at `pose` lies in `obstacle` grown by `grow` (m, may be < 0).
bool sampled_touch(const Footprint& footprint, const double* pose, const Box& obstacle, double grow) {
  const double c = std::cos(pose[2]), s = std::sin(pose[2]);
  for (int i = 0; i <= kBodySamples; ++i) {
    const double along = -footprint.rear_overhang + footprint.length * i / kBodySamples;
    for (int j = 0; j <= kBodySamples; ++j) {
      const double across = footprint.width * (double(j) / kBodySamples - 0.5);
      const double x = pose[0] + along * c - across * s, y = pose[1] + along * s + across * c;
      if (x >= obstacle.lb[0] - grow && x <= obstacle.ub[0] + grow && y >= obstacle.lb[1] - grow &&
          y <= obstacle.ub[1] + grow)
        return true;
    }
  }
  return false;
}

TEST(SpecSets, BodyTouchesAgreesWithTheSampledBodyAwayFromContact) {
  const Footprint footprint = car(4.5, 1.6, 1.0);
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> place(-4, 4), size(0.2, 2), heading(-M_PI, M_PI);
  int touching = 0, apart = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const double pose[3] = {place(random), place(random), heading(random)};
    const double x = place(random), y = place(random);
    const Box obstacle = box({x, y}, {x + size(random), y + size(random)});
    const bool exact = body_touches(footprint, pose, Region(obstacle));
    // Deep inside: a sampled point lies in the shrunk box; clearly apart: none in the grown one.
    if (sampled_touch(footprint, pose, obstacle, -kSampleMargin)) {
      EXPECT_TRUE(exact) << "trial " << trial;
      ++touching;
    } else if (!sampled_touch(footprint, pose, obstacle, kSampleMargin)) {
      EXPECT_FALSE(exact) << "trial " << trial;
      ++apart;
    }
  }
  EXPECT_GT(touching, 40);
  EXPECT_GT(apart, 40);
}

// At 45 degrees the body's axis-aligned box reaches a corner the body itself does not.
TEST(SpecSets, AnObliqueBodyMissesTheCornerOfItsBoundingBox) {
  const Footprint footprint = car(4.0, 1.0, 0.0);
  const double pose[3] = {0.0, 0.0, M_PI / 4};
  EXPECT_FALSE(body_touches(footprint, pose, Region(box({2.4, 0.0}, {2.8, 0.3}))));
  EXPECT_TRUE(body_touches(footprint, pose, Region(box({1.3, 1.3}, {1.6, 1.6}))));
  // Contact counts: a box whose corner is the body's front corner.
  const double front_x = 4.0 * std::cos(M_PI / 4) + 0.5 * std::sin(M_PI / 4);
  const double front_y = 4.0 * std::sin(M_PI / 4) - 0.5 * std::cos(M_PI / 4);
  EXPECT_TRUE(body_touches(footprint, pose, Region(box({front_x, front_y - 1}, {front_x + 1, front_y}))));
  EXPECT_FALSE(body_touches(footprint, pose, Region(box({front_x + 1e-6, front_y - 1}, {front_x + 1, front_y}))));
}

Config grid_config(const std::string& spec) {
  return config_from_yaml(YAML::Load("name: sets\nstates: {lb: [0, 0], ub: [4, 4], eta: [1, 1]}\n"
                                     "dynamics: [\"x0\", \"x1\"]\n"
                                     "noise: {type: additive, distribution: normal, covariance: [1, 1]}\n"
                                     "spec: " + spec + "\n"));
}

TEST(SpecSets, ReachAvoidJudgesClosedBoxesUnionsAndTheCoveredBox) {
  const SpecSets sets(grid_config(
      "{type: reach_avoid, horizon: 3, target: [{lb: [3, 3], ub: [4, 4]}, {lb: [0, 3], ub: [1, 4]}], "
      "avoid: {lb: [1.5, 1.5], ub: [2.5, 2.5]}}"));
  auto judge = [&](double x, double y) {
    const double state[2] = {x, y};
    return sets.judge(state);
  };
  EXPECT_EQ(judge(3.5, 3.5), SetVerdict::Target);
  EXPECT_EQ(judge(0.5, 3.0), SetVerdict::Target) << "the second box of the union, on its face";
  EXPECT_EQ(judge(2.0, 3.0), SetVerdict::Undecided);
  EXPECT_EQ(judge(2.5, 1.5), SetVerdict::Avoid) << "a corner of the closed avoid box";
  EXPECT_EQ(judge(2.0, 2.6), SetVerdict::Undecided);
  EXPECT_EQ(judge(4.5, 4.0), SetVerdict::Undecided) << "the covered box reaches half a cell beyond ub";
  EXPECT_EQ(judge(4.51, 4.0), SetVerdict::OutsideGrid);
  EXPECT_EQ(judge(-0.6, 1.0), SetVerdict::OutsideGrid);
  EXPECT_EQ(judge(std::nan(""), 1.0), SetVerdict::OutsideGrid);
}

TEST(SpecSets, SafetyJudgesTheSafeSetAndObstaclesByTheBody) {
  SpecSets sets(grid_config("{type: safety, horizon: 3, safe: {lb: [0, 0], ub: [3, 4]}}"));
  const double inside[2] = {2.9, 1.0}, outside[2] = {3.1, 1.0};
  EXPECT_EQ(sets.judge(inside), SetVerdict::Undecided);
  EXPECT_EQ(sets.judge(outside), SetVerdict::Unsafe);
  Config with_obstacle = config_from_yaml(YAML::Load(
      "name: car\nstates: {lb: [0, 0, 0], ub: [8, 8, 3], eta: [0.5, 0.5, 0.5]}\n"
      "dynamics: [\"x0\", \"x1\", \"x2\"]\n"
      "noise: {type: additive, distribution: normal, covariance: [1, 1, 1]}\n"
      "spec: {type: safety, horizon: 3, obstacles: [{lb: [6, 0], ub: [7, 1]}],\n"
      "       footprint: {pose: [0, 1, 2], length: 4, width: 1, rear_overhang: 1}}\n"));
  const SpecSets car_sets(with_obstacle);
  const double towards[3] = {3.5, 0.5, 0.0}, away[3] = {3.5, 0.5, M_PI / 2};
  EXPECT_EQ(car_sets.judge(towards), SetVerdict::Obstacle) << "the front reaches x = 6.5";
  EXPECT_EQ(car_sets.judge(away), SetVerdict::Undecided);
}

}  // namespace
}  // namespace amytiss
