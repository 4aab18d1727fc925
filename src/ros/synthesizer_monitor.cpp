#include "synthesizer_monitor.hpp"

#include <cstdio>
#include <ctime>

namespace amytiss_ros {

std::string utc_time_text(double seconds) {
  const std::time_t whole = static_cast<std::time_t>(seconds);
  std::tm parts{};
  gmtime_r(&whole, &parts);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", &parts);
  return text;
}

void SynthesizerMonitor::on_status(const amytiss::PolicyStatus& status, double now_s) {
  ever_heard_ = true;
  last_heard_s_ = now_s;
  last_status_ = status;
}

bool SynthesizerMonitor::alive(double now_s, std::size_t publishers) const {
  return ever_heard_ && publishers > 0 && now_s - last_heard_s_ <= timeout_s_;
}

std::string SynthesizerMonitor::stopped_notice(double now_s, std::size_t publishers) const {
  if (!ever_heard_) return "waiting for the synthesizer's status on /amytiss/status";
  if (alive(now_s, publishers)) return "";
  char why[96];
  if (publishers == 0)
    std::snprintf(why, sizeof why, "its status publisher is gone");
  else
    std::snprintf(why, sizeof why, "no status for %.1f s", now_s - last_heard_s_);
  return "synthesizer not running since " + utc_time_text(last_heard_s_) + " (" + why + ")";
}

std::string SynthesizerMonitor::no_policy_reason(double now_s, std::size_t publishers) const {
  const std::string stopped = stopped_notice(now_s, publishers);
  if (!stopped.empty()) return stopped;
  if (last_status_.synthesizing) {
    char text[64];
    std::snprintf(text, sizeof text, "synthesis is running (%.0f%%): ", last_status_.percent);
    return text + last_status_.message;
  }
  return "synthesizer says: " + last_status_.message;
}

std::string SynthesizerMonitor::serving_notice(const ServedPolicy& served, double now_s,
                                               std::size_t publishers) const {
  if (!ever_heard_) return "";  // serving a file given at start, no synthesizer expected yet
  const std::string stopped = stopped_notice(now_s, publishers);
  if (stopped.empty()) return "";
  return stopped + "; serving policy '" + served.config_name + "' (hash " + served.config_hash + ", run " +
         served.run_id + ", loaded " + utc_time_text(served.loaded_at_s) + ")";
}

}  // namespace amytiss_ros
