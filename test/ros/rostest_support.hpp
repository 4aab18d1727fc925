#pragma once
// Helpers for the amytiss rostests (map_server's rtest style): everything waits with a bound.
#include <functional>
#include <mutex>

#include <amytiss/PolicyStatus.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

namespace amytiss_test {

constexpr double kServiceWaitSeconds = 20.0;
constexpr double kPolicyWaitSeconds = 40.0;
constexpr double kPollPeriodSeconds = 0.02;

/// Latest /amytiss/status, kept by a subscriber on the caller's spinner.
class StatusWatcher {
 public:
  explicit StatusWatcher(ros::NodeHandle& handle)
      : subscriber_(handle.subscribe("/amytiss/status", 20, &StatusWatcher::on_status, this)) {}
  amytiss::PolicyStatus latest() {
    std::lock_guard<std::mutex> lock(mutex_);
    return latest_;
  }
  /// Waits (bounded) until `condition` holds for the latest status; returns whether it did.
  bool wait_for(const std::function<bool(const amytiss::PolicyStatus&)>& condition, double seconds) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::ok() && ros::WallTime::now() < deadline) {
      if (condition(latest())) return true;
      ros::WallDuration(kPollPeriodSeconds).sleep();
    }
    return condition(latest());
  }

 private:
  void on_status(const amytiss::PolicyStatus::ConstPtr& status) {
    std::lock_guard<std::mutex> lock(mutex_);
    latest_ = *status;
  }
  std::mutex mutex_;
  amytiss::PolicyStatus latest_;
  ros::Subscriber subscriber_;
};

/// main() of a rostest: gtest, a node named `node_name`, `threads` spinner threads for the
/// subscriptions and action clients of the tests.
inline int run_rostests(int argc, char** argv, const char* node_name, unsigned threads) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, node_name);
  ros::AsyncSpinner spinner(threads);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  ros::shutdown();
  return result;
}

/// Polls `condition` every kPollPeriodSeconds for at most `seconds`.
inline bool poll_until(const std::function<bool()>& condition, double seconds) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    if (condition()) return true;
    ros::WallDuration(kPollPeriodSeconds).sleep();
  }
  return condition();
}

}  // namespace amytiss_test
