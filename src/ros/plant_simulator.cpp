#include "plant_simulator.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include <amytiss/StateStamped.h>
#include <visualization_msgs/Marker.h>

#include "amytiss/policy_file.hpp"
#include "amytiss/config.hpp"
#include "conversions.hpp"
#include "plant_model.hpp"
#include "synthesizer.hpp"

namespace amytiss_ros {

PlantSimulatorNode::PlantSimulatorNode(ros::NodeHandle public_handle, ros::NodeHandle private_handle)
    : public_handle_(public_handle), private_handle_(private_handle) {
  state_publisher_ = public_handle_.advertise<amytiss::StateStamped>("state", 10);
  summary_publisher_ = public_handle_.advertise<amytiss::EpisodeSummary>("episode_summary", 1, /*latch=*/true);
  car_publisher_ = public_handle_.advertise<visualization_msgs::Marker>("car_marker", 10);
  status_subscriber_ = public_handle_.subscribe("status", 10, &PlantSimulatorNode::on_status, this);
  command_subscriber_ = public_handle_.subscribe("command", 10, &PlantSimulatorNode::on_command, this,
                                                 ros::TransportHints().tcpNoDelay());
}

void PlantSimulatorNode::on_status(const amytiss::PolicyStatus::ConstPtr& status) {
  if (!status->ready) return;
  std::lock_guard<std::mutex> lock(mutex_);
  ready_status_ = status;
  changed_.notify_all();
}

void PlantSimulatorNode::on_command(const amytiss::InputCommand::ConstPtr& command) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_command_ = command;
  changed_.notify_all();
}

namespace {

std::string format4(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4f", value);
  return text;
}

// The bounds of a policy with guarantee: system at a state's cell.
std::string bounds_text(double lower, double upper) {
  return "certified lower bound for the continuous system (guarantee: system) = " + format4(lower) +
         ", upper bound " + format4(upper);
}

std::string join(const std::vector<double>& values) {
  std::ostringstream text;
  text.precision(6);
  for (std::size_t i = 0; i < values.size(); ++i) text << (i ? ", " : "") << values[i];
  return text.str();
}

/// One CSV row without the success column; an empty input (the final state) leaves u and
/// probability empty.
std::string csv_row(int episode, unsigned step, const std::vector<double>& state, const std::vector<double>& input,
                    std::size_t input_dims, double probability) {
  std::ostringstream row;
  row.precision(10);
  row << episode << "," << step;
  for (double x : state) row << "," << x;
  for (std::size_t i = 0; i < input_dims; ++i) {
    row << ",";
    if (i < input.size()) row << input[i];
  }
  row << ",";
  if (!std::isnan(probability)) row << probability;
  return row.str();
}

// Runs a program with these arguments (no shell, so names and paths need no quoting) and waits.
// Returns "" on exit status 0, otherwise what went wrong.
std::string run_program(const std::vector<std::string>& arguments) {
  std::vector<char*> argv;
  for (const auto& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  pid_t child = 0;
  const int spawn_error = posix_spawnp(&child, argv[0], nullptr, nullptr, argv.data(), environ);
  if (spawn_error != 0) return std::string("cannot start ") + arguments[0] + ": " + std::strerror(spawn_error);
  int status = 0;
  while (waitpid(child, &status, 0) < 0)
    if (errno != EINTR) return std::string("cannot wait for ") + arguments[0] + ": " + std::strerror(errno);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  return WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                           : "killed by signal " + std::to_string(WTERMSIG(status));
}

/// The stored configuration of a policy file, as the plant needs it (dynamics, noise, spec, model):
/// read, not judged again (it was validated before the policy was computed, and the file's digest
/// vouches for the text).
amytiss::Config stored_configuration(const amytiss::LoadedPolicy& loaded) {
  return amytiss::read_stored_config(loaded.config_yaml);
}

}  // namespace

struct PlantSimulatorNode::Simulation {
  std::string policy_file;
  amytiss::LoadedPolicy loaded;
  amytiss::Config config;
  std::optional<PlantModel> plant;
  std::optional<amytiss::SpecSets> sets;  // what ends an episode: the configuration's own sets
  std::optional<amytiss::VehicleOutline> outline;
  const amytiss::Policy& policy() const { return loaded.policy; }
};

PlantSimulatorNode::Settings PlantSimulatorNode::read_settings() const {
  Settings settings;
  private_handle_.getParam("initial_state", settings.initial_state);
  private_handle_.param("episodes", settings.episodes, 20);
  private_handle_.param("seed", settings.seed, 1);
  private_handle_.param("command_timeout_s", settings.command_timeout_s, 5.0);
  private_handle_.param("policy_timeout_s", settings.policy_timeout_s, 600.0);
  private_handle_.param<std::string>("output_dir", settings.output_dir, "");
  private_handle_.param<std::string>("plot_script", settings.plot_script, "");
  // The interpreter catkin was configured with (the one catkin_install_python puts in shebangs).
  private_handle_.param<std::string>("python", settings.python, AMYTISS_PYTHON_EXECUTABLE);
  private_handle_.param("exit_when_done", settings.exit_when_done, true);
  private_handle_.param<std::string>("scene_file", settings.scene_file, "");
  private_handle_.param("playback_period_s", settings.playback_period_s, 0.0);
  if (settings.output_dir.empty())
    settings.output_dir = std::filesystem::path(default_policy_path("x")).parent_path().string() + "/episodes";
  return settings;
}

amytiss::PolicyStatus::ConstPtr PlantSimulatorNode::wait_for_policy(double timeout_s) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                    [&] { return ready_status_ != nullptr || !ros::ok(); });
  return ready_status_;
}

