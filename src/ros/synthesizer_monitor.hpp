#pragma once
// What the policy server knows about the synthesizer, from its /amytiss/status messages and
// their heartbeat: whether it is alive, what it says, and the notice that goes with each answer.
// Pure logic (times are passed in, in seconds of the wall clock), so it is tested without a master.
#include <cstddef>
#include <string>

#include <amytiss/PolicyStatus.h>

namespace amytiss_ros {

/// The policy a server is serving: name, identity and where it came from.
struct ServedPolicy {
  std::string config_name;
  std::string config_hash;
  std::string run_id;
  std::string path;
  double loaded_at_s = 0;  // wall clock, seconds since the epoch
};

class SynthesizerMonitor {
 public:
  /// timeout_s: the synthesizer counts as stopped when no status arrived for this long (its
  /// heartbeat comes every second).
  explicit SynthesizerMonitor(double timeout_s) : timeout_s_(timeout_s) {}

  void on_status(const amytiss::PolicyStatus& status, double now_s);

  /// True after a status arrived, while statuses keep coming within the timeout and some node
  /// publishes them (publishers: the status subscription's publisher count).
  bool alive(double now_s, std::size_t publishers) const;
  bool ever_heard() const { return ever_heard_; }

  /// "" while the synthesizer is alive; otherwise "synthesizer not running since <UTC time>
  /// (no status for 12.3 s)" or "... (its status publisher is gone)", or, before any status,
  /// "waiting for the synthesizer's status on /amytiss/status".
  std::string stopped_notice(double now_s, std::size_t publishers) const;

  /// Why there is no policy: the stopped notice, or what the synthesizer says (progress, error).
  std::string no_policy_reason(double now_s, std::size_t publishers) const;

  /// The warning attached to successful answers: "" while the synthesizer is alive, otherwise
  /// "<stopped notice>; serving policy '<name>' (hash <h>, run <r>, loaded <t>)".
  std::string serving_notice(const ServedPolicy& served, double now_s, std::size_t publishers) const;

  /// The last status received (default-constructed before any).
  const amytiss::PolicyStatus& last_status() const { return last_status_; }

 private:
  double timeout_s_;
  bool ever_heard_ = false;
  double last_heard_s_ = 0;
  amytiss::PolicyStatus last_status_;
};

/// "2026-11-26 13:05:01 UTC" for a wall-clock time in seconds since the epoch.
std::string utc_time_text(double seconds);

}  // namespace amytiss_ros
