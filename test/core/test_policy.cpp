#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "amytiss/engine.hpp"
#include "amytiss/policy.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using namespace test_support;

constexpr double kExact = 0.0;

// A hand-made policy on X = [-10, 10]^2 eta 0.5 (41 x 41), U = [-1, 1]^2 eta 0.5 (5 x 5), horizon 2:
// input index = (cell + step) % 25, value = cell / size at step 0.
Policy hand_policy() {
  Policy policy;
  policy.states = Grid(grid_spec({-10, -10}, {10, 10}, {0.5, 0.5}));
  policy.inputs = Grid(grid_spec({-1, -1}, {1, 1}, {0.5, 0.5}));
  policy.horizon = 2;
  const std::size_t cells = policy.states.size();
  policy.values.resize(3 * cells);
  policy.input_index.resize(2 * cells);
  policy.roles.assign(cells, CellRole::Free);
  for (std::size_t step = 0; step < 3; ++step)
    for (std::size_t cell = 0; cell < cells; ++cell) {
      policy.values[step * cells + cell] = double(cell) / double(cells) / double(step + 1);
      if (step < 2) policy.input_index[step * cells + cell] = std::uint32_t((cell + step) % 25);
    }
  return policy;
}

TEST(PolicyLookup, NearestCellInputAndProbability) {
  const Policy policy = hand_policy();
  const double state[2] = {-8.1, 7.26};  // nearest point (-8, 7.5): indices (4, 35)
  double input[2], probability = -1;
  ASSERT_EQ(policy.lookup(state, 2, 1, input, &probability), LookupStatus::Ok);
  const std::size_t cell = 4 * 41 + 35;
  const std::size_t input_index = (cell + 1) % 25;
  EXPECT_NEAR(input[0], -1 + 0.5 * double(input_index / 5), kExact);
  EXPECT_NEAR(input[1], -1 + 0.5 * double(input_index % 5), kExact);
  EXPECT_EQ(probability, policy.value(1, cell));
  // The covered set's outer faces belong to the grid.
  const double corner[2] = {-10.25, 10.25};
  EXPECT_EQ(policy.lookup(corner, 2, 0, input, &probability), LookupStatus::Ok);
}

TEST(PolicyLookup, WrongDimensionMessage) {
  const Policy policy = hand_policy();
  const double state[3] = {0, 0, 0};
  double input[2], probability;
  EXPECT_EQ(policy.lookup(state, 3, 0, input, &probability), LookupStatus::WrongDimension);
  EXPECT_EQ(policy.describe(LookupStatus::WrongDimension, state, 3, 0), "state has 3 values, expected 2 (x0, x1)");
  EXPECT_EQ(policy.lookup(state, 1, 0, input, &probability), LookupStatus::WrongDimension);
  EXPECT_EQ(policy.describe(LookupStatus::WrongDimension, state, 1, 0), "state has 1 value, expected 2 (x0, x1)");
}

TEST(PolicyLookup, NotFiniteMessage) {
  const Policy policy = hand_policy();
  double input[2], probability;
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    const double state[2] = {1.0, bad};
    EXPECT_EQ(policy.lookup(state, 2, 0, input, &probability), LookupStatus::NotFinite);
    const std::string message = policy.describe(LookupStatus::NotFinite, state, 2, 0);
    EXPECT_NE(message.find("not finite"), std::string::npos) << message;
    EXPECT_NE(message.find("x1 = "), std::string::npos) << message;
  }
}

TEST(PolicyLookup, OutsideGridMessage) {
  const Policy policy = hand_policy();
  const double state[2] = {12, 0};
  double input[2], probability;
  EXPECT_EQ(policy.lookup(state, 2, 0, input, &probability), LookupStatus::OutsideGrid);
  EXPECT_EQ(policy.describe(LookupStatus::OutsideGrid, state, 2, 0),
            "state [12, 0] is outside the grid [-10.25, 10.25] x [-10.25, 10.25] (x0 = 12 is not in [-10.25, 10.25])");
  const double just_outside[2] = {0, -10.2500001};
  EXPECT_EQ(policy.lookup(just_outside, 2, 0, input, &probability), LookupStatus::OutsideGrid);
}

