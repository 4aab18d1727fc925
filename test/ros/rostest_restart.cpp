// rostest: nodes that die. A synthesizer killed mid-run (SIGKILL, no goodbye): the server keeps
// serving the last policy and says the synthesizer is gone; a new synthesizer started with
// another configuration restarts its generation at 1, as the killed one had announced only one
// policy, and the server still follows it, by (config_hash, run_id), without any goal. A policy
// server killed and restarted while the policy file is damaged: it refuses the file, the
// synthesizer computes the policy again and the server serves it, without any goal from outside.
// A policy server restarted with a valid policy file of another configuration in the announced
// file's place: it refuses the file, answers no and names both hashes, and asks for the
// announced policy.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>

#include <diagnostic_msgs/DiagnosticArray.h>

#include "amytiss/errors.hpp"
#include "amytiss/policy_file.hpp"
#include "rostest_fixture.hpp"
#include "rostest_nodes.hpp"

namespace {

constexpr double kNoticeWaitSeconds = 20.0;  // the server's synthesizer_timeout_s is 2
const std::string kSynthesizer = "/amytiss/synthesizer";
const std::string kServer = "/amytiss/policy_server";

class RestartTest : public amytiss_test::SynthesizerAndServerTest {
 protected:
  /// The nodes a test started stay up for the next test (each test needs a synthesizer and a
  /// server); they stop after the last one, and this run's policy file (restart.test names it
  /// with $(anon ...)) is removed.
  static void TearDownTestSuite() {
    for (const pid_t pid : spawned_) amytiss_test::stop_node(pid);
    spawned_.clear();
    if (!policy_file_.empty()) std::remove(policy_file_.c_str());
  }
  static pid_t spawn(const std::vector<std::string>& arguments) {
    const pid_t pid = amytiss_test::spawn_node(arguments);
    if (pid > 0) spawned_.push_back(pid);
    return pid;
  }
  /// The status that holds `condition`, waited for (bounded); the default status when none did.
  amytiss::PolicyStatus wait_for_status(const std::function<bool(const amytiss::PolicyStatus&)>& condition,
                                        double seconds) {
    amytiss::PolicyStatus matched;
    status_.wait_for(
        [&](const amytiss::PolicyStatus& s) {
          if (!condition(s)) return false;
          matched = s;
          return true;
        },
        seconds);
    return matched;
  }
  /// GetInput at the default state of a restarted server: a new connection when the call fails
  /// (the old one died with the old server).
  amytiss::GetInput::Response call_reconnecting() {
    amytiss::GetInput service;
    service.request.state = {-4.0, -4.0};
    if (!client_.call(service))
      client_ = handle_.serviceClient<amytiss::GetInput>("/amytiss/get_input", /*persistent=*/true);
    return service.response;
  }
  void compute_other_then_own(amytiss_test::GoalOutcome& b, amytiss_test::GoalOutcome& a);
  static std::vector<pid_t> spawned_;
  static std::string policy_file_;
};

std::vector<pid_t> RestartTest::spawned_;
std::string RestartTest::policy_file_;

// Flips every byte of the middle third of a file in place (no rename: the same path, damaged).
void damage(const std::string& path) {
  std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 3u);
  for (std::size_t i = bytes.size() / 3; i < 2 * bytes.size() / 3; ++i) bytes[i] = char(~bytes[i]);
  file.clear();
  file.seekp(0);
  file.write(bytes.data(), std::streamsize(bytes.size()));
  ASSERT_TRUE(file.good());
}

TEST_F(RestartTest, KilledSynthesizerIsReportedAndARestartedOneIsFollowedWithoutAGoal) {
  const amytiss::PolicyStatus served = status_.latest();
  policy_file_ = served.policy_file;
  ASSERT_EQ(1u, served.generation) << "the scenario needs a synthesizer that announced one policy";
  amytiss::SynthesizeGoal slow;
  slow.config_yaml = amytiss_test::kSlowConfig;
  slow.force = true;
  action_.sendGoal(slow);
  ASSERT_TRUE(status_.wait_for([](const amytiss::PolicyStatus& s) { return s.synthesizing && s.percent > 0; },
                               30.0));
  const int pid = amytiss_ros::node_pid(kSynthesizer);
  ASSERT_GT(pid, 0);
  ASSERT_EQ(0, ::kill(pid, SIGKILL));

  // Still the previous policy, now with a notice that the synthesizer is gone.
  amytiss::GetInput::Response response;
  ASSERT_TRUE(amytiss_test::poll_until(
      [&] {
        response = call();
        return response.message.find("synthesizer not running since") != std::string::npos;
      },
      kNoticeWaitSeconds))
      << response.message;
  EXPECT_TRUE(response.success);
  EXPECT_EQ(served.config_hash, response.config_hash);
  EXPECT_EQ(served.run_id, response.run_id);
  EXPECT_NE(std::string::npos, response.message.find("serving policy 'tiny_reach_avoid'")) << response.message;

  // A new synthesizer with another configuration: its generation restarts at 1, yet the server
  // follows its (config_hash, run_id) without any goal.
  ros::param::set(kSynthesizer + "/spec/horizon", 6);
  ASSERT_GT(spawn({AMYTISS_SYNTHESIZER_BIN, "__name:=synthesizer", "__ns:=/amytiss"}), 0);
  const amytiss::PolicyStatus restarted_status = wait_for_status(
      [&](const amytiss::PolicyStatus& s) { return s.ready && s.horizon == 6 && s.generation == 1; },
      amytiss_test::kPolicyWaitSeconds);
  ASSERT_EQ(6u, restarted_status.horizon) << "the restarted synthesizer announced no policy: " << status_.latest().message;
  EXPECT_NE(served.config_hash, restarted_status.config_hash);
  EXPECT_TRUE(amytiss_test::poll_until(
      [&] {
        response = call();
        return response.config_hash == restarted_status.config_hash && response.message.empty();
      },
      kNoticeWaitSeconds))
      << response.config_hash << " " << response.message;
  EXPECT_EQ(restarted_status.run_id, response.run_id);
}