bool PlantSimulatorNode::wait_for_server(double timeout_s) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
  while (ros::ok() && (state_publisher_.getNumSubscribers() == 0 || command_subscriber_.getNumPublishers() == 0)) {
    if (ros::WallTime::now() > deadline) return false;
    ros::WallDuration(0.01).sleep();
  }
  return true;
}

amytiss::InputCommand::ConstPtr PlantSimulatorNode::request_input(const std::vector<double>& state, unsigned step) {
  // The server loads the policy after the status says ready: until then it answers "no policy
  // yet", and the state is sent again (bounded by policy_timeout_s).
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(settings_.policy_timeout_s);
  for (;;) {
    amytiss::StateStamped message;
    message.header.stamp = ros::Time::now();
    if (message.header.stamp <= last_stamp_) message.header.stamp = last_stamp_ + ros::Duration(0, 1);
    last_stamp_ = message.header.stamp;
    message.header.frame_id = "map";
    message.state = state;
    message.time_step = step;
    amytiss::InputCommand::ConstPtr command;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      state_publisher_.publish(message);
      const bool answered =
          changed_.wait_for(lock, std::chrono::duration<double>(settings_.command_timeout_s), [&] {
            return !ros::ok() || (last_command_ && last_command_->header.stamp == message.header.stamp &&
                                  last_command_->time_step == step);
          });
      if (answered) command = last_command_;
    }
    const bool not_loaded_yet = command && !command->valid && command->message.rfind("no policy yet", 0) == 0;
    if (!not_loaded_yet || ros::WallTime::now() > give_up || !ros::ok()) return command;
    ros::WallDuration(0.05).sleep();
  }
}

