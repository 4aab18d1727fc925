#include "policy_server.hpp"

#include <visualization_msgs/MarkerArray.h>

#include "amytiss/policy_file.hpp"
#include "checked_get_input.hpp"
#include "conversions.hpp"

namespace amytiss_ros {

namespace {

// The notices' "no status for 3.4 s" and the stopped state are this fresh at most.
constexpr double kNoticeRefreshPeriodSeconds = 0.25;
// get_input calls answered on the network thread between two of its polls; the next ones go to the
// spinner threads (see ImmediateCallbackQueue). More than the connections one poll usually finds
// ready, so that only a connection read on and on is handed over.
constexpr std::size_t kImmediateCallsPerPoll = 8;
// How long a load waits for the synthesizer's action server before asking it to recompute.
constexpr double kSynthesisServerWaitSeconds = 5.0;

double wall_now() { return ros::WallTime::now().toSec(); }

double double_parameter(const ros::NodeHandle& private_handle, const std::string& name, double fallback) {
  double value = fallback;
  private_handle.param(name, value, fallback);
  return value;
}

}  // namespace

PolicyServerNode::PolicyServerNode(ros::NodeHandle public_handle, ros::NodeHandle private_handle)
    : public_handle_(public_handle),
      private_handle_(private_handle),
      service_queue_(*ros::getGlobalCallbackQueue(), kImmediateCallsPerPoll),
      notices_(std::make_shared<const Notices>()),
      monitor_(double_parameter(private_handle, "synthesizer_timeout_s", 3.0)),
      follower_(double_parameter(private_handle, "retry_period_s", 5.0)),
      synthesis_client_(public_handle, "synthesize", /*spin_thread=*/false),
      diagnostics_(public_handle, private_handle) {
  private_handle_.param<std::string>("frame_id", frame_id_, "map");
  command_publisher_ = public_handle_.advertise<amytiss::InputCommand>("command", 10);
  marker_publisher_ = public_handle_.advertise<visualization_msgs::MarkerArray>("markers", 1, /*latch=*/true);
  std::string initial_file;
  private_handle_.param<std::string>("policy_file", initial_file, "");
  if (!initial_file.empty()) load(LoadJob{initial_file, "", "", ""});
  refresh_notices();
  ros::AdvertiseServiceOptions service_options = checked_get_input_options(
      "get_input", [this](amytiss::GetInput::Request& request, amytiss::GetInput::Response& response) {
        return on_get_input(request, response);
      });
  // A call reads two atomics and looks up one cell: far cheaper than the hand-offs between the
  // network thread and a spinner thread, which were most of the server's CPU time per call.
  service_options.callback_queue = &service_queue_;
  service_ = public_handle_.advertiseService(service_options);
  state_subscriber_ = public_handle_.subscribe("state", 10, &PolicyServerNode::on_state, this,
                                               ros::TransportHints().tcpNoDelay());
  status_subscriber_ = public_handle_.subscribe("status", 10, &PolicyServerNode::on_status, this);
  diagnostics_.setHardwareID("amytiss");
  diagnostics_.add("policy server", this, &PolicyServerNode::diagnose);
  diagnostics_timer_ = public_handle_.createWallTimer(ros::WallDuration(1.0),
                                                      [this](const ros::WallTimerEvent&) { diagnostics_.update(); });
  notices_timer_ = public_handle_.createWallTimer(ros::WallDuration(kNoticeRefreshPeriodSeconds),
                                                  [this](const ros::WallTimerEvent&) { refresh_notices(); });
}

PolicyServerNode::~PolicyServerNode() {
  std::lock_guard<std::mutex> lock(loader_mutex_);
  if (loader_thread_.joinable()) loader_thread_.join();
}

void PolicyServerNode::load(const LoadJob& job) {
  try {
    amytiss::LoadedPolicy loaded = amytiss::read_policy_file(job.path);
    const std::string mismatch = identity_mismatch(job, loaded.policy.config_hash, loaded.policy.run_id);
    if (!mismatch.empty()) return refuse(job, mismatch);
    serve(job, std::move(loaded));
  } catch (const std::exception& error) {
    refuse(job, error.what());
  }
}

void PolicyServerNode::serve(const LoadJob& job, amytiss::LoadedPolicy loaded) {
  const MarkedSets sets = marked_sets_from_yaml(loaded.config_yaml);
  auto policy = std::make_shared<const amytiss::Policy>(std::move(loaded.policy));
  std::atomic_store(&policy_, std::shared_ptr<const amytiss::Policy>(policy));
  {
    std::lock_guard<std::mutex> lock(monitor_mutex_);
    served_ = ServedPolicy{sets.config_name, policy->config_hash, policy->run_id, job.path, wall_now()};
    convergence_notice_ = convergence_notice(*policy);
    follower_.loaded(policy_identity(policy->config_hash, policy->run_id));
  }
  refresh_notices();
  visualization_msgs::MarkerArray markers = make_set_markers(policy->states, sets, frame_id_);
  for (auto& marker : markers.markers) marker.header.stamp = ros::Time::now();
  marker_publisher_.publish(markers);
  ROS_INFO("serving policy '%s' (hash %s, run %s, horizon %u, %zu cells x %zu inputs) from %s",
           sets.config_name.c_str(), policy->config_hash.c_str(), policy->run_id.c_str(), policy->horizon,
           policy->states.size(), policy->inputs.size(), job.path.c_str());
}

void PolicyServerNode::refuse(const LoadJob& job, const std::string& reason) {
  bool ask = false, withdrawn = false;
  {
    std::lock_guard<std::mutex> lock(monitor_mutex_);
    withdrawn = follower_.refused(job, reason, wall_now());
    if (withdrawn) {
      std::atomic_store(&policy_, std::shared_ptr<const amytiss::Policy>());
      served_ = ServedPolicy{};
      convergence_notice_.clear();
    }
    ask = follower_.take_synthesis_request(monitor_.last_status());
  }
  ROS_ERROR("cannot load policy %s: %s (%s)", job.path.c_str(), reason.c_str(),
            withdrawn ? "no longer serving the policy read from ~policy_file: no status announces it"
                      : "still serving the previous policy, if any");
  if (ask) request_synthesis();
  refresh_notices();
}

void PolicyServerNode::request_synthesis() {
  // Runs on the loader thread, never in a callback, so waiting here does not stall the spinner.
  if (!synthesis_client_.waitForServer(ros::Duration(kSynthesisServerWaitSeconds))) {
    ROS_ERROR("the refused policy cannot be recomputed: no synthesizer action server at %s within %.0f s",
              public_handle_.resolveName("synthesize").c_str(), kSynthesisServerWaitSeconds);
    return;
  }
  amytiss::SynthesizeGoal goal;  // empty config_yaml: the synthesizer's own parameters
  goal.force = true;
  synthesis_client_.sendGoal(goal);
  ROS_WARN("asked the synthesizer to compute the refused policy again");
}

void PolicyServerNode::refresh_notices() {
  auto notices = std::make_shared<Notices>();
  const std::size_t publishers = status_subscriber_.getNumPublishers();
  const double now = wall_now();
  {
    std::lock_guard<std::mutex> lock(monitor_mutex_);
    const std::string refusal = follower_.refusal_notice();
    notices->no_policy = refusal.empty() ? monitor_.no_policy_reason(now, publishers) : refusal;
    for (const std::string& part : {convergence_notice_, refusal, monitor_.serving_notice(served_, now, publishers)})
      if (!part.empty()) notices->serving += (notices->serving.empty() ? "" : "; ") + part;
    // Stored under the lock, so a refresh that read older state cannot overwrite a newer one.
    std::atomic_store(&notices_, std::shared_ptr<const Notices>(std::move(notices)));
  }
}

const std::string& PolicyServerNode::notice_for(const std::shared_ptr<const amytiss::Policy>& policy,
                                                const std::shared_ptr<const Notices>& notices) const {
  return policy ? notices->serving : notices->no_policy;
}

bool PolicyServerNode::on_get_input(amytiss::GetInput::Request& request, amytiss::GetInput::Response& response) {
  const std::shared_ptr<const amytiss::Policy> policy = std::atomic_load(&policy_);
  const std::shared_ptr<const Notices> notices = std::atomic_load(&notices_);
  fill_get_input_response(policy.get(), request.state, request.time_step, notice_for(policy, notices), response);
  // Malformed requests are answered (success false), never refused: the caller gets the message.
  return true;
}

void PolicyServerNode::on_state(const amytiss::StateStamped::ConstPtr& state) {
  const std::shared_ptr<const amytiss::Policy> policy = std::atomic_load(&policy_);
  const std::shared_ptr<const Notices> notices = std::atomic_load(&notices_);
  std::lock_guard<std::mutex> lock(command_mutex_);
  fill_input_command(policy.get(), *state, notice_for(policy, notices), command_);
  command_publisher_.publish(command_);
}

void PolicyServerNode::on_status(const amytiss::PolicyStatus::ConstPtr& status) {
  std::optional<LoadJob> job;
  {
    std::lock_guard<std::mutex> lock(monitor_mutex_);
    monitor_.on_status(*status, wall_now());
    job = follower_.on_status(*status, wall_now());
  }
  refresh_notices();
  if (job) start_load(*job);
}

void PolicyServerNode::start_load(const LoadJob& job) {
  // Loading a large file takes a while; requests keep being served from the old policy meanwhile.
  std::lock_guard<std::mutex> lock(loader_mutex_);
  if (loader_thread_.joinable()) loader_thread_.join();
  loader_thread_ = std::thread([this, job] { load(job); });
}

void PolicyServerNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const bool have_policy = std::atomic_load(&policy_) != nullptr;
  const std::size_t publishers = status_subscriber_.getNumPublishers();
  const double now = wall_now();
  std::lock_guard<std::mutex> lock(monitor_mutex_);
  const std::string stopped = monitor_.stopped_notice(now, publishers);
  const std::string refusal = follower_.refusal_notice();
  using diagnostic_msgs::DiagnosticStatus;
  if (!refusal.empty())
    status.summary(DiagnosticStatus::ERROR, refusal);
  else if (!have_policy)
    status.summary(DiagnosticStatus::WARN, "no policy yet: " + monitor_.no_policy_reason(now, publishers));
  else if (!stopped.empty() && monitor_.ever_heard())
    status.summary(DiagnosticStatus::WARN, monitor_.serving_notice(served_, now, publishers));
  else
    status.summary(DiagnosticStatus::OK, "serving policy '" + served_.config_name + "'");
  status.add("policy loaded", have_policy);
  status.add("policy name", served_.config_name);
  status.add("policy config_hash", served_.config_hash);
  status.add("policy run_id", served_.run_id);
  status.add("policy file", served_.path);
  status.add("policy age (s)", have_policy ? now - served_.loaded_at_s : 0.0);
  status.add("policy convergence", convergence_notice_.empty() ? std::string("converged") : convergence_notice_);
  status.add("refused policy file", refusal);
  status.add("announced config_hash", monitor_.last_status().config_hash);
  status.add("announced run_id", monitor_.last_status().run_id);
  status.add("synthesizer", stopped.empty() ? std::string("running") : stopped);
  status.add("synthesis phase", monitor_.last_status().phase);
  status.add("synthesis percent", monitor_.last_status().percent);
  status.add("device", monitor_.last_status().device);
  status.add("get_input calls answered on the network thread", service_queue_.immediate_count());
  status.add("get_input calls answered on a spinner thread", service_queue_.overflow_count());
}

}  // namespace amytiss_ros
