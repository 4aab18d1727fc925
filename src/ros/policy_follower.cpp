#include "policy_follower.hpp"

namespace amytiss_ros {

std::string policy_identity(const std::string& config_hash, const std::string& run_id) {
  return config_hash + " " + run_id;
}

std::string identity_mismatch(const LoadJob& job, const std::string& file_config_hash, const std::string& file_run_id) {
  if (job.identity.empty() || policy_identity(file_config_hash, file_run_id) == job.identity) return "";
  return "it holds the policy of hash " + file_config_hash + " (run " + file_run_id +
         "), not the announced one, hash " + job.config_hash + " (run " + job.run_id + ")";
}

std::optional<LoadJob> PolicyFollower::on_status(const amytiss::PolicyStatus& status, double now_s) {
  if (!status.ready) return std::nullopt;
  const std::string identity = policy_identity(status.config_hash, status.run_id);
  announced_identity_ = identity;
  if (identity == served_identity_) served_announced_ = true;
  if (identity == served_identity_ || identity == loading_identity_) return std::nullopt;
  if (refused_ && refused_->identity == identity && now_s - refused_at_s_ < retry_period_s_) return std::nullopt;
  loading_identity_ = identity;
  return LoadJob{status.policy_file, identity, status.config_hash, status.run_id};
}

void PolicyFollower::loaded(const std::string& served_identity) {
  served_identity_ = served_identity;
  served_announced_ = served_identity == announced_identity_;
  loading_identity_.clear();
  refused_.reset();
  synthesis_requested_ = false;
}

bool PolicyFollower::refused(const LoadJob& job, const std::string& reason, double now_s) {
  if (loading_identity_ == job.identity) loading_identity_.clear();
  // Each refusal may ask once: a recomputation that failed is asked for again at the next retry.
  synthesis_requested_ = false;
  refused_ = job;
  refusal_reason_ = reason;
  refused_at_s_ = now_s;
  if (served_identity_.empty() || served_announced_ || job.identity.empty()) return false;
  served_identity_.clear();
  return true;
}

bool PolicyFollower::take_synthesis_request(const amytiss::PolicyStatus& latest) {
  if (!refused_ || synthesis_requested_ || latest.synthesizing || !latest.ready) return false;
  if (policy_identity(latest.config_hash, latest.run_id) != refused_->identity) return false;
  synthesis_requested_ = true;
  return true;
}

std::string PolicyFollower::refusal_notice() const {
  if (!refused_) return "";
  return "policy file " + refused_->path + " refused (" + refusal_reason_ + "); " +
         (synthesis_requested_ ? "asked the synthesizer to compute it again" : "waiting for the synthesizer");
}

}  // namespace amytiss_ros