TEST_F(RestartTest, ARestartedServerRefusesADamagedFileAndTheSynthesizerComputesItAgainWithoutAGoal) {
  const amytiss::PolicyStatus served =
      wait_for_status([](const amytiss::PolicyStatus& s) { return s.ready && !s.synthesizing; }, 1.0);
  ASSERT_TRUE(served.ready);
  policy_file_ = served.policy_file;
  damage(served.policy_file);
  ASSERT_THROW(amytiss::read_policy_file(served.policy_file), amytiss::PolicyFileError)
      << "the damage must be one the reader refuses";

  const int old_server = amytiss_ros::node_pid(kServer);
  ASSERT_GT(old_server, 0);
  ASSERT_EQ(0, ::kill(old_server, SIGKILL));
  ASSERT_GT(spawn({AMYTISS_POLICY_SERVER_BIN, "__name:=policy_server", "__ns:=/amytiss", "_synthesizer_timeout_s:=2.0"}),
            0);

  // The restarted server refuses the announced file and asks for it again: a new run, same hash.
  const amytiss::PolicyStatus recomputed = wait_for_status(
      [&](const amytiss::PolicyStatus& s) {
        return s.ready && !s.synthesizing && s.config_hash == served.config_hash && s.run_id != served.run_id;
      },
      amytiss_test::kPolicyWaitSeconds);
  ASSERT_TRUE(recomputed.ready) << "no recomputation; last status: " << status_.latest().message;
  EXPECT_EQ(served.syntheses_run + 1, recomputed.syntheses_run);
  EXPECT_NO_THROW(amytiss::read_policy_file(recomputed.policy_file));

  // The old connection died with the old server: a new one to the restarted server.
  ASSERT_TRUE(ros::service::waitForService("/amytiss/get_input", ros::Duration(amytiss_test::kServiceWaitSeconds)));
  client_ = handle_.serviceClient<amytiss::GetInput>("/amytiss/get_input", /*persistent=*/true);
  amytiss::GetInput::Response response;
  EXPECT_TRUE(amytiss_test::poll_until(
      [&] {
        response = call_reconnecting();
        return response.success && response.run_id == recomputed.run_id;
      },
      amytiss_test::kPolicyWaitSeconds))
      << response.run_id << " " << response.message;
  EXPECT_TRUE(response.message.empty()) << response.message;
}

/// B, a valid policy of another configuration, copied to <policy file>.other; then A, the
/// synthesizer's own configuration computed again into the same policy file and announced.
void RestartTest::compute_other_then_own(amytiss_test::GoalOutcome& b, amytiss_test::GoalOutcome& a) {
  amytiss::SynthesizeGoal other;
  other.config_yaml = "name: tiny_other\nstates: {lb: [-5, -5], ub: [5, 5], eta: [1, 1]}\n"
                      "inputs: {lb: [0, -3.2], ub: [1, 3.2], eta: [0.5, 0.4]}\n"
                      "dynamics: [\"x0 + u0*cos(u1)\", \"x1 + u0*sin(u1)\"]\nnoise: {covariance: [0.05, 0.05]}\n"
                      "spec: {type: reachability, horizon: 3, target: {lb: [3, 3], ub: [4.5, 4.5]}}\n";
  other.force = true;
  b = run_goal_with_status(other);
  ASSERT_TRUE(b.result.success) << b.result.message;
  policy_file_ = b.status.policy_file;
  std::filesystem::copy_file(policy_file_, policy_file_ + ".other", std::filesystem::copy_options::overwrite_existing);
  amytiss::SynthesizeGoal own;  // empty config_yaml: the synthesizer's parameters
  own.force = true;
  a = run_goal_with_status(own);
  ASSERT_TRUE(a.result.success) << a.result.message;
  ASSERT_EQ(policy_file_, a.status.policy_file);
  ASSERT_NE(a.status.config_hash, b.status.config_hash);
}

