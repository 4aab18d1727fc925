// rostest: nodes that die. A synthesizer killed mid-run (SIGKILL, no goodbye): the server keeps
// serving the last policy and says the synthesizer is gone; a new synthesizer started with
// another configuration restarts its generation at 1, as the killed one had announced only one
// policy, and the server still follows it, by (config_hash, run_id), without any goal. A policy
// server killed and restarted while the policy file is damaged: it refuses the file, the
// synthesizer computes the policy again and the server serves it, without any goal from outside.
#include <cstdio>
#include <fstream>
#include <iterator>

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
        amytiss::GetInput service;
        service.request.state = {-4.0, -4.0};
        if (!client_.call(service))
          client_ = handle_.serviceClient<amytiss::GetInput>("/amytiss/get_input", /*persistent=*/true);
        response = service.response;
        return response.success && response.run_id == recomputed.run_id;
      },
      amytiss_test::kPolicyWaitSeconds))
      << response.run_id << " " << response.message;
  EXPECT_TRUE(response.message.empty()) << response.message;
}

}  // namespace

int main(int argc, char** argv) { return amytiss_test::run_rostests(argc, argv, "amytiss_rostest_restart", 2); }
