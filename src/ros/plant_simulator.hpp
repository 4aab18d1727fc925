#pragma once
// The plant simulator node's logic: closes the loop through the policy server's topics.
//
// Waits for a ready policy on /amytiss/status, reads its file (configuration and V_0 inside),
// then runs ~episodes episodes from ~initial_state: publish amytiss/StateStamped on state, wait
// for the matching amytiss/InputCommand on command, step the plant (PlantModel), until the
// target, the avoid set / outside the safe set, leaving the grid, or the horizon. Logs each
// outcome and, at the end, the empirical success rate next to V_0 of the start state; writes a
// CSV of the trajectories and pictures (scripts/plot_episodes.py) into ~output_dir; publishes a
// latched amytiss/EpisodeSummary on episode_summary.
// Private parameters: initial_state (list, state units, required), episodes (int, 20), seed
// (int, 1), output_dir (string, default $ROS_HOME/amytiss/episodes), plot_script (string, empty:
// no pictures), python (string, default: the Python catkin was configured with), command_timeout_s (5), policy_timeout_s
// (600), exit_when_done (bool, true), scene_file (string, empty: none; a picture's scene for the
// plot script, e.g. config/bmw_parking_scene.yaml), playback_period_s (wall seconds between steps,
// 0: as fast as the loop runs; for watching in RViz).
// For a built-in model of a car (amytiss::VehicleOutline) it also publishes the body on car_marker
// (visualization_msgs/Marker, frame "map") at every state, tells each outcome how the car turned
// and moved, and has its footprint drawn in the trajectory picture.
#include <condition_variable>
#include <mutex>
#include <string>
#include <vector>

#include <amytiss/EpisodeSummary.h>
#include <amytiss/InputCommand.h>
#include <amytiss/PolicyStatus.h>
#include <ros/ros.h>

#include "plant_model.hpp"

namespace amytiss_ros {

class PlantSimulatorNode {
 public:
  PlantSimulatorNode(ros::NodeHandle public_handle, ros::NodeHandle private_handle);
  /// Runs all episodes (needs a spinner running in other threads). Returns the process exit code:
  /// 0 when all episodes ran, 1 when the policy or the server never came.
  int run();

 private:
  /// The private parameters (see above).
  struct Settings {
    std::vector<double> initial_state;
    int episodes = 20, seed = 1;
    double command_timeout_s = 5.0, policy_timeout_s = 600.0, playback_period_s = 0.0;
    std::string output_dir, plot_script, python, scene_file;
    bool exit_when_done = true;
  };
  struct Simulation;  // the policy, its configuration and the plant of one run()

  Settings read_settings() const;
  void on_status(const amytiss::PolicyStatus::ConstPtr& status);
  void on_command(const amytiss::InputCommand::ConstPtr& command);
  /// The first ready status within the timeout, or null.
  amytiss::PolicyStatus::ConstPtr wait_for_policy(double timeout_s);
  /// Whether the policy server subscribed to state and publishes command within the timeout.
  bool wait_for_server(double timeout_s);
  /// All episodes; their trajectories into the CSV file `csv_path`. Fills episodes, successes,
  /// outcomes and csv_file of the summary.
  amytiss::EpisodeSummary run_episodes(Simulation& simulation, const std::string& csv_path);
  /// One episode from the initial state; its CSV rows (without the success column) into `rows`.
  EpisodeOutcome run_episode(int episode, Simulation& simulation, std::vector<std::string>& rows);
  /// The server's command for `state` at `step`; a "no policy yet" answer is asked again until
  /// policy_timeout_s. Null when the server did not answer within command_timeout_s.
  amytiss::InputCommand::ConstPtr request_input(const std::vector<double>& state, unsigned step);
  /// Runs the plot script; on success the picture paths go into `summary`.
  void draw_pictures(const Simulation& simulation, const std::string& csv_path, const std::string& base,
                     amytiss::EpisodeSummary& summary) const;

  ros::NodeHandle public_handle_, private_handle_;
  ros::Publisher state_publisher_, summary_publisher_, car_publisher_;
  ros::Subscriber status_subscriber_, command_subscriber_;
  Settings settings_;
  ros::Time last_stamp_;  // of the last published state: each state gets a later stamp

  std::mutex mutex_;
  std::condition_variable changed_;
  amytiss::PolicyStatus::ConstPtr ready_status_;
  amytiss::InputCommand::ConstPtr last_command_;
};

}  // namespace amytiss_ros
