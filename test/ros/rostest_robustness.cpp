// rostest: hostile expressions (parameters and goal) are refused on /amytiss/status and the node
// stays up; a zeroed policy file is refused and computed again; /diagnostics of both nodes.
#include <algorithm>
#include <cstddef>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <utility>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <hdf5.h>

#include "amytiss/errors.hpp"
#include "amytiss/policy_file.hpp"
#include "rostest_fixture.hpp"

namespace {

// Where the first chunk of dataset `name` lies in the policy file: its offset and stored size.
std::pair<std::size_t, std::size_t> first_chunk(const std::string& path, const char* name) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t dataset = H5Dopen2(file, name, H5P_DEFAULT);
  const hid_t space = H5Dget_space(dataset);
  haddr_t address = HADDR_UNDEF;
  hsize_t size = 0;
  unsigned filter_mask = 0;
  const herr_t found = H5Dget_chunk_info(dataset, space, 0, nullptr, &filter_mask, &address, &size);
  H5Sclose(space);
  H5Dclose(dataset);
  H5Fclose(file);
  EXPECT_GE(found, 0) << name;
  return {std::size_t(address), std::size_t(size)};
}

constexpr double kNoticeWaitSeconds = 20.0;
const std::string kSynthesizer = "/amytiss/synthesizer";
using amytiss_test::GoalOutcome;

std::string repeat(const std::string& piece, std::size_t times) {
  std::string text;
  for (std::size_t i = 0; i < times; ++i) text += piece;
  return text;
}

class RobustnessTest : public amytiss_test::SynthesizerAndServerTest {
 protected:
  // A goal that must be refused with each of `expected` in its result and on /amytiss/status.
  void expect_refused(const amytiss::SynthesizeGoal& goal, const std::vector<std::string>& expected) {
    // The previous refusal's status may still be the latest: this one's is waited for.
    const GoalOutcome refused = run_goal_with_status(goal);
    EXPECT_FALSE(refused.result.success);
    for (const auto& part : expected)
      EXPECT_NE(std::string::npos, refused.result.message.find(part)) << refused.result.message.substr(0, 500);
    EXPECT_EQ("error", refused.status.phase);
    EXPECT_LT(refused.status.message.size(), 1000u) << "the expression is abbreviated";
    EXPECT_TRUE(call().success) << "the last good policy is still served";
  }
};

TEST_F(RobustnessTest, DeepAndLongExpressionsAreRefusedAndTheNodeStaysUp) {
  XmlRpc::XmlRpcValue good_dynamics;
  ASSERT_TRUE(ros::param::get(kSynthesizer + "/dynamics", good_dynamics));
  XmlRpc::XmlRpcValue deep = good_dynamics;
  deep[0] = repeat("(", 10000) + "x0" + repeat(")", 10000);
  ros::param::set(kSynthesizer + "/dynamics", deep);
  expect_refused(amytiss::SynthesizeGoal(), {"dynamics[0]: column ", "nested deeper than the limit of 256"});
  deep[0] = repeat("-", 60000) + "x0";
  ros::param::set(kSynthesizer + "/dynamics", deep);
  expect_refused(amytiss::SynthesizeGoal(), {"nested deeper than the limit of 256"});
  ros::param::set(kSynthesizer + "/dynamics", good_dynamics);

  // Through a goal: abs( nested 100,000 deep, ^1 repeated, a 10 MB flat sum.
  const std::string head = "name: hostile\nstates: {lb: [-1], ub: [1], eta: [0.5]}\ndynamics: [\"";
  const std::string tail = "\"]\nnoise: {covariance: [0.1]}\nspec: {type: safety, horizon: 2}\n";
  amytiss::SynthesizeGoal goal;
  goal.config_yaml = head + repeat("abs(", 100000) + "x0" + repeat(")", 100000) + tail;
  expect_refused(goal, {"characters long, more than the limit of 65536"});
  goal.config_yaml = head + "x0" + repeat("^1", 30000) + tail;
  expect_refused(goal, {"nested deeper than the limit of 256"});
  goal.config_yaml = head + "x0" + repeat(" + x0", 2 * 1024 * 1024) + tail;
  expect_refused(goal, {"10485762 characters long"});

  // Alive: the unchanged configuration is reused.
  const amytiss::SynthesizeResult result = run_goal(amytiss::SynthesizeGoal());
  EXPECT_TRUE(result.success) << result.message;
  EXPECT_TRUE(result.reused);
}

