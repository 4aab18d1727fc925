#pragma once
// The policy server node's logic (the node's main() only constructs it and spins).
//
// Interface (relative to the public node handle, /amytiss in the launch files):
//   service get_input (amytiss/GetInput)          state + step -> input + probability
//   topic   state     (amytiss/StateStamped, in)   closed loop: each state is answered on
//   topic   command   (amytiss/InputCommand, out)  with the same stamp and time step
//   topic   status    (amytiss/PolicyStatus, in)   loads policy_file when ready and
//                                                       (config_hash, run_id) differs from the
//                                                       policy served; its heartbeat tells
//                                                       whether the synthesizer still runs
//   topic   markers   (visualization_msgs/MarkerArray, latched) grid bounds, target, avoid, safe
//   topic   /diagnostics (diagnostic_updater): policy loaded, its name, hash, run id and age,
//                                              synthesizer alive or not, synthesis state, device
// Private parameters: ~policy_file (string, optional: a policy to serve from the start, before
// any status arrives), ~frame_id (string, default "map") for the markers,
// ~synthesizer_timeout_s (double, default 3): no status for this long means the synthesizer
// stopped (it sends one every second).
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <amytiss/GetInput.h>
#include <amytiss/InputCommand.h>
#include <amytiss/PolicyStatus.h>
#include <amytiss/StateStamped.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include "amytiss/policy.hpp"
#include "synthesizer_monitor.hpp"

namespace amytiss_ros {

class PolicyServerNode {
 public:
  PolicyServerNode(ros::NodeHandle public_handle, ros::NodeHandle private_handle);
  ~PolicyServerNode();

  /// Loads a policy file and swaps it in atomically (requests in flight finish on the old one).
  /// Returns false (and logs) when the file cannot be read (missing, corrupt: a checksum does not
  /// match); the old policy stays.
  bool load(const std::string& path);

 private:
  bool on_get_input(amytiss::GetInput::Request& request, amytiss::GetInput::Response& response);
  void on_state(const amytiss::StateStamped::ConstPtr& state);
  void on_status(const amytiss::PolicyStatus::ConstPtr& status);
  /// The notice for an answer: why there is no policy, or a warning when the synthesizer stopped.
  std::string notice(bool have_policy) const;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle public_handle_, private_handle_;
  std::string frame_id_;
  ros::ServiceServer service_;
  ros::Subscriber state_subscriber_, status_subscriber_;
  ros::Publisher command_publisher_, marker_publisher_;

  // Read with std::atomic_load by every request, replaced with std::atomic_store by load().
  std::shared_ptr<const amytiss::Policy> policy_;

  mutable std::mutex monitor_mutex_;  // guards the three below
  SynthesizerMonitor monitor_;
  ServedPolicy served_;
  std::string requested_identity_;  // "<config_hash> <run_id>" of the last load started

  std::mutex command_mutex_;
  amytiss::InputCommand command_;  // reused: its input vector keeps its capacity

  std::mutex loader_mutex_;
  std::thread loader_thread_;

  diagnostic_updater::Updater diagnostics_;
  ros::WallTimer diagnostics_timer_;
};

}  // namespace amytiss_ros
