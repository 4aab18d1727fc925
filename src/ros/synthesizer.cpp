#include "synthesizer.hpp"

#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "amytiss/abstraction.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/policy_file.hpp"
#include "amytiss/refinement.hpp"
#include "config_from_params.hpp"
#include "conversions.hpp"

namespace amytiss_ros {
namespace {

// One synthesis on the configuration's grid, or refine's rounds. The abstraction's set-up (the
// footprint's test of the cells) reports progress and can be cancelled too.
amytiss::Policy synthesize_policy(const amytiss::Config& config, const amytiss::SynthesisOptions& options,
                                  amytiss::SynthesisReport& report) {
  if (config.refine) return amytiss::synthesize_refined(config, options, &report).policy;
  const amytiss::Abstraction abstraction = amytiss::Abstraction::from_config(config, options.progress);
  return amytiss::synthesize(abstraction, options, &report);
}

}  // namespace

std::string default_policy_path(const std::string& config_name) {
  std::string home;
  if (const char* ros_home = std::getenv("ROS_HOME"); ros_home && *ros_home) {
    home = ros_home;
  } else {
    const char* user_home = std::getenv("HOME");
    home = std::string(user_home ? user_home : "/tmp") + "/.ros";
  }
  std::string safe_name;
  for (char c : config_name)
    safe_name += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') ? c : '_';
  if (safe_name.empty()) safe_name = "policy";
  return home + "/amytiss/" + safe_name + ".h5";
}

SynthesizerNode::SynthesizerNode(ros::NodeHandle public_handle, ros::NodeHandle private_handle)
    : public_handle_(public_handle),
      private_handle_(private_handle),
      status_publisher_(public_handle_.advertise<amytiss::PolicyStatus>("status", 1, /*latch=*/true)),
      diagnostics_(public_handle, private_handle),
      action_server_(public_handle, "synthesize",
                     [this](const amytiss::SynthesizeGoalConstPtr& goal) { execute_goal(goal); }, false) {
  update_status([](amytiss::PolicyStatus& status) {
    status.phase = amytiss::PolicyStatus::PHASE_IDLE;
    status.remaining_s = -1;
    status.message = "synthesizer started";
  });
  double heartbeat_period_s = 1.0;
  private_handle_.param("heartbeat_period_s", heartbeat_period_s, 1.0);
  // Republishing the unchanged status is the heartbeat the policy server watches; a wall timer
  // keeps beating while a synthesis occupies the worker thread.
  heartbeat_timer_ = public_handle_.createWallTimer(ros::WallDuration(heartbeat_period_s),
                                                    [this](const ros::WallTimerEvent&) {
                                                      update_status([](amytiss::PolicyStatus&) {});
                                                      diagnostics_.update();
                                                    });
  diagnostics_.setHardwareID("amytiss");
  diagnostics_.add("synthesizer", this, &SynthesizerNode::diagnose);
}

void SynthesizerNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& diagnostic) {
  std::lock_guard<std::mutex> lock(status_mutex_);
  using diagnostic_msgs::DiagnosticStatus;
  const unsigned char level = status_.phase == amytiss::PolicyStatus::PHASE_ERROR       ? DiagnosticStatus::ERROR
                              : status_.phase == amytiss::PolicyStatus::PHASE_CANCELLED ? DiagnosticStatus::WARN
                                                                                             : DiagnosticStatus::OK;
  diagnostic.summary(level, status_.phase + ": " + status_.message);
  diagnostic.add("policy ready", bool(status_.ready));
  diagnostic.add("synthesizing", bool(status_.synthesizing));
  diagnostic.add("percent", status_.percent);
  diagnostic.add("device", status_.device);
  diagnostic.add("config name", status_.config_name);
  diagnostic.add("config_hash", status_.config_hash);
  diagnostic.add("run_id", status_.run_id);
  diagnostic.add("policy file", status_.policy_file);
  diagnostic.add("syntheses run", status_.syntheses_run);
}

SynthesizerNode::~SynthesizerNode() { shutdown(); }

void SynthesizerNode::start() {
  action_server_.start();
  bool synthesize_on_start = true;
  private_handle_.param("synthesize_on_start", synthesize_on_start, true);
  if (!synthesize_on_start) return;
  startup_thread_ = std::thread([this] {
    std::lock_guard<std::mutex> job_lock(job_mutex_);
    if (stopping_) return;
    run_from_source([this] { return read_parameters(); }, /*force=*/false,
                    [this] { return stopping_.load() || cancel_startup_job_.load() || !ros::ok(); },
                    [](const amytiss::Progress&) {});
  });
}

void SynthesizerNode::shutdown() {
  if (stopping_.exchange(true)) return;
  heartbeat_timer_.stop();
  // Joins the action thread: its goal, if any, sees stopping_ at its next progress report.
  action_server_.shutdown();
  if (startup_thread_.joinable()) startup_thread_.join();
  update_status([](amytiss::PolicyStatus& status) {
    status.synthesizing = false;
    status.remaining_s = -1;
    status.message = "synthesizer stopped";
  });
}