EpisodeOutcome PlantSimulatorNode::run_episode(int episode, Simulation& simulation, std::vector<std::string>& rows) {
  const amytiss::Policy& policy = simulation.policy();
  std::vector<double> state = settings_.initial_state;
  EpisodeOutcome outcome;
  for (unsigned step = 0;; ++step) {
    if (simulation.outline) car_publisher_.publish(make_car_marker(state, *simulation.outline, "map"));
    const amytiss::SetVerdict verdict = classify_state(*simulation.sets, state);
    if (verdict != amytiss::SetVerdict::Undecided || step >= policy.horizon) {
      outcome = episode_outcome(simulation.config.spec.type, verdict, step);
      rows.push_back(csv_row(episode, step, state, {}, policy.inputs.dims(), std::nan("")));
      break;
    }
    const amytiss::InputCommand::ConstPtr command = request_input(state, step);
    if (!command) {
      outcome = {false, "no command from the policy server within " + std::to_string(settings_.command_timeout_s) +
                            " s at step " + std::to_string(step)};
      break;
    }
    if (!command->valid) {
      outcome = {false, "unsafe: the server gave no input at step " + std::to_string(step) + " (" +
                            command->message + ")"};
      break;
    }
    rows.push_back(csv_row(episode, step, state, command->input, policy.inputs.dims(), command->probability));
    state = simulation.plant->step(state, command->input);
    if (settings_.playback_period_s > 0) ros::WallDuration(settings_.playback_period_s).sleep();
  }
  if (simulation.outline) outcome.description += vehicle_motion_text(*simulation.outline, settings_.initial_state, state);
  return outcome;
}

void PlantSimulatorNode::draw_pictures(const Simulation& simulation, const std::string& csv_path,
                                       const std::string& base, amytiss::EpisodeSummary& summary) const {
  const std::string trajectories_png = base + "_trajectories.png", values_png = base + "_values.png";
  std::vector<std::string> arguments = {settings_.python, settings_.plot_script, "--csv", csv_path, "--policy",
                                        simulation.policy_file, "--initial-state", join(settings_.initial_state),
                                        "--trajectories", trajectories_png, "--values", values_png};
  if (const auto& outline = simulation.outline) {
    arguments.push_back("--footprint");
    arguments.push_back(join({outline->length, outline->width, outline->rear_to_reference, double(outline->x_index),
                              double(outline->y_index), double(outline->yaw_index)}));
  }
  if (!settings_.scene_file.empty()) {
    arguments.push_back("--scene");
    arguments.push_back(settings_.scene_file);
  }
  const std::string failure = run_program(arguments);
  if (!failure.empty()) {
    ROS_WARN("the plot script %s failed (%s); trajectories are in %s", settings_.plot_script.c_str(), failure.c_str(),
             csv_path.c_str());
    return;
  }
  summary.trajectories_png = trajectories_png;
  summary.values_png = values_png;
  ROS_INFO("pictures: %s and %s", trajectories_png.c_str(), values_png.c_str());
}

amytiss::EpisodeSummary PlantSimulatorNode::run_episodes(Simulation& simulation, const std::string& csv_path) {
  const amytiss::Policy& policy = simulation.policy();
  std::ofstream csv(csv_path);
  csv << "episode,step";
  for (std::size_t i = 0; i < policy.states.dims(); ++i) csv << ",x" << i;
  for (std::size_t i = 0; i < policy.inputs.dims(); ++i) csv << ",u" << i;
  csv << ",probability,success\n";
  amytiss::EpisodeSummary summary;
  for (int episode = 1; episode <= settings_.episodes && ros::ok(); ++episode) {
    std::vector<std::string> rows;  // "episode,step,x..,u..,probability"; success appended at the end
    const EpisodeOutcome outcome = run_episode(episode, simulation, rows);
    summary.episodes += 1;
    if (outcome.success) summary.successes += 1;
    const std::string line = "episode " + std::to_string(episode) + ": " + outcome.description;
    summary.outcomes.push_back(line);
    ROS_INFO("%s", line.c_str());
    // The success flag goes on every row of the episode, so the plot can colour whole trajectories.
    for (const auto& row : rows) csv << row << "," << (outcome.success ? 1 : 0) << "\n";
  }
  summary.csv_file = csv_path;
  return summary;
}

