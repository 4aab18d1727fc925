// rostest: the issue of a synthesizer that dies. Killed mid-run (SIGKILL, no goodbye), the server
// keeps serving the last policy and says the synthesizer is gone; a new synthesizer started with
// another configuration restarts its generation at 1, as the killed one had announced only one
// policy, and the server still follows it, by (config_hash, run_id), without any goal.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <XmlRpcClient.h>
#include <ros/master.h>
#include <ros/network.h>

#include "rostest_fixture.hpp"

namespace {

constexpr double kNoticeWaitSeconds = 20.0;  // the server's synthesizer_timeout_s is 2
const std::string kSynthesizer = "/amytiss/synthesizer";

// The process id of a node, asked through its XML-RPC API (as `rosnode info` does).
int node_pid(const std::string& node) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  request[1] = node;
  if (!ros::master::execute("lookupNode", request, response, payload, true)) return -1;
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(std::string(payload), host, port)) return -1;
  XmlRpc::XmlRpcClient client(host.c_str(), int(port), "/");
  XmlRpc::XmlRpcValue pid_request, pid_response;
  pid_request[0] = ros::this_node::getName();
  if (!client.execute("getPid", pid_request, pid_response) || int(pid_response[0]) != 1) return -1;
  return int(pid_response[2]);
}

using RestartTest = amytiss_test::SynthesizerAndServerTest;

TEST_F(RestartTest, KilledSynthesizerIsReportedAndARestartedOneIsFollowedWithoutAGoal) {
  const amytiss::PolicyStatus served = status_.latest();
  ASSERT_EQ(1u, served.generation) << "the scenario needs a synthesizer that announced one policy";
  amytiss::SynthesizeGoal slow;
  slow.config_yaml = amytiss_test::kSlowConfig;
  slow.force = true;
  action_.sendGoal(slow);
  ASSERT_TRUE(status_.wait_for([](const amytiss::PolicyStatus& s) { return s.synthesizing && s.percent > 0; },
                               30.0));
  const int pid = node_pid(kSynthesizer);
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
  std::vector<std::string> arguments = {AMYTISS_SYNTHESIZER_BIN, "__name:=synthesizer", "__ns:=/amytiss"};
  std::vector<char*> argv;
  for (auto& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  pid_t restarted = 0;
  ASSERT_EQ(0, posix_spawn(&restarted, argv[0], nullptr, nullptr, argv.data(), environ));
  const bool followed = status_.wait_for(
      [&](const amytiss::PolicyStatus& s) { return s.ready && s.horizon == 6 && s.generation == 1; },
      amytiss_test::kPolicyWaitSeconds);
  const amytiss::PolicyStatus restarted_status = status_.latest();
  EXPECT_TRUE(followed) << restarted_status.message;
  EXPECT_NE(served.config_hash, restarted_status.config_hash);
  EXPECT_TRUE(amytiss_test::poll_until(
      [&] {
        response = call();
        return response.config_hash == restarted_status.config_hash && response.message.empty();
      },
      kNoticeWaitSeconds))
      << response.config_hash << " " << response.message;
  EXPECT_EQ(restarted_status.run_id, response.run_id);
  ::kill(restarted, SIGINT);
  int status = 0;
  ::waitpid(restarted, &status, 0);
}

}  // namespace

int main(int argc, char** argv) { return amytiss_test::run_rostests(argc, argv, "amytiss_rostest_restart", 2); }
