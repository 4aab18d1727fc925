#pragma once
// A rostest fixture for a launch with the synthesizer and the policy server in /amytiss: waits
// (bounded) for both and for a served policy, then offers GetInput calls and Synthesize goals.
#include <string>
#include <vector>

#include <actionlib/client/simple_action_client.h>
#include <amytiss_msgs/GetInput.h>
#include <amytiss_msgs/SynthesizeAction.h>

#include "rostest_support.hpp"

namespace amytiss_test {

constexpr double kActionWaitSeconds = 60.0;

class SynthesizerAndServerTest : public ::testing::Test {
 protected:
  /// The state every call() asks about (inside the tiny_reach_avoid grid).
  const std::vector<double> kState = {-4.0, -4.0};

  void SetUp() override {
    ASSERT_TRUE(ros::service::waitForService("/amytiss/get_input", ros::Duration(kServiceWaitSeconds)));
    client_ = handle_.serviceClient<amytiss_msgs::GetInput>("/amytiss/get_input");
    ASSERT_TRUE(action_.waitForServer(ros::Duration(kServiceWaitSeconds)));
    ASSERT_TRUE(status_.wait_for([](const amytiss_msgs::PolicyStatus& s) { return s.ready && !s.synthesizing; },
                                 kPolicyWaitSeconds))
        << status_.latest().message;
    ASSERT_TRUE(poll_until([&] { return call().success; }, kPolicyWaitSeconds));
  }
  /// GetInput for kState at step 0 (the call itself must succeed; the answer may say no).
  amytiss_msgs::GetInput::Response call() {
    amytiss_msgs::GetInput service;
    service.request.state = kState;
    service.request.time_step = 0;
    EXPECT_TRUE(client_.call(service));
    return service.response;
  }
  amytiss_msgs::SynthesizeResult run_goal(const amytiss_msgs::SynthesizeGoal& goal) {
    action_.sendGoal(goal);
    EXPECT_TRUE(action_.waitForResult(ros::Duration(kActionWaitSeconds)));
    return *action_.getResult();
  }

  ros::NodeHandle handle_;
  StatusWatcher status_{handle_};
  ros::ServiceClient client_;
  actionlib::SimpleActionClient<amytiss_msgs::SynthesizeAction> action_{"/amytiss/synthesize", true};
};

}  // namespace amytiss_test