int PlantSimulatorNode::run() {
  settings_ = read_settings();
  ROS_INFO("plant simulator: waiting for a policy on %s", status_subscriber_.getTopic().c_str());
  const amytiss::PolicyStatus::ConstPtr status = wait_for_policy(settings_.policy_timeout_s);
  if (!status) {
    ROS_ERROR("plant simulator: no policy became ready within %.0f s", settings_.policy_timeout_s);
    return 1;
  }
  Simulation simulation;
  simulation.policy_file = status->policy_file;
  try {
    simulation.loaded = amytiss::read_policy_file(status->policy_file);
    simulation.config = stored_configuration(simulation.loaded);
    simulation.plant.emplace(simulation.config, static_cast<std::uint64_t>(settings_.seed));
    simulation.sets.emplace(simulation.config);
  } catch (const std::exception& error) {
    ROS_ERROR("plant simulator: cannot simulate the policy %s: %s", status->policy_file.c_str(), error.what());
    return 1;
  }
  simulation.outline = vehicle_outline(simulation.config);
  const amytiss::Policy& policy = simulation.policy();
  const std::vector<double>& initial_state = settings_.initial_state;
  if (initial_state.size() != policy.states.dims()) {
    ROS_ERROR("plant simulator: ~initial_state has %zu values, expected %zu (x0..x%zu)", initial_state.size(),
              policy.states.dims(), policy.states.dims() - 1);
    return 1;
  }
  std::vector<double> predicted_input(policy.inputs.dims());
  double predicted = 0.0, upper = 0.0;
  if (policy.lookup(initial_state.data(), initial_state.size(), 0, predicted_input.data(), &predicted, &upper) !=
      amytiss::LookupStatus::Ok)
    predicted = upper = 0.0;
  // With guarantee: system, V_0 is the certified lower bound for the continuous system.
  const bool certified = policy.guarantee == amytiss::Guarantee::System;
  const std::string abstraction_label = std::string(" (") + amytiss::kAbstractionValueLabel + ")";
  const std::string prediction = certified ? bounds_text(predicted, upper) : "V_0 = " + format4(predicted) + abstraction_label;
  ROS_INFO("plant simulator: '%s', %d episodes from [%s], seed %d; %s", simulation.config.name.c_str(),
           settings_.episodes, join(initial_state).c_str(), settings_.seed, prediction.c_str());
  if (!wait_for_server(settings_.command_timeout_s * 4)) {
    ROS_ERROR("plant simulator: the policy server is not connected to %s / %s", state_publisher_.getTopic().c_str(),
              command_subscriber_.getTopic().c_str());
    return 1;
  }

  std::filesystem::create_directories(settings_.output_dir);
  const std::string base = settings_.output_dir + "/" + simulation.config.name;
  amytiss::EpisodeSummary summary = run_episodes(simulation, base + "_episodes.csv");
  summary.initial_state = initial_state;
  summary.predicted_probability = predicted;
  summary.success_rate = summary.episodes ? double(summary.successes) / summary.episodes : 0.0;
  const double standard_error =
      summary.episodes ? std::sqrt(summary.success_rate * (1 - summary.success_rate) / summary.episodes) : 0.0;
  const std::string at_start = certified ? prediction + " at the start state"
                                         : "predicted V_0 at the start state = " + format4(predicted) + abstraction_label;
  ROS_INFO("plant simulator: empirical success rate %u/%u = %.3f (standard error %.3f); %s", summary.successes,
           summary.episodes, summary.success_rate, standard_error, at_start.c_str());
  ROS_INFO("plant simulator: %s", certified
                                      ? bounds_consistency_text(summary.successes, summary.episodes, predicted, upper).c_str()
                                      : consistency_text(summary.successes, summary.episodes, predicted).c_str());
  if (!settings_.plot_script.empty()) draw_pictures(simulation, summary.csv_file, base, summary);
  ROS_INFO("trajectories: %s", summary.csv_file.c_str());
  summary.header.stamp = ros::Time::now();
  summary_publisher_.publish(summary);
  if (!settings_.exit_when_done) ros::waitForShutdown();
  return 0;
}

}  // namespace amytiss_ros