// The policy server's latest /diagnostics status.
class ServerDiagnostics {
 public:
  explicit ServerDiagnostics(ros::NodeHandle& handle)
      : subscriber_(handle.subscribe("/diagnostics", 10, &ServerDiagnostics::on_array, this)) {}
  diagnostic_msgs::DiagnosticStatus latest() {
    std::lock_guard<std::mutex> lock(mutex_);
    return latest_;
  }
  static std::string value(const diagnostic_msgs::DiagnosticStatus& status, const std::string& key) {
    for (const auto& pair : status.values)
      if (pair.key == key) return pair.value;
    return "<missing>";
  }

 private:
  void on_array(const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& status : array->status)
      if (status.name.find("policy server") != std::string::npos) latest_ = status;
  }
  std::mutex mutex_;
  diagnostic_msgs::DiagnosticStatus latest_;
  ros::Subscriber subscriber_;
};

bool names_both(const std::string& text, const std::string& one, const std::string& other) {
  return text.find(one) != std::string::npos && text.find(other) != std::string::npos;
}

TEST_F(RestartTest, ARestartedServerRefusesAFileOfAnotherPolicyAndAsksForTheAnnouncedOne) {
  // B: a valid policy of another configuration, kept aside; then A, the synthesizer's own.
  amytiss_test::GoalOutcome a, b;
  ASSERT_NO_FATAL_FAILURE(compute_other_then_own(b, a));
  const std::string kept = policy_file_ + ".other";

  // B moved into the announced file and the server restarted with it as ~policy_file, while a
  // long synthesis runs (no recomputation is asked for meanwhile: the refusal lasts until it is
  // cancelled).
  const int old_server = amytiss_ros::node_pid(kServer);
  ASSERT_GT(old_server, 0);
  ASSERT_EQ(0, ::kill(old_server, SIGKILL));
  std::filesystem::rename(kept, policy_file_);
  std::string long_config = amytiss_test::kSlowConfig;
  long_config.replace(long_config.find("horizon: 40"), 11, "horizon: 400");
  amytiss::SynthesizeGoal busy;
  busy.config_yaml = long_config;
  busy.force = true;
  action_.sendGoal(busy);
  ASSERT_TRUE(status_.wait_for([](const amytiss::PolicyStatus& s) { return s.synthesizing; }, kNoticeWaitSeconds));
  ServerDiagnostics diagnostics(handle_);
  ASSERT_GT(spawn({AMYTISS_POLICY_SERVER_BIN, "__name:=policy_server", "__ns:=/amytiss", "_synthesizer_timeout_s:=2.0",
                   "_retry_period_s:=1.0", "_policy_file:=" + policy_file_}),
            0);
  ASSERT_TRUE(ros::service::waitForService("/amytiss/get_input", ros::Duration(amytiss_test::kServiceWaitSeconds)));

  // No answer from B: "no" with both hashes, in every answer and in /diagnostics.
  amytiss::GetInput::Response response;
  EXPECT_TRUE(amytiss_test::poll_until(
      [&] {
        response = call_reconnecting();
        return !response.success && names_both(response.message, a.status.config_hash, b.status.config_hash);
      },
      kNoticeWaitSeconds))
      << response.success << " " << response.config_hash << " " << response.message;
  diagnostic_msgs::DiagnosticStatus server;
  EXPECT_TRUE(amytiss_test::poll_until(
      [&] {
        server = diagnostics.latest();
        return server.level == diagnostic_msgs::DiagnosticStatus::ERROR &&
               names_both(server.message, a.status.config_hash, b.status.config_hash);
      },
      kNoticeWaitSeconds))
      << server.message;
  EXPECT_EQ("False", ServerDiagnostics::value(server, "policy loaded"));
  EXPECT_EQ(a.status.config_hash, ServerDiagnostics::value(server, "announced config_hash"));
  EXPECT_NE(b.status.config_hash, ServerDiagnostics::value(server, "policy config_hash"));

  // Once the synthesizer is free, the server asks for A again and serves it.
  action_.cancelGoal();
  ASSERT_TRUE(action_.waitForResult(ros::Duration(amytiss_test::kActionWaitSeconds)));
  const amytiss::PolicyStatus recomputed = wait_for_status(
      [&](const amytiss::PolicyStatus& s) {
        return s.ready && !s.synthesizing && s.config_hash == a.status.config_hash && s.run_id != a.status.run_id;
      },
      amytiss_test::kPolicyWaitSeconds);
  ASSERT_TRUE(recomputed.ready) << "no recomputation; last status: " << status_.latest().message;
  EXPECT_TRUE(amytiss_test::poll_until(
      [&] {
        response = call_reconnecting();
        return response.success && response.run_id == recomputed.run_id;
      },
      kNoticeWaitSeconds))
      << response.run_id << " " << response.message;
  EXPECT_EQ(a.status.config_hash, response.config_hash);
  EXPECT_TRUE(response.message.empty()) << response.message;
}

}  // namespace

int main(int argc, char** argv) { return amytiss_test::run_rostests(argc, argv, "amytiss_rostest_restart", 2); }
