#include "policy_server.hpp"

#include <visualization_msgs/MarkerArray.h>

#include "amytiss/errors.hpp"
#include "amytiss/policy_file.hpp"
#include "config_from_params.hpp"
#include "conversions.hpp"

namespace amytiss_ros {

namespace {

double wall_now() { return ros::WallTime::now().toSec(); }

double timeout_parameter(const ros::NodeHandle& private_handle) {
  double timeout_s = 3.0;
  private_handle.param("synthesizer_timeout_s", timeout_s, 3.0);
  return timeout_s;
}

}  // namespace

PolicyServerNode::PolicyServerNode(ros::NodeHandle public_handle, ros::NodeHandle private_handle)
    : public_handle_(public_handle),
      private_handle_(private_handle),
      monitor_(timeout_parameter(private_handle)),
      diagnostics_(public_handle, private_handle) {
  private_handle_.param<std::string>("frame_id", frame_id_, "map");
  command_publisher_ = public_handle_.advertise<amytiss::InputCommand>("command", 10);
  marker_publisher_ = public_handle_.advertise<visualization_msgs::MarkerArray>("markers", 1, /*latch=*/true);
  std::string initial_file;
  private_handle_.param<std::string>("policy_file", initial_file, "");
  if (!initial_file.empty()) load(initial_file);
  service_ = public_handle_.advertiseService("get_input", &PolicyServerNode::on_get_input, this);
  state_subscriber_ = public_handle_.subscribe("state", 10, &PolicyServerNode::on_state, this,
                                               ros::TransportHints().tcpNoDelay());
  status_subscriber_ = public_handle_.subscribe("status", 10, &PolicyServerNode::on_status, this);
  diagnostics_.setHardwareID("amytiss");
  diagnostics_.add("policy server", this, &PolicyServerNode::diagnose);
  diagnostics_timer_ = public_handle_.createWallTimer(ros::WallDuration(1.0),
                                                      [this](const ros::WallTimerEvent&) { diagnostics_.update(); });
}

PolicyServerNode::~PolicyServerNode() {
  std::lock_guard<std::mutex> lock(loader_mutex_);
  if (loader_thread_.joinable()) loader_thread_.join();
}

bool PolicyServerNode::load(const std::string& path) {
  try {
    amytiss::LoadedPolicy loaded = amytiss::read_policy_file(path);
    const amytiss::Config config = config_from_yaml_text(loaded.config_yaml);
    auto policy = std::make_shared<const amytiss::Policy>(std::move(loaded.policy));
    std::atomic_store(&policy_, std::shared_ptr<const amytiss::Policy>(policy));
    {
      std::lock_guard<std::mutex> lock(monitor_mutex_);
      served_ = ServedPolicy{config.name, policy->config_hash, policy->run_id, path, wall_now()};
    }
    visualization_msgs::MarkerArray markers = make_set_markers(config, frame_id_);
    for (auto& marker : markers.markers) marker.header.stamp = ros::Time::now();
    marker_publisher_.publish(markers);
    ROS_INFO("serving policy '%s' (hash %s, run %s, horizon %u, %zu cells x %zu inputs) from %s",
             config.name.c_str(), policy->config_hash.c_str(), policy->run_id.c_str(), policy->horizon,
             policy->states.size(), policy->inputs.size(), path.c_str());
    return true;
  } catch (const std::exception& error) {
    ROS_ERROR("cannot load policy %s: %s (still serving the previous policy, if any)", path.c_str(), error.what());
    return false;
  }
}

std::string PolicyServerNode::notice(bool have_policy) const {
  const std::size_t publishers = status_subscriber_.getNumPublishers();
  std::lock_guard<std::mutex> lock(monitor_mutex_);
  return have_policy ? monitor_.serving_notice(served_, wall_now(), publishers)
                     : monitor_.no_policy_reason(wall_now(), publishers);
}

bool PolicyServerNode::on_get_input(amytiss::GetInput::Request& request,
                                    amytiss::GetInput::Response& response) {
  const std::shared_ptr<const amytiss::Policy> policy = std::atomic_load(&policy_);
  fill_get_input_response(policy.get(), request.state, request.time_step, notice(policy != nullptr), response);
  // Malformed requests are answered (success false), never refused: the caller gets the message.
  return true;
}

void PolicyServerNode::on_state(const amytiss::StateStamped::ConstPtr& state) {
  const std::shared_ptr<const amytiss::Policy> policy = std::atomic_load(&policy_);
  const std::string server_notice = notice(policy != nullptr);
  std::lock_guard<std::mutex> lock(command_mutex_);
  fill_input_command(policy.get(), *state, server_notice, command_);
  command_publisher_.publish(command_);
}

void PolicyServerNode::on_status(const amytiss::PolicyStatus::ConstPtr& status) {
  {
    std::lock_guard<std::mutex> lock(monitor_mutex_);
    monitor_.on_status(*status, wall_now());
    // The pair identifies a policy across synthesizer restarts (a generation counter restarts).
    const std::string identity = status->config_hash + " " + status->run_id;
    if (!status->ready || identity == requested_identity_) return;
    requested_identity_ = identity;
  }
  // Loading a large file takes a while; requests keep being served from the old policy meanwhile.
  std::lock_guard<std::mutex> lock(loader_mutex_);
  if (loader_thread_.joinable()) loader_thread_.join();
  loader_thread_ = std::thread([this, path = status->policy_file] { load(path); });
}

void PolicyServerNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const bool have_policy = std::atomic_load(&policy_) != nullptr;
  const std::size_t publishers = status_subscriber_.getNumPublishers();
  const double now = wall_now();
  std::lock_guard<std::mutex> lock(monitor_mutex_);
  const std::string stopped = monitor_.stopped_notice(now, publishers);
  if (!have_policy)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no policy yet: " + monitor_.no_policy_reason(now, publishers));
  else if (!stopped.empty() && monitor_.ever_heard())
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, monitor_.serving_notice(served_, now, publishers));
  else
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "serving policy '" + served_.config_name + "'");
  status.add("policy loaded", have_policy);
  status.add("policy name", served_.config_name);
  status.add("policy config_hash", served_.config_hash);
  status.add("policy run_id", served_.run_id);
  status.add("policy file", served_.path);
  status.add("policy age (s)", have_policy ? now - served_.loaded_at_s : 0.0);
  status.add("synthesizer", stopped.empty() ? std::string("running") : stopped);
  status.add("synthesis phase", monitor_.last_status().phase);
  status.add("synthesis percent", monitor_.last_status().percent);
  status.add("device", monitor_.last_status().device);
}

}  // namespace amytiss_ros
