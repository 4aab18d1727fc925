#pragma once
// A rostest fixture for a launch with the synthesizer and the policy server in /amytiss: waits
// (bounded) for both and for a served policy, then offers GetInput calls and Synthesize goals.
#include <string>
#include <vector>

#include <actionlib/client/simple_action_client.h>
#include <amytiss/GetInput.h>
#include <amytiss/SynthesizeAction.h>

#include "rostest_support.hpp"

namespace amytiss_test {

constexpr double kActionWaitSeconds = 60.0;
// A configuration big enough (about 0.1 s per step on the reference engine, 40 steps) to be
// cancelled or killed while it runs.
constexpr const char* kSlowConfig = R"YAML(
name: slow_for_cancel
states:  {lb: [-5, -5], ub: [5, 5], eta: [0.125, 0.125]}
inputs:  {lb: [0, -3.2], ub: [1, 3.2], eta: [0.5, 0.4]}
dynamics: ["x0 + u0*cos(u1)", "x1 + u0*sin(u1)"]
noise: {type: additive, distribution: normal, covariance: [0.05, 0.05], truncation: cutting_probability, cutting_probability: 1.0e-4}
spec: {type: reach_avoid, horizon: 40, target: {lb: [3, 3], ub: [4.5, 4.5]}, avoid: {lb: [-1, -1], ub: [1, 1]}}
)YAML";

/// A goal's result and the status that reports it (the status topic and the action's result
/// arrive in either order: the latest status right after the result may still be an older one).
struct GoalOutcome {
  amytiss::SynthesizeResult result;
  amytiss::PolicyStatus status;
};

class SynthesizerAndServerTest : public ::testing::Test {
 protected:

  void SetUp() override {
    ASSERT_TRUE(ros::service::waitForService("/amytiss/get_input", ros::Duration(kServiceWaitSeconds)));
    // One persistent connection: a new TCP connection per call would leave a socket in TIME_WAIT
    // per call, and loops of calls can exhaust the ephemeral ports of a busy machine.
    client_ = handle_.serviceClient<amytiss::GetInput>("/amytiss/get_input", /*persistent=*/true);
    ASSERT_TRUE(action_.waitForServer(ros::Duration(kServiceWaitSeconds)));
    ASSERT_TRUE(status_.wait_for([](const amytiss::PolicyStatus& s) { return s.ready && !s.synthesizing; },
                                 kPolicyWaitSeconds))
        << status_.latest().message;
    ASSERT_TRUE(poll_until([&] { return call().success; }, kPolicyWaitSeconds));
  }
  /// GetInput (the call itself must succeed; the answer may say no). The default state lies in
  /// the tiny_reach_avoid grid.
  amytiss::GetInput::Response call(const std::vector<double>& state = {-4.0, -4.0}, unsigned step = 0) {
    amytiss::GetInput service;
    service.request.state = state;
    service.request.time_step = step;
    EXPECT_TRUE(client_.call(service));
    return service.response;
  }
  amytiss::SynthesizeResult run_goal(const amytiss::SynthesizeGoal& goal) {
    action_.sendGoal(goal);
    EXPECT_TRUE(action_.waitForResult(ros::Duration(kActionWaitSeconds)));
    return *action_.getResult();
  }
  GoalOutcome run_goal_with_status(const amytiss::SynthesizeGoal& goal) {
    const StatusMark before = status_.mark();
    GoalOutcome outcome;
    outcome.result = run_goal(goal);
    const auto status = status_.wait_for_outcome(before, outcome.result.message, kPolicyWaitSeconds);
    EXPECT_TRUE(status.has_value()) << "no status says: " << outcome.result.message.substr(0, 500);
    if (status) outcome.status = *status;
    return outcome;
  }

  ros::NodeHandle handle_;
  StatusWatcher status_{handle_};
  ros::ServiceClient client_;
  actionlib::SimpleActionClient<amytiss::SynthesizeAction> action_{"/amytiss/synthesize", true};
};

}  // namespace amytiss_test
