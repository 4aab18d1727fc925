#pragma once
// The synthesizer node's logic (the node's main() only constructs it and spins).
//
// Interface (relative to the public node handle, /amytiss in the launch files):
//   action  synthesize (amytiss/Synthesize): re-read the private parameters (or the goal's YAML)
//           and synthesize; cancel the goal to stop; feedback per time step.
//   topic   status (amytiss/PolicyStatus, latched): progress, errors, and each new policy;
//           republished every ~heartbeat_period_s as a heartbeat.
//   topic   /diagnostics (diagnostic_updater): synthesis state, device, the ready policy.
// SIGINT / SIGTERM (the node's main) and rosnode kill end in shutdown(): exit status 0, the
// policy file whole.
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
  /// shutdown().
  ~SynthesizerNode();
  /// Starts the action server and, when ~synthesize_on_start, a first synthesis in a worker
  /// thread from the private parameters.
  void start();
  /// Stops in order: new goals are refused, the running synthesis is cancelled at its next
  /// progress report (a policy file being written is finished: the file is replaced whole or not
  /// at all), the action and start-up threads are joined, and a last status says nothing runs.
  /// Idempotent; call it while ROS is still up so that the last status and result go out.
  void shutdown();

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
  /// The valid policy file of `config` at outcome.policy_file, announced as reused, or nothing.
  bool reuse_existing(const amytiss::Config& config, Outcome& outcome);
  /// Synthesizes `config` and writes outcome.policy_file; throws Cancelled or the engine's errors.
  void synthesize_and_write(const amytiss::Config& config, const CancelCheck& cancelled,
                            const ProgressSink& on_progress, Outcome& outcome);
  /// The status of a new ready policy (computed: PHASE_DONE, or PHASE_REUSED).
  void announce(const amytiss::Config& config, const amytiss::Policy& policy, const Outcome& outcome,
                const std::string& phase);
  /// The status of a synthesis that ended without a policy (PHASE_CANCELLED or PHASE_ERROR).
  void report_stopped(const std::string& phase, const std::string& message);
  Outcome run_from_source(const std::function<amytiss::Config()>& read_config, bool force,
                          const CancelCheck& cancelled, const ProgressSink& on_progress);
  void execute_goal(const amytiss::SynthesizeGoalConstPtr& goal);
  /// Edits the status under its lock, stamps it and publishes it.
  void update_status(const std::function<void(amytiss::PolicyStatus&)>& edit);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& diagnostic);

  // Members are destroyed in reverse order: the threads that use the status, the mutexes and the
  // publisher (action server, start-up thread) come last so that they are stopped first
  // (shutdown() joins them before any of this is destroyed).
  ros::NodeHandle public_handle_, private_handle_;
  ros::Publisher status_publisher_;
  std::mutex job_mutex_;  // one synthesis at a time
  std::mutex status_mutex_;
  amytiss::PolicyStatus status_;
  std::atomic<bool> stopping_{false};  // shutdown() began: refuse goals, cancel the running job
  std::atomic<bool> cancel_startup_job_{false};
  diagnostic_updater::Updater diagnostics_;
  ros::WallTimer heartbeat_timer_;
  actionlib::SimpleActionServer<amytiss::SynthesizeAction> action_server_;
  std::thread startup_thread_;
};

}  // namespace amytiss_ros