TEST(PolicyLookup, StepBeyondHorizonMessage) {
  const Policy policy = hand_policy();
  const double state[2] = {0, 0};
  double input[2], probability;
  EXPECT_EQ(policy.lookup(state, 2, 2, input, &probability), LookupStatus::StepBeyondHorizon);
  EXPECT_EQ(policy.describe(LookupStatus::StepBeyondHorizon, state, 2, 2),
            "time_step 2 is beyond the horizon, expected 0 <= time_step < 2");
}

TEST(PolicyLookup, AutonomousPolicyHasEmptyInput) {
  auto dynamics = std::make_shared<LambdaDynamics>(1, 0, 0, [](const double* x, const double*, const double*, double* post) {
    post[0] = 0.8 * x[0];
  });
  const Policy policy = synthesize_reference(
      make_abstraction(make_config(grid_spec({-1}, {1}, {0.5}), std::nullopt, std::nullopt, normal_noise({0.1}),
                                   safety_spec(3), "autonomous"),
                       dynamics),
      nullptr);
  const double state = 0.3;
  double probability = -1;
  EXPECT_EQ(policy.lookup(&state, 1, 0, nullptr, &probability), LookupStatus::Ok);
  EXPECT_EQ(probability, policy.value(0, 3));
  EXPECT_GT(probability, 0.0);
}

TEST(PolicySummary, InitialValuesOverFreeCells) {
  Policy policy;
  policy.states = Grid(grid_spec({0}, {3}, {1}));
  policy.horizon = 1;
  policy.values = {0.2, 0.6, 1.0, 0.0, /* step 1 */ 1, 1, 1, 0};
  policy.input_index = {0, 0, 0, 0};
  policy.roles = {CellRole::Free, CellRole::Free, CellRole::FixedOne, CellRole::FixedZero};
  const ValueSummary summary = summarize_initial_values(policy);
  EXPECT_EQ(summary.free_cells, 2u);
  EXPECT_DOUBLE_EQ(summary.min, 0.2);
  EXPECT_DOUBLE_EQ(summary.max, 0.6);
  EXPECT_DOUBLE_EQ(summary.mean, 0.4);
  EXPECT_EQ(summary.cells_at_least_half, 1u);
}

// Continuous-system bounds: lower and upper bound of step 0 and their gap over the Free cells only.
TEST(PolicySummary, BoundsOverFreeCells) {
  Policy policy;
  policy.states = Grid(grid_spec({0}, {3}, {1}));
  policy.horizon = 1;
  policy.guarantee = Guarantee::System;
  policy.values = {0.2, 0.6, 1.0, 0.0, /* step 1 */ 1, 1, 1, 0};
  policy.upper_values = {0.5, 0.7, 1.0, 0.0, /* step 1 */ 1, 1, 1, 0};
  policy.input_index = {0, 0, 0, 0};
  policy.roles = {CellRole::Free, CellRole::Free, CellRole::FixedOne, CellRole::FixedZero};
  const BoundsSummary summary = summarize_bounds(policy);
  EXPECT_EQ(summary.free_cells, 2u);
  EXPECT_DOUBLE_EQ(summary.lower.min, 0.2);
  EXPECT_DOUBLE_EQ(summary.lower.mean, 0.4);
  EXPECT_DOUBLE_EQ(summary.lower.max, 0.6);
  EXPECT_DOUBLE_EQ(summary.upper.min, 0.5);
  EXPECT_DOUBLE_EQ(summary.upper.mean, 0.6);
  EXPECT_DOUBLE_EQ(summary.upper.max, 0.7);
  EXPECT_DOUBLE_EQ(summary.gap.min, 0.7 - 0.6);
  EXPECT_DOUBLE_EQ(summary.gap.mean, 0.2);
  EXPECT_DOUBLE_EQ(summary.gap.max, 0.5 - 0.2);

  // Without upper bounds the upper bound is the value and the gap 0.
  policy.guarantee = Guarantee::Abstraction;
  policy.upper_values.clear();
  const BoundsSummary exact = summarize_bounds(policy);
  EXPECT_DOUBLE_EQ(exact.upper.mean, exact.lower.mean);
  EXPECT_DOUBLE_EQ(exact.gap.max, 0.0);
}

}  // namespace
}  // namespace amytiss
