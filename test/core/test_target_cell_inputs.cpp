// The abstraction's controller in its target cells: the input a Free cell would get, not input
// 0, on every engine, bounded and unbounded.
#include <gtest/gtest.h>

#include <string>

#include "amytiss/abstraction.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/policy.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using test_support::from_yaml;

// A walk x+ = x + u + noise on the cells 0..9, u in {-1, 0, 1} (input indices 0, 1, 2), noise
// standard deviation 0.2, one fixed cell at each end: `left` ([-0.5, 0.5] or [-0.5, 1.5]) and
// `right`. Input 0 (u = -1) sends half the mass of cell 0 off the grid.
std::string walk(const std::string& horizon, const std::string& target, const std::string& avoid) {
  return "name: walk\n"
         "states: {lb: [0], ub: [9], eta: [1]}\n"
         "inputs: {lb: [-1], ub: [1], eta: [1]}\n"
         "dynamics: [\"x0 + u0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.04]}\n"
         "spec: {type: reach_avoid, horizon: " + horizon + ", target: " + target + ", avoid: " + avoid + "}\n";
}

const std::string kLeftCell = "{lb: [-0.5], ub: [0.5]}", kLeftPair = "{lb: [-0.5], ub: [1.5]}";
const std::string kRightCell = "{lb: [8.5], ub: [9.5]}", kRightPair = "{lb: [7.5], ub: [9.5]}";
constexpr std::size_t kLeftEnd = 0;
constexpr std::uint32_t kLeft = 0, kStay = 1, kRight = 2;  // u = -1, 0, 1

Policy synthesize_on(DeviceKind device, const Abstraction& abstraction) {
  SynthesisOptions options;
  options.compute.device = device;
  return synthesize(abstraction, options, nullptr);
}

// Target cells 0 and 1, avoid cell 9. From cell 0, u = 1 keeps all the mass on target or Free
// cells (cell 2, of positive value before the last step), u = 0 loses the tail below -0.5, u = -1
// half of it. At the last step cell 2 is worth 0: u = 0 and u = 1 tie, the lowest index wins.
TEST(TargetCellInputs, ATargetCellsInputKeepsTheStateOnTheGrid) {
  const Abstraction abstraction = from_yaml(walk("10", kLeftPair, kRightCell));
  ASSERT_EQ(abstraction.roles[kLeftEnd], CellRole::FixedOne);
  for (DeviceKind device : {DeviceKind::Reference, DeviceKind::Auto}) {
    const Policy policy = synthesize_on(device, abstraction);
    for (unsigned k = 0; k < policy.horizon; ++k) {
      EXPECT_EQ(policy.value(k, kLeftEnd), 1.0) << "step " << k;
      EXPECT_NE(policy.input(k, kLeftEnd), kLeft) << "step " << k;
    }
    for (unsigned k = 0; k + 2 <= policy.horizon; ++k) EXPECT_EQ(policy.input(k, kLeftEnd), kRight) << "step " << k;
    EXPECT_EQ(policy.input(policy.horizon - 1, kLeftEnd), kStay);
  }
}

TEST(TargetCellInputs, AStationaryPolicysToo) {
  const Policy policy = synthesize_on(DeviceKind::Reference, from_yaml(walk("infinite", kLeftPair, kRightCell)));
  ASSERT_TRUE(policy.stationary);
  EXPECT_EQ(policy.input(0, kLeftEnd), kRight);
}

// Avoid cells keep input 0: the abstraction counts them as failed whatever the input.
TEST(TargetCellInputs, AvoidCellsKeepInputZero) {
  const Policy policy = synthesize_on(DeviceKind::Reference, from_yaml(walk("10", kRightPair, kLeftCell)));
  for (unsigned k = 0; k < policy.horizon; ++k) EXPECT_EQ(policy.input(k, kLeftEnd), kLeft) << "step " << k;
}

}  // namespace
}  // namespace amytiss