amytiss::Config SynthesizerNode::read_parameters() const {
  XmlRpc::XmlRpcValue tree;
  // Uncached on purpose: a new goal must see parameters set since the last one.
  if (!ros::param::get(private_handle_.getNamespace(), tree)) tree = XmlRpc::XmlRpcValue();
  std::string device;
  private_handle_.param<std::string>("device", device, "");
  return config_from_params(tree, device);
}

std::string SynthesizerNode::policy_path_for(const amytiss::Config& config) const {
  std::string path;
  private_handle_.param<std::string>("policy_file", path, "");
  if (path.empty()) path = default_policy_path(config.name);
  return std::filesystem::absolute(path).lexically_normal().string();
}

void SynthesizerNode::update_status(const std::function<void(amytiss::PolicyStatus&)>& edit) {
  std::lock_guard<std::mutex> lock(status_mutex_);
  edit(status_);
  status_.header.stamp = ros::Time::now();
  status_publisher_.publish(status_);
}

SynthesizerNode::Outcome SynthesizerNode::run_from_source(const std::function<amytiss::Config()>& read_config,
                                                          bool force, const CancelCheck& cancelled,
                                                          const ProgressSink& on_progress) {
  amytiss::Config config;
  try {
    config = read_config();
  } catch (const std::exception& error) {
    Outcome outcome;
    outcome.message = std::string("invalid configuration: ") + error.what();
    ROS_ERROR("%s (still serving the last good policy, if any)", outcome.message.c_str());
    report_stopped(amytiss::PolicyStatus::PHASE_ERROR, outcome.message);
    return outcome;
  }
  return run(config, force, cancelled, on_progress);
}

SynthesizerNode::Outcome SynthesizerNode::run(const amytiss::Config& config, bool force,
                                              const CancelCheck& cancelled, const ProgressSink& on_progress) {
  Outcome outcome;
  try {
    outcome.policy_file = policy_path_for(config);
  } catch (const std::exception& error) {
    outcome.message = std::string("bad policy_file parameter: ") + error.what();
    ROS_ERROR("%s", outcome.message.c_str());
    report_stopped(amytiss::PolicyStatus::PHASE_ERROR, outcome.message);
    return outcome;
  }
  if (!force && reuse_existing(config, outcome)) return outcome;
  try {
    synthesize_and_write(config, cancelled, on_progress, outcome);
  } catch (const amytiss::Cancelled&) {
    outcome.message = "synthesis of '" + config.name + "' cancelled; still serving the last good policy";
    ROS_WARN("%s", outcome.message.c_str());
    report_stopped(amytiss::PolicyStatus::PHASE_CANCELLED, outcome.message);
  } catch (const std::exception& error) {
    outcome.message = "synthesis of '" + config.name + "' failed: " + error.what();
    ROS_ERROR("%s (still serving the last good policy, if any)", outcome.message.c_str());
    report_stopped(amytiss::PolicyStatus::PHASE_ERROR, outcome.message);
  }
  return outcome;
}

bool SynthesizerNode::reuse_existing(const amytiss::Config& config, Outcome& outcome) {
  if (!std::filesystem::exists(outcome.policy_file)) return false;
  try {
    const amytiss::LoadedPolicy loaded = amytiss::read_policy_file_for(outcome.policy_file, config);
    outcome.success = true;
    outcome.reused = true;
    outcome.message = "reusing " + outcome.policy_file + " (configuration '" + config.name + "' unchanged, hash " +
                      amytiss::config_hash(config) + "); nothing to synthesize";
    ROS_INFO("%s", outcome.message.c_str());
    announce(config, loaded.policy, outcome, amytiss::PolicyStatus::PHASE_REUSED);
    return true;
  } catch (const amytiss::PolicyFileError& error) {
    ROS_WARN("not reusing %s: %s; computing it again", outcome.policy_file.c_str(), error.what());
    return false;
  }
}

