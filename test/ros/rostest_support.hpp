#pragma once
// Helpers for the amytiss rostests (map_server's rtest style): everything waits with a bound.
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <amytiss/PolicyStatus.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

namespace amytiss_test {

constexpr double kServiceWaitSeconds = 20.0;
constexpr double kPolicyWaitSeconds = 40.0;
constexpr double kPollPeriodSeconds = 0.02;

/// Polls `condition` every kPollPeriodSeconds for at most `seconds`.
inline bool poll_until(const std::function<bool()>& condition, double seconds) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    if (condition()) return true;
    ros::WallDuration(kPollPeriodSeconds).sleep();
  }
  return condition();
}

/// The status stream at one moment: how many statuses had arrived and the latest of them.
struct StatusMark {
  std::size_t received = 0;
  amytiss::PolicyStatus latest;
};

/// Whether two statuses say the same (the heartbeat republishes a status with a new stamp only).
inline bool same_content(const amytiss::PolicyStatus& a, const amytiss::PolicyStatus& b) {
  return a.ready == b.ready && a.synthesizing == b.synthesizing && a.percent == b.percent && a.phase == b.phase &&
         a.message == b.message && a.config_hash == b.config_hash && a.run_id == b.run_id &&
         a.generation == b.generation && a.syntheses_run == b.syntheses_run;
}

/// Every /amytiss/status, kept by a subscriber on the caller's spinner.
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
    return poll_until([&] { return condition(latest()); }, seconds);
  }
  StatusMark mark() {
    std::lock_guard<std::mutex> lock(mutex_);
    return {received_.size(), latest_};
  }
  /// Waits (bounded) for the status that reports the outcome `message` of something started
  /// after `mark`: the first status received since then with that message, once the stream has
  /// said something new (a heartbeat of the status at `mark` does not count, so a result whose
  /// message repeats the previous status's waits for its own status; the synthesizer marks the
  /// start of each goal on the stream).
  std::optional<amytiss::PolicyStatus> wait_for_outcome(const StatusMark& mark, const std::string& message,
                                                        double seconds) {
    std::optional<amytiss::PolicyStatus> found;
    poll_until([&] {
      std::lock_guard<std::mutex> lock(mutex_);
      bool changed = false;
      for (std::size_t i = mark.received; i < received_.size() && !found; ++i) {
        changed = changed || !same_content(received_[i], mark.latest);
        if (changed && received_[i].message == message) found = received_[i];
      }
      return found.has_value();
    }, seconds);
    return found;
  }

 private:
  void on_status(const amytiss::PolicyStatus::ConstPtr& status) {
    std::lock_guard<std::mutex> lock(mutex_);
    latest_ = *status;
    received_.push_back(*status);
  }
  std::mutex mutex_;
  amytiss::PolicyStatus latest_;
  std::vector<amytiss::PolicyStatus> received_;  // in order of arrival
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

}  // namespace amytiss_test
