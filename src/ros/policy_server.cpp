#include "policy_server.hpp"

#include <visualization_msgs/MarkerArray.h>

#include "amytiss/errors.hpp"
#include "amytiss/policy_file.hpp"
#include "config_from_params.hpp"
#include "conversions.hpp"

namespace amytiss_ros {

PolicyServerNode::PolicyServerNode(ros::NodeHandle public_handle, ros::NodeHandle private_handle)
    : public_handle_(public_handle), private_handle_(private_handle) {
  private_handle_.param<std::string>("frame_id", frame_id_, "map");
  command_publisher_ = public_handle_.advertise<amytiss::InputCommand>("command", 10);
  marker_publisher_ = public_handle_.advertise<visualization_msgs::MarkerArray>("markers", 1, /*latch=*/true);
  std::string initial_file;
  private_handle_.param<std::string>("policy_file", initial_file, "");
  if (!initial_file.empty()) load(initial_file, 0);
  service_ = public_handle_.advertiseService("get_input", &PolicyServerNode::on_get_input, this);
  state_subscriber_ = public_handle_.subscribe("state", 10, &PolicyServerNode::on_state, this,
                                               ros::TransportHints().tcpNoDelay());
  status_subscriber_ = public_handle_.subscribe("status", 10, &PolicyServerNode::on_status, this);
}

PolicyServerNode::~PolicyServerNode() {
  std::lock_guard<std::mutex> lock(loader_mutex_);
  if (loader_thread_.joinable()) loader_thread_.join();
}

bool PolicyServerNode::load(const std::string& path, unsigned generation) {
  try {
    amytiss::LoadedPolicy loaded = amytiss::read_policy_file(path);
    const amytiss::Config config = config_from_yaml_text(loaded.config_yaml);
    auto policy = std::make_shared<const amytiss::Policy>(std::move(loaded.policy));
    std::atomic_store(&policy_, std::shared_ptr<const amytiss::Policy>(policy));
    loaded_generation_ = generation;
    visualization_msgs::MarkerArray markers = make_set_markers(config, frame_id_);
    for (auto& marker : markers.markers) marker.header.stamp = ros::Time::now();
    marker_publisher_.publish(markers);
    ROS_INFO("serving policy '%s' (hash %s, horizon %u, %zu cells x %zu inputs) from %s", config.name.c_str(),
             loaded.config_hash.c_str(), policy->horizon, policy->states.size(), policy->inputs.size(),
             path.c_str());
    return true;
  } catch (const std::exception& error) {
    ROS_ERROR("cannot load policy %s: %s (still serving the previous policy, if any)", path.c_str(), error.what());
    std::lock_guard<std::mutex> lock(reason_mutex_);
    synthesizer_message_ = std::string("the policy file could not be loaded: ") + error.what();
    return false;
  }
}

std::string PolicyServerNode::no_policy_reason() const {
  std::lock_guard<std::mutex> lock(reason_mutex_);
  return synthesizer_message_;
}

bool PolicyServerNode::on_get_input(amytiss::GetInput::Request& request, amytiss::GetInput::Response& response) {
  const std::shared_ptr<const amytiss::Policy> policy = std::atomic_load(&policy_);
  fill_get_input_response(policy.get(), request.state, request.time_step,
                          policy ? std::string() : no_policy_reason(), response);
  // Malformed requests are answered (success false), never refused: the caller gets the message.
  return true;
}

void PolicyServerNode::on_state(const amytiss::StateStamped::ConstPtr& state) {
  const std::shared_ptr<const amytiss::Policy> policy = std::atomic_load(&policy_);
  std::lock_guard<std::mutex> lock(command_mutex_);
  fill_input_command(policy.get(), *state, policy ? std::string() : no_policy_reason(), command_);
  command_publisher_.publish(command_);
}

void PolicyServerNode::on_status(const amytiss::PolicyStatus::ConstPtr& status) {
  {
    std::lock_guard<std::mutex> lock(reason_mutex_);
    if (status->synthesizing) {
      char text[64];
      std::snprintf(text, sizeof text, "synthesis is running (%.0f%%): ", status->percent);
      synthesizer_message_ = text + status->message;
    } else {
      synthesizer_message_ = "synthesizer says: " + status->message;
    }
  }
  if (!status->ready || status->generation == requested_generation_.load()) return;
  requested_generation_ = status->generation;
  // Loading a large file takes a while; requests keep being served from the old policy meanwhile.
  std::lock_guard<std::mutex> lock(loader_mutex_);
  if (loader_thread_.joinable()) loader_thread_.join();
  loader_thread_ = std::thread([this, path = status->policy_file, generation = status->generation] {
    load(path, generation);
  });
}

}  // namespace amytiss_ros