TEST_F(RobustnessTest, AZeroedPolicyFileIsRefusedAndComputedAgain) {
  const amytiss::PolicyStatus before = status_.latest();
  const std::string file = before.policy_file;
  ASSERT_NO_THROW(amytiss::read_policy_file(file));
  // Zeros over the first stored (compressed, checksummed) chunk of /values: only the checksum or
  // the decompression can tell.
  const auto [at, size] = first_chunk(file, "/values");
  ASSERT_GT(size, 0u);
  {
    std::fstream output(file, std::ios::in | std::ios::out | std::ios::binary);
    output.seekp(std::streamoff(at));
    const std::string zeros(size, '\0');
    output.write(zeros.data(), std::streamsize(zeros.size()));
  }
  EXPECT_THROW(amytiss::read_policy_file(file), amytiss::PolicyFileError);

  const GoalOutcome recomputed = run_goal_with_status(amytiss::SynthesizeGoal());
  EXPECT_TRUE(recomputed.result.success) << recomputed.result.message;
  EXPECT_FALSE(recomputed.result.reused) << "a corrupt file must not be reused";
  EXPECT_EQ(before.syntheses_run + 1, recomputed.status.syntheses_run);
  EXPECT_NE(before.run_id, recomputed.status.run_id);
  EXPECT_NO_THROW(amytiss::read_policy_file(file));
  const std::string new_run = recomputed.status.run_id;
  ASSERT_TRUE(amytiss_test::poll_until([&] { return call().run_id == new_run; }, kNoticeWaitSeconds));
}

TEST_F(RobustnessTest, BothNodesPublishDiagnostics) {
  std::mutex mutex;
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> latest;  // by status name
  const ros::Subscriber subscriber = handle_.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
        std::lock_guard<std::mutex> lock(mutex);
        for (const auto& status : array->status) latest[status.name] = status;
      });
  const auto find = [&](const std::string& part, diagnostic_msgs::DiagnosticStatus& out) {
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& [name, status] : latest)
      if (name.find(part) != std::string::npos) {
        out = status;
        return true;
      }
    return false;
  };
  diagnostic_msgs::DiagnosticStatus server, synthesizer;
  ASSERT_TRUE(amytiss_test::poll_until([&] { return find("policy server", server) && find(": synthesizer", synthesizer); },
                                       kNoticeWaitSeconds));
  const auto value = [](const diagnostic_msgs::DiagnosticStatus& status, const std::string& key) {
    for (const auto& pair : status.values)
      if (pair.key == key) return pair.value;
    return std::string("<missing>");
  };
  const amytiss::PolicyStatus current = status_.latest();
  EXPECT_EQ(diagnostic_msgs::DiagnosticStatus::OK, server.level) << server.message;
  EXPECT_EQ("True", value(server, "policy loaded"));
  EXPECT_EQ(current.config_name, value(server, "policy name"));
  EXPECT_EQ(current.config_hash, value(server, "policy config_hash"));
  EXPECT_EQ(current.run_id, value(server, "policy run_id"));
  EXPECT_EQ("running", value(server, "synthesizer"));
  EXPECT_NE("<missing>", value(server, "policy age (s)"));
  EXPECT_EQ(current.run_id, value(synthesizer, "run_id"));
  EXPECT_EQ(current.device, value(synthesizer, "device"));
}

}  // namespace

int main(int argc, char** argv) { return amytiss_test::run_rostests(argc, argv, "amytiss_rostest_robustness", 2); }
