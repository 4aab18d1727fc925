// rostest: re-synthesis through the action with new parameters, hot swap, reuse, cancel, errors.
#include <atomic>
#include <thread>

#include <actionlib/client/simple_action_client.h>
#include <amytiss/GetInput.h>
#include <amytiss/SynthesizeAction.h>

#include "amytiss/policy_file.hpp"
#include "rostest_fixture.hpp"

namespace {

const std::string kSynthesizer = "/amytiss/synthesizer";
using amytiss_test::kActionWaitSeconds;
using amytiss_test::kSlowConfig;
using Client = actionlib::SimpleActionClient<amytiss::SynthesizeAction>;
using ResynthesisTest = amytiss_test::SynthesizerAndServerTest;
using amytiss_test::GoalOutcome;

TEST_F(ResynthesisTest, ChangedParametersSwapThePolicyWhileServingAndUnchangedOnesReuseTheFile) {
  const amytiss::PolicyStatus before = status_.latest();

  // Requests keep being answered, successfully, during the whole re-synthesis and swap.
  std::atomic<bool> stop{false};
  std::atomic<int> answered{0}, failed{0};
  std::string first_failure;  // written by the caller thread only, read after join()
  std::thread caller([&] {
    // One persistent connection for the whole loop (see rostest_fixture.hpp).
    ros::ServiceClient client = handle_.serviceClient<amytiss::GetInput>("/amytiss/get_input", /*persistent=*/true);
    while (!stop) {
      amytiss::GetInput service;
      service.request.state = {-4.0, -4.0};
      service.request.time_step = 0;
      const bool called = client.call(service);
      if (called && service.response.success) {
        ++answered;
      } else if (++failed == 1) {
        first_failure = called ? service.response.message : "the service call itself failed";
      }
    }
  });

  ros::param::set(kSynthesizer + "/spec/horizon", 9);
  XmlRpc::XmlRpcValue target_lb;
  target_lb.setSize(2);
  target_lb[0] = 2.0;
  target_lb[1] = 2.0;
  ros::param::set(kSynthesizer + "/spec/target/lb", target_lb);
  const GoalOutcome changed = run_goal_with_status(amytiss::SynthesizeGoal());
  EXPECT_TRUE(changed.result.success) << changed.result.message;
  EXPECT_FALSE(changed.result.reused);
  const amytiss::PolicyStatus after = changed.status;
  EXPECT_EQ(after.generation, before.generation + 1);
  EXPECT_EQ(after.syntheses_run, before.syntheses_run + 1);
  EXPECT_NE(after.config_hash, before.config_hash);
  EXPECT_EQ(after.horizon, 9u);

  // The server swaps to the new policy: step 9 becomes beyond the horizon, and answers equal the
  // new file's.
  ASSERT_TRUE(amytiss_test::poll_until([&] { return !call({-4.0, -4.0}, 9).success; }, amytiss_test::kPolicyWaitSeconds));
  const amytiss::LoadedPolicy fresh = amytiss::read_policy_file(after.policy_file);
  EXPECT_EQ(fresh.config_hash, after.config_hash);
  std::vector<double> expected(fresh.policy.inputs.dims());
  double probability = -1;
  const std::vector<double> state = {-3.0, -4.0};
  ASSERT_EQ(fresh.policy.lookup(state.data(), 2, 1, expected.data(), &probability), amytiss::LookupStatus::Ok);
  const amytiss::GetInput::Response response = call(state, 1);
  EXPECT_TRUE(response.success);
  EXPECT_EQ(response.input, expected);
  EXPECT_EQ(response.probability, probability);

  stop = true;
  caller.join();
  EXPECT_EQ(failed.load(), 0) << "first failure: " << first_failure;
  EXPECT_GT(answered.load(), 0);

  // Unchanged parameters: the file is reused, nothing is computed.
  const GoalOutcome unchanged = run_goal_with_status(amytiss::SynthesizeGoal());
  EXPECT_TRUE(unchanged.result.success) << unchanged.result.message;
  EXPECT_TRUE(unchanged.result.reused);
  EXPECT_NE(unchanged.result.message.find("reusing"), std::string::npos) << unchanged.result.message;
  EXPECT_EQ(unchanged.status.generation, after.generation + 1);
  EXPECT_EQ(unchanged.status.syntheses_run, after.syntheses_run);
  EXPECT_EQ(unchanged.status.phase, "reused");

  // force: computed again although the file is valid.
  amytiss::SynthesizeGoal forced;
  forced.force = true;
  const GoalOutcome recomputed = run_goal_with_status(forced);
  EXPECT_TRUE(recomputed.result.success);
  EXPECT_FALSE(recomputed.result.reused);
  EXPECT_EQ(recomputed.status.syntheses_run, after.syntheses_run + 1);
  EXPECT_NE(recomputed.status.run_id, after.run_id);
}

TEST_F(ResynthesisTest, ARunningSynthesisCanBeCancelledAndTheOldPolicyStays) {
  const amytiss::PolicyStatus before = status_.latest();
  const amytiss_test::StatusMark mark = status_.mark();
  std::atomic<int> feedbacks{0};
  amytiss::SynthesizeGoal goal;
  goal.config_yaml = kSlowConfig;
  goal.force = true;
  action_.sendGoal(goal, Client::SimpleDoneCallback(), Client::SimpleActiveCallback(),
                   [&](const amytiss::SynthesizeFeedbackConstPtr& feedback) {
                     if (feedback->phase == "synthesis") ++feedbacks;
                   });
  ASSERT_TRUE(amytiss_test::poll_until([&] { return feedbacks > 0; }, kActionWaitSeconds));
  action_.cancelGoal();
  ASSERT_TRUE(action_.waitForResult(ros::Duration(kActionWaitSeconds)));
  EXPECT_EQ(action_.getState(), actionlib::SimpleClientGoalState::PREEMPTED);
  EXPECT_FALSE(action_.getResult()->success);
  const auto cancelled = status_.wait_for_outcome(mark, action_.getResult()->message, amytiss_test::kPolicyWaitSeconds);
  ASSERT_TRUE(cancelled.has_value()) << action_.getResult()->message;
  const amytiss::PolicyStatus after = *cancelled;
  EXPECT_EQ(after.phase, "cancelled");
  EXPECT_FALSE(after.synthesizing);
  EXPECT_TRUE(after.ready);
  EXPECT_EQ(after.generation, before.generation);
  EXPECT_EQ(after.config_hash, before.config_hash);
  EXPECT_TRUE(call({-4.0, -4.0}, 0).success);
}

TEST_F(ResynthesisTest, ABadConfigurationIsReportedAndTheOldPolicyStays) {
  const amytiss::PolicyStatus before = status_.latest();
  amytiss::SynthesizeGoal goal;
  goal.config_yaml = std::string(kSlowConfig) + "\n";
  goal.config_yaml.replace(goal.config_yaml.find("horizon: 40"), 11, "horizon: 0");
  const GoalOutcome refused = run_goal_with_status(goal);
  EXPECT_FALSE(refused.result.success);
  EXPECT_NE(refused.result.message.find("horizon"), std::string::npos) << refused.result.message;
  EXPECT_EQ(refused.status.phase, "error");
  EXPECT_NE(refused.status.message.find("horizon"), std::string::npos);
  EXPECT_TRUE(refused.status.ready);
  EXPECT_EQ(refused.status.generation, before.generation);
  EXPECT_TRUE(call({-4.0, -4.0}, 0).success);
}

}  // namespace

int main(int argc, char** argv) { return amytiss_test::run_rostests(argc, argv, "amytiss_resynthesis_test", 3); }
