// What the policy server says about the synthesizer: alive while its heartbeat comes, "not running
// since ..." after the timeout or when its publisher is gone, and the notice on each answer.
#include <gtest/gtest.h>

#include "synthesizer_monitor.hpp"

namespace {

constexpr double kTimeout = 3.0;
constexpr double kStart = 1764162300.0;  // 2025-11-26 13:05:00 UTC

amytiss::PolicyStatus running_status() {
  amytiss::PolicyStatus status;
  status.synthesizing = true;
  status.percent = 41;
  status.message = "synthesis 41% (step 5/12) on reference";
  return status;
}

amytiss_ros::ServedPolicy served() {
  return {"robot_safety", "0123456789abcdef", "fedcba9876543210", "/tmp/robot_safety.h5", kStart - 60};
}

TEST(SynthesizerMonitor, BeforeAnyStatusItWaits) {
  const amytiss_ros::SynthesizerMonitor monitor(kTimeout);
  EXPECT_FALSE(monitor.alive(kStart, 1));
  EXPECT_EQ("waiting for the synthesizer's status on /amytiss/status", monitor.no_policy_reason(kStart, 0));
  EXPECT_EQ("", monitor.serving_notice(served(), kStart, 0)) << "a file given at start needs no synthesizer";
}

TEST(SynthesizerMonitor, AliveWhileTheHeartbeatComes) {
  amytiss_ros::SynthesizerMonitor monitor(kTimeout);
  monitor.on_status(running_status(), kStart);
  EXPECT_TRUE(monitor.alive(kStart + kTimeout, 1));
  EXPECT_EQ("synthesis is running (41%): synthesis 41% (step 5/12) on reference",
            monitor.no_policy_reason(kStart + 1, 1));
  EXPECT_EQ("", monitor.serving_notice(served(), kStart + 1, 1));
}

TEST(SynthesizerMonitor, NoHeartbeatMeansStoppedAndTheNoticeNamesThePolicy) {
  amytiss_ros::SynthesizerMonitor monitor(kTimeout);
  monitor.on_status(running_status(), kStart);
  const double later = kStart + 15.25;
  EXPECT_FALSE(monitor.alive(later, 1));
  EXPECT_EQ("synthesizer not running since 2025-11-26 13:05:00 UTC (no status for 15.2 s)",
            monitor.no_policy_reason(later, 1));
  EXPECT_EQ("synthesizer not running since 2025-11-26 13:05:00 UTC (no status for 15.2 s); serving policy "
            "'robot_safety' (hash 0123456789abcdef, run fedcba9876543210, loaded 2025-11-26 13:04:00 UTC)",
            monitor.serving_notice(served(), later, 1));
  // A new status brings it back.
  monitor.on_status(running_status(), later);
  EXPECT_TRUE(monitor.alive(later + 1, 1));
}

TEST(SynthesizerMonitor, PublisherGoneMeansStoppedAtOnce) {
  amytiss_ros::SynthesizerMonitor monitor(kTimeout);
  monitor.on_status(running_status(), kStart);
  EXPECT_FALSE(monitor.alive(kStart + 0.5, 0));
  EXPECT_EQ("synthesizer not running since 2025-11-26 13:05:00 UTC (its status publisher is gone)",
            monitor.stopped_notice(kStart + 0.5, 0));
}

}  // namespace