void SynthesizerNode::synthesize_and_write(const amytiss::Config& config, const CancelCheck& cancelled,
                                           const ProgressSink& on_progress, Outcome& outcome) {
  const std::string device = amytiss::to_string(config.compute.device);
  ROS_INFO("synthesizing '%s' (hash %s, horizon %u) on device %s -> %s", config.name.c_str(),
           amytiss::config_hash(config).c_str(), config.spec.horizon, device.c_str(), outcome.policy_file.c_str());
  update_status([&](amytiss::PolicyStatus& status) {
    status.synthesizing = true;
    status.percent = 0.0;
    status.phase = amytiss::PolicyStatus::PHASE_SETUP;
    status.device = device;
    status.remaining_s = -1;
    status.message = "synthesizing '" + config.name + "' on " + device;
  });
  const auto started = std::chrono::steady_clock::now();
  amytiss::SynthesisOptions options;
  options.compute = config.compute;
  options.progress = [&](const amytiss::Progress& progress) {
    const std::string text = describe_progress(progress);
    ROS_INFO("%s", text.c_str());
    update_status([&](amytiss::PolicyStatus& status) {
      status.synthesizing = true;
      status.percent = progress.percent();
      status.phase = amytiss::to_string(progress.phase);
      status.device = progress.device;
      status.remaining_s = progress.remaining_s;
      status.message = text;
    });
    on_progress(progress);
    return !cancelled();
  };
  amytiss::SynthesisReport report;
  const amytiss::Policy policy = synthesize_policy(config, options, report);
  for (const auto& note : report.notes) {
    if (note.severity == amytiss::NoteSeverity::Warning)
      ROS_WARN("%s", note.text.c_str());
    else
      ROS_INFO("%s", note.text.c_str());
  }
  if (cancelled()) throw amytiss::Cancelled();
  // Not cancellable from here on: the file is written whole to a temporary and renamed.
  update_status([&](amytiss::PolicyStatus& status) { status.message = "writing " + outcome.policy_file; });
  std::filesystem::create_directories(std::filesystem::path(outcome.policy_file).parent_path());
  amytiss::write_policy_file(outcome.policy_file, policy, config);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const amytiss::ValueSummary summary = amytiss::summarize_initial_values(policy);
  char text[512];
  std::snprintf(text, sizeof text,
                "new policy '%s' synthesized in %.2f s on %s: V_0 over free cells min %.4f mean %.4f "
                "max %.4f; written to %s",
                config.name.c_str(), seconds, policy.computed_by.c_str(), summary.min, summary.mean, summary.max,
                outcome.policy_file.c_str());
  outcome.success = true;
  outcome.message = text;
  ROS_INFO("%s", text);
  announce(config, policy, outcome, amytiss::PolicyStatus::PHASE_DONE);
}

void SynthesizerNode::announce(const amytiss::Config& config, const amytiss::Policy& policy, const Outcome& outcome,
                               const std::string& phase) {
  // An unbounded run whose bounds did not meet says so wherever the policy is announced.
  const std::string convergence = convergence_notice(policy);
  update_status([&](amytiss::PolicyStatus& status) {
    status.ready = true;
    status.synthesizing = false;
    status.percent = 100.0;
    status.phase = phase;
    status.device = policy.computed_by;
    status.remaining_s = 0.0;
    status.message = convergence.empty() ? outcome.message : outcome.message + "; " + convergence;
    status.config_name = config.name;
    status.config_hash = amytiss::config_hash(config);
    status.policy_file = outcome.policy_file;
    status.horizon = policy.horizon;
    status.guarantee = amytiss::to_string(policy.guarantee);
    status.run_id = policy.run_id;
    status.generation += 1;
    if (phase == amytiss::PolicyStatus::PHASE_DONE) status.syntheses_run += 1;
  });
}

void SynthesizerNode::report_stopped(const std::string& phase, const std::string& message) {
  update_status([&](amytiss::PolicyStatus& status) {
    status.synthesizing = false;
    status.phase = phase;
    status.remaining_s = -1;
    status.message = message;
  });
}

void SynthesizerNode::execute_goal(const amytiss::SynthesizeGoalConstPtr& goal) {
  cancel_startup_job_ = true;
  std::lock_guard<std::mutex> job_lock(job_mutex_);
  if (stopping_) {
    amytiss::SynthesizeResult result;
    result.message = "the synthesizer is shutting down";
    action_server_.setAborted(result, result.message);
    return;
  }
  // Marks the start of this goal on the status stream, so that its outcome is told apart from
  // an equal outcome of the previous goal.
  update_status([](amytiss::PolicyStatus& status) { status.message = "new goal: reading its configuration"; });
  const auto read_config = [&]() {
    if (goal->config_yaml.empty()) return read_parameters();
    std::string device;
    private_handle_.param<std::string>("device", device, "");
    return config_from_yaml_text(goal->config_yaml, device);
  };
  const Outcome outcome = run_from_source(
      read_config, goal->force,
      [this] { return stopping_.load() || action_server_.isPreemptRequested() || !ros::ok(); },
      [this](const amytiss::Progress& progress) { action_server_.publishFeedback(feedback_from_progress(progress)); });
  amytiss::SynthesizeResult result;
  result.success = outcome.success;
  result.message = outcome.message;
  result.policy_file = outcome.success ? outcome.policy_file : "";
  result.reused = outcome.reused;
  if (outcome.success)
    action_server_.setSucceeded(result, outcome.message);
  else if (action_server_.isPreemptRequested())
    action_server_.setPreempted(result, outcome.message);
  else
    action_server_.setAborted(result, outcome.message);
}

}  // namespace amytiss_ros
