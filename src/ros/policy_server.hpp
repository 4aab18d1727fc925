#pragma once
// The policy server node's logic (the node's main() only constructs it and spins).
//
// Interface (relative to the public node handle, /amytiss in the launch files):
//   service get_input (amytiss/GetInput)          state + step -> input + probability; a request
//                                                  whose state length claims more values than it
//                                                  carries is answered without being decoded
//   topic   state     (amytiss/StateStamped, in)   closed loop: each state is answered on
//   topic   command   (amytiss/InputCommand, out)  with the same stamp and time step
//   topic   status    (amytiss/PolicyStatus, in)   loads policy_file when ready and
//                                                       (config_hash, run_id) differs from the
//                                                       policy served, and refuses a file that
//                                                       holds another policy; its heartbeat
//                                                       tells whether the synthesizer still runs
//   action  synthesize (amytiss/Synthesize, client) a refused policy file (corrupt, missing, not
//                                                  the announced policy) is retried and the
//                                                  synthesizer asked to compute it again (goal
//                                                  with force: true)
//   topic   markers   (visualization_msgs/MarkerArray, latched) grid bounds, target, avoid, safe
//   topic   /diagnostics (diagnostic_updater): policy loaded, its name, hash, run id and age,
//                                              refused file, the announced hash and run id,
//                                              synthesizer alive or not, synthesis
//                                              state, device, get_input calls answered on the
//                                              network thread and on a spinner thread
// Private parameters: ~policy_file (string, optional: a policy to serve from the start, before
// any status arrives; once a status announces another policy and its file is refused, it is no
// longer served), ~frame_id (string, default "map") for the markers,
// ~synthesizer_timeout_s (double, default 3): no status for this long means the synthesizer
// stopped (it sends one every second), ~retry_period_s (double, default 5): a refused file that
// is still announced is read again after this long.
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <actionlib/client/simple_action_client.h>
#include <amytiss/GetInput.h>
#include <amytiss/InputCommand.h>
#include <amytiss/PolicyStatus.h>
#include <amytiss/StateStamped.h>
#include <amytiss/SynthesizeAction.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include "amytiss/policy.hpp"
#include "amytiss/policy_file.hpp"
#include "immediate_callback_queue.hpp"
#include "policy_follower.hpp"
#include "synthesizer_monitor.hpp"

namespace amytiss_ros {

class PolicyServerNode {
 public:
  PolicyServerNode(ros::NodeHandle public_handle, ros::NodeHandle private_handle);
  ~PolicyServerNode();

 private:
  /// The notices every answer carries, prepared off the request path (on statuses, loads and a
  /// timer): `serving` goes with answers of a loaded policy, `no_policy` says why there is none.
  struct Notices {
    std::string serving;
    std::string no_policy;
  };

  /// Loads a policy file and swaps it in atomically (requests in flight finish on the old one).
  /// On failure (missing, corrupt: a checksum does not match; another policy than the status
  /// announced) the refusal is recorded in follower_, the old policy stays unless no status ever
  /// announced it (PolicyFollower::refused), and the synthesizer is asked to compute it again.
  void load(const LoadJob& job);
  void serve(const LoadJob& job, amytiss::LoadedPolicy loaded);
  void refuse(const LoadJob& job, const std::string& reason);
  void request_synthesis();
  bool on_get_input(amytiss::GetInput::Request& request, amytiss::GetInput::Response& response);
  void on_state(const amytiss::StateStamped::ConstPtr& state);
  void on_status(const amytiss::PolicyStatus::ConstPtr& status);
  void start_load(const LoadJob& job);
  /// Rebuilds notices_ from the monitor, the follower and the served policy.
  void refresh_notices();
  const std::string& notice_for(const std::shared_ptr<const amytiss::Policy>& policy,
                                const std::shared_ptr<const Notices>& notices) const;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle public_handle_, private_handle_;
  std::string frame_id_;
  // get_input is answered on roscpp's network thread as each request is read (declared before
  // service_, which uses it until it is shut down); every other callback goes to the spinners.
  ImmediateCallbackQueue service_queue_;
  ros::ServiceServer service_;
  ros::Subscriber state_subscriber_, status_subscriber_;
  ros::Publisher command_publisher_, marker_publisher_;

  // Read with std::atomic_load by every request, replaced with std::atomic_store.
  std::shared_ptr<const amytiss::Policy> policy_;
  std::shared_ptr<const Notices> notices_;

  mutable std::mutex monitor_mutex_;  // guards the four below
  SynthesizerMonitor monitor_;
  PolicyFollower follower_;
  ServedPolicy served_;
  std::string convergence_notice_;  // of the served policy

  std::mutex command_mutex_;
  amytiss::InputCommand command_;  // reused: its input vector keeps its capacity

  actionlib::SimpleActionClient<amytiss::SynthesizeAction> synthesis_client_;

  std::mutex loader_mutex_;
  std::thread loader_thread_;

  diagnostic_updater::Updater diagnostics_;
  ros::WallTimer diagnostics_timer_, notices_timer_;
};

}  // namespace amytiss_ros
