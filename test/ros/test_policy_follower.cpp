// Which policy the server loads from the synthesizer's statuses, and how a refused file heals:
// retried after the retry period, and the synthesizer asked once per refusal to compute it again.
// A file that holds another policy than the announced one is refused, and a policy no status
// announced (~policy_file at start) is no longer served then.
#include <gtest/gtest.h>

#include "policy_follower.hpp"

namespace {

constexpr double kRetryPeriod = 5.0;
constexpr double kStart = 1764162300.0;  // 2025-11-26 13:05:00 UTC

amytiss::PolicyStatus ready_status(const std::string& run_id) {
  amytiss::PolicyStatus status;
  status.ready = true;
  status.config_hash = "0123456789abcdef";
  status.run_id = run_id;
  status.policy_file = "/tmp/robot.h5";
  return status;
}

TEST(PolicyFollower, LoadsEachAnnouncedPolicyOnce) {
  amytiss_ros::PolicyFollower follower(kRetryPeriod);
  amytiss::PolicyStatus status = ready_status("00000000000000a1");
  status.ready = false;
  EXPECT_FALSE(follower.on_status(status, kStart)) << "nothing ready yet";
  status.ready = true;
  const auto job = follower.on_status(status, kStart);
  ASSERT_TRUE(job);
  EXPECT_EQ(job->path, "/tmp/robot.h5");
  EXPECT_FALSE(follower.on_status(status, kStart + 0.1)) << "the heartbeat while loading starts no second load";
  follower.loaded(job->identity);
  EXPECT_FALSE(follower.on_status(status, kStart + 1)) << "the served policy is not loaded again";
  EXPECT_TRUE(follower.on_status(ready_status("00000000000000a2"), kStart + 2)) << "a new run is followed";
  EXPECT_EQ("", follower.refusal_notice());
}

TEST(PolicyFollower, ARefusedFileIsRetriedAfterThePeriodAndRecomputedOncePerRefusal) {
  amytiss_ros::PolicyFollower follower(kRetryPeriod);
  const amytiss::PolicyStatus status = ready_status("00000000000000b1");
  const auto job = follower.on_status(status, kStart);
  ASSERT_TRUE(job);
  follower.refused(*job, "checksum mismatch in /values", kStart);
  EXPECT_NE(follower.refusal_notice().find("policy file /tmp/robot.h5 refused (checksum mismatch in /values)"),
            std::string::npos)
      << follower.refusal_notice();
  EXPECT_TRUE(follower.take_synthesis_request(status));
  EXPECT_FALSE(follower.take_synthesis_request(status)) << "one request per refusal";
  EXPECT_NE(follower.refusal_notice().find("asked the synthesizer to compute it again"), std::string::npos);

  EXPECT_FALSE(follower.on_status(status, kStart + kRetryPeriod / 2)) << "no retry before the period";
  const auto retry = follower.on_status(status, kStart + kRetryPeriod);
  ASSERT_TRUE(retry) << "the same announcement is read again after the period";
  follower.refused(*retry, "checksum mismatch in /values", kStart + kRetryPeriod);
  EXPECT_TRUE(follower.take_synthesis_request(status)) << "a recomputation that failed is asked again";

  const auto healed = follower.on_status(ready_status("00000000000000b2"), kStart + kRetryPeriod + 1);
  ASSERT_TRUE(healed) << "the recomputed policy is loaded at once";
  follower.loaded(healed->identity);
  EXPECT_EQ("", follower.refusal_notice());
}

TEST(PolicyFollower, NoRecomputationWhileTheSynthesizerRunsOrAnnouncesAnotherPolicy) {
  amytiss_ros::PolicyFollower follower(kRetryPeriod);
  amytiss::PolicyStatus status = ready_status("00000000000000c1");
  const auto job = follower.on_status(status, kStart);
  ASSERT_TRUE(job);
  follower.refused(*job, "truncated", kStart);
  status.synthesizing = true;
  EXPECT_FALSE(follower.take_synthesis_request(status)) << "a goal would cancel the running synthesis";
  EXPECT_FALSE(follower.take_synthesis_request(ready_status("00000000000000c2"))) << "another policy is announced";
  EXPECT_NE(follower.refusal_notice().find("waiting for the synthesizer"), std::string::npos);
}

constexpr const char* kOtherHash = "fedcba9876543210";
constexpr const char* kOtherRun = "00000000000000d0";

TEST(PolicyFollower, AFileOfAnotherPolicyIsRefusedNamingBothAndAnUnannouncedPolicyGivesWay) {
  amytiss_ros::PolicyFollower follower(kRetryPeriod);
  const amytiss_ros::LoadJob at_start{"/tmp/robot.h5", "", "", ""};
  EXPECT_EQ("", amytiss_ros::identity_mismatch(at_start, kOtherHash, kOtherRun)) << "no announcement: any policy";
  follower.loaded(amytiss_ros::policy_identity(kOtherHash, kOtherRun));

  const amytiss::PolicyStatus status = ready_status("00000000000000d1");
  const auto job = follower.on_status(status, kStart);
  ASSERT_TRUE(job) << "the announced policy is not the one served";
  EXPECT_EQ(status.config_hash, job->config_hash);
  EXPECT_EQ(status.run_id, job->run_id);
  EXPECT_EQ("", amytiss_ros::identity_mismatch(*job, status.config_hash, status.run_id));
  const std::string reason = amytiss_ros::identity_mismatch(*job, kOtherHash, kOtherRun);
  EXPECT_EQ("it holds the policy of hash fedcba9876543210 (run 00000000000000d0), not the announced one, "
            "hash 0123456789abcdef (run 00000000000000d1)",
            reason);
  EXPECT_TRUE(follower.refused(*job, reason, kStart)) << "the policy no status announced gives way";
  EXPECT_TRUE(follower.take_synthesis_request(status)) << "the announced policy is asked for";
  EXPECT_NE(follower.refusal_notice().find(reason), std::string::npos) << follower.refusal_notice();
  EXPECT_FALSE(follower.on_status(status, kStart + 1)) << "retried after the period only";

  const auto retry = follower.on_status(status, kStart + kRetryPeriod);
  ASSERT_TRUE(retry);
  EXPECT_FALSE(follower.refused(*retry, reason, kStart + kRetryPeriod)) << "nothing served any more";
  const auto healed = follower.on_status(ready_status("00000000000000d2"), kStart + kRetryPeriod + 1);
  ASSERT_TRUE(healed);
  follower.loaded(healed->identity);
  EXPECT_EQ("", follower.refusal_notice());
}

TEST(PolicyFollower, AnAnnouncedPolicyStaysServedWhenTheNextFileIsRefused) {
  amytiss_ros::PolicyFollower follower(kRetryPeriod);
  // Served from ~policy_file at start, then announced: it counts as announced.
  const amytiss::PolicyStatus first = ready_status("00000000000000e1");
  follower.loaded(amytiss_ros::policy_identity(first.config_hash, first.run_id));
  EXPECT_FALSE(follower.on_status(first, kStart)) << "the served policy is not loaded again";
  const auto job = follower.on_status(ready_status("00000000000000e2"), kStart + 1);
  ASSERT_TRUE(job);
  EXPECT_FALSE(follower.refused(*job, amytiss_ros::identity_mismatch(*job, kOtherHash, kOtherRun), kStart + 1))
      << "a policy once announced stays served until the next one loads";

  amytiss_ros::PolicyFollower followed(kRetryPeriod);
  const auto announced = followed.on_status(first, kStart);
  ASSERT_TRUE(announced);
  followed.loaded(announced->identity);
  const auto next = followed.on_status(ready_status("00000000000000e2"), kStart + 1);
  ASSERT_TRUE(next);
  EXPECT_FALSE(followed.refused(*next, "truncated", kStart + 1));
}

}  // namespace
