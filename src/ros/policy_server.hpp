#pragma once
// The policy server node's logic (the node's main() only constructs it and spins).
//
// Interface (relative to the public node handle, /amytiss in the launch files):
//   service get_input (amytiss/GetInput)          state + step -> input + probability
//   topic   state     (amytiss/StateStamped, in)   closed loop: each state is answered on
//   topic   command   (amytiss/InputCommand, out)  with the same stamp and time step
//   topic   status    (amytiss/PolicyStatus, in)   loads policy_file when ready and generation changes
//   topic   markers   (visualization_msgs/MarkerArray, latched) grid bounds, target, avoid, safe
// Private parameters: ~policy_file (string, optional: a policy to serve from the start, before
// any status arrives), ~frame_id (string, default "map") for the markers.
#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <amytiss/GetInput.h>
#include <amytiss/InputCommand.h>
#include <amytiss/PolicyStatus.h>
#include <amytiss/StateStamped.h>
#include <ros/ros.h>

#include "amytiss/policy.hpp"

namespace amytiss_ros {

class PolicyServerNode {
 public:
  PolicyServerNode(ros::NodeHandle public_handle, ros::NodeHandle private_handle);
  ~PolicyServerNode();

  /// Loads a policy file and swaps it in atomically (requests in flight finish on the old one).
  /// Returns false (and logs) when the file cannot be read; the old policy stays.
  bool load(const std::string& path, unsigned generation);

 private:
  bool on_get_input(amytiss::GetInput::Request& request, amytiss::GetInput::Response& response);
  void on_state(const amytiss::StateStamped::ConstPtr& state);
  void on_status(const amytiss::PolicyStatus::ConstPtr& status);
  std::string no_policy_reason() const;

  ros::NodeHandle public_handle_, private_handle_;
  std::string frame_id_;
  ros::ServiceServer service_;
  ros::Subscriber state_subscriber_, status_subscriber_;
  ros::Publisher command_publisher_, marker_publisher_;

  // Read with std::atomic_load by every request, replaced with std::atomic_store by load().
  std::shared_ptr<const amytiss::Policy> policy_;
  std::atomic<unsigned> loaded_generation_{0};
  std::atomic<unsigned> requested_generation_{0};

  mutable std::mutex reason_mutex_;
  std::string synthesizer_message_ = "waiting for the synthesizer's status on /amytiss/status";

  std::mutex command_mutex_;
  amytiss::InputCommand command_;  // reused: its input vector keeps its capacity

  std::mutex loader_mutex_;
  std::thread loader_thread_;
};

}  // namespace amytiss_ros
