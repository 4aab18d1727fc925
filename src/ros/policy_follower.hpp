#pragma once
// Which policy file the policy server loads, from the synthesizer's statuses, and what it does
// when a file is refused (missing, corrupt, not a policy, or another policy than the one the
// status announces): it retries the file after a while and asks the synthesizer to compute it
// again, so a damaged or replaced file heals without a person.
// Pure logic (times are passed in, in seconds of the wall clock), tested without a master.
#include <optional>
#include <string>

#include <amytiss/PolicyStatus.h>

namespace amytiss_ros {

/// "<config_hash> <run_id>": identifies a policy across synthesizer restarts (the status's
/// generation counter restarts with the node).
std::string policy_identity(const std::string& config_hash, const std::string& run_id);

/// A policy file to load and the identity its status announced (all empty for ~policy_file at
/// start, before any status: any valid policy file is served then).
struct LoadJob {
  std::string path;
  std::string identity;  ///< policy_identity(config_hash, run_id)
  std::string config_hash;
  std::string run_id;
};

/// Why the policy read from job.path is not the one its status announced: "" when it is (or the
/// job announces none), otherwise "it holds the policy of hash <h> (run <r>), not the announced
/// one, hash <h'> (run <r'>)".
std::string identity_mismatch(const LoadJob& job, const std::string& file_config_hash, const std::string& file_run_id);

class PolicyFollower {
 public:
  /// retry_period_s: a refused file announced again (same identity) is read again after this long.
  explicit PolicyFollower(double retry_period_s) : retry_period_s_(retry_period_s) {}

  /// The load a status calls for: none while the status is not ready, names the policy served or
  /// being loaded, or names a file refused less than retry_period_s ago. A returned job counts as
  /// started until loaded() or refused().
  std::optional<LoadJob> on_status(const amytiss::PolicyStatus& status, double now_s);

  /// The file of `job` was loaded; `served_identity` is the identity read from the file itself.
  void loaded(const std::string& served_identity);
  /// The file of `job` was refused for `reason` (the reader's error message, identity_mismatch()).
  /// Returns whether to stop serving the policy served now: one no status has announced (read
  /// from ~policy_file at start) gives way to the announced one, so that the server answers "no
  /// policy" rather than serve a policy the synthesizer does not stand behind; a policy once
  /// announced stays served until the next one loads.
  bool refused(const LoadJob& job, const std::string& reason, double now_s);

  /// Whether to ask the synthesizer to compute the refused policy again now: a refusal is
  /// pending, the synthesizer still announces the refused identity and is not synthesizing
  /// (a goal would cancel a running synthesis), and no request was made since the last refusal
  /// (a file refused again at a retry may ask again).
  /// A true answer counts as the request.
  bool take_synthesis_request(const amytiss::PolicyStatus& latest);

  /// "" when no refusal is pending, otherwise "policy file <path> refused (<reason>); asked the
  /// synthesizer to compute it again" (or "...; waiting for the synthesizer").
  std::string refusal_notice() const;

 private:
  double retry_period_s_;
  std::string served_identity_;
  bool served_announced_ = false;   // a ready status named served_identity_
  std::string announced_identity_;  // of the latest ready status
  std::string loading_identity_;
  // The pending refusal: cleared when a policy is loaded.
  std::optional<LoadJob> refused_;
  std::string refusal_reason_;
  double refused_at_s_ = 0;
  bool synthesis_requested_ = false;
};

}  // namespace amytiss_ros
