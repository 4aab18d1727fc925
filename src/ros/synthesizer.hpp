#pragma once
// The synthesizer node's logic (the node's main() only constructs it and spins).
//
// Interface (relative to the public node handle, /amytiss in the launch files):
//   action  synthesize (amytiss/Synthesize): re-read the private parameters (or the goal's YAML)
//           and synthesize; cancel the goal to stop; feedback per time step.
//   topic   status (amytiss/PolicyStatus, latched): progress, errors, and each new policy;
//           republished every ~heartbeat_period_s as a heartbeat.
//   topic   /diagnostics (diagnostic_updater): synthesis state, device, the ready policy.
// Private parameters: the configuration schema (docs/configuration.md), plus
//   ~policy_file (string, default $ROS_HOME/amytiss/<name>.h5, ROS_HOME defaults to ~/.ros),
//   ~device (string, overrides compute.device when not empty: auto | cpu | gpu | reference),
//   ~synthesize_on_start (bool, default true),
//   ~heartbeat_period_s (double, default 1): period of the status heartbeat.
#include <atomic>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include <actionlib/server/simple_action_server.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <amytiss/PolicyStatus.h>
#include <amytiss/SynthesizeAction.h>
#include <ros/ros.h>

#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"

namespace amytiss_ros {

/// Default policy file of a configuration: $ROS_HOME/amytiss/<name>.h5 (ROS_HOME defaults to
/// $HOME/.ros). `name` is sanitized to [A-Za-z0-9_-].
std::string default_policy_path(const std::string& config_name);

class SynthesizerNode {
 public:
  SynthesizerNode(ros::NodeHandle public_handle, ros::NodeHandle private_handle);
  ~SynthesizerNode();
  /// Starts the action server and, when ~synthesize_on_start, a first synthesis in a worker
  /// thread from the private parameters.
  void start();

 private:
  struct Outcome {
    bool success = false;
    bool reused = false;
    std::string message;
    std::string policy_file;
  };
  using CancelCheck = std::function<bool()>;
  using ProgressSink = std::function<void(const amytiss::Progress&)>;

  amytiss::Config read_parameters() const;
  std::string policy_path_for(const amytiss::Config& config) const;
  /// One synthesis (or reuse) of `config`; never throws: errors end in the status and outcome.
  Outcome run(const amytiss::Config& config, bool force, const CancelCheck& cancelled,
              const ProgressSink& on_progress);
  Outcome run_from_source(const std::function<amytiss::Config()>& read_config, bool force,
                          const CancelCheck& cancelled, const ProgressSink& on_progress);
  void execute_goal(const amytiss::SynthesizeGoalConstPtr& goal);
  /// Edits the status under its lock, stamps it and publishes it.
  void update_status(const std::function<void(amytiss::PolicyStatus&)>& edit);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& diagnostic);

  ros::NodeHandle public_handle_, private_handle_;
  diagnostic_updater::Updater diagnostics_;
  ros::WallTimer heartbeat_timer_;
  actionlib::SimpleActionServer<amytiss::SynthesizeAction> action_server_;
  ros::Publisher status_publisher_;
  std::mutex job_mutex_;  // one synthesis at a time
  std::mutex status_mutex_;
  amytiss::PolicyStatus status_;
  std::atomic<bool> cancel_startup_job_{false};
  std::thread startup_thread_;
};

}  // namespace amytiss_ros
