// rostest: Ctrl-C while a goal runs. The synthesizer, sent SIGINT during the synthesis or while it
// writes the policy file, exits with status 0 (no abort, no corrupted heap) and leaves the policy
// file whole: the old one after an interrupted synthesis, the old or the complete new one after an
// interrupted write, and no temporary file next to it.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "amytiss/errors.hpp"
#include "amytiss/policy_file.hpp"
#include "rostest_fixture.hpp"

namespace {

constexpr double kExitWaitSeconds = 30.0;
// About 250,000 cells and one input, horizon 20: a few seconds of synthesis, and a policy file of
// about 80 MB whose write takes long enough (seconds) for a SIGINT to land during it.
constexpr const char* kBigFileConfig = R"YAML(
name: big_file_write
states:  {lb: [-5, -5], ub: [5, 5], eta: [0.02, 0.02]}
inputs:  {lb: [-0.5], ub: [0.5], eta: [1.0]}
dynamics: ["x0 + u0", "x1"]
noise: {type: additive, distribution: normal, covariance: [0.0004, 0.0004], truncation: cutting_probability, cutting_probability: 1.0e-3}
spec: {type: reach_avoid, horizon: 20, target: {lb: [3, 3], ub: [4.5, 4.5]}, avoid: {lb: [-1, -1], ub: [1, 1]}}
)YAML";
const std::string kSynthesizer = "/amytiss/synthesizer";

std::string file_bytes(const std::string& path) {
  std::ifstream input(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(input), std::istreambuf_iterator<char>());
}

/// A synthesizer node started by the test (its parameters come from shutdown.test).
class SynthesizerProcess {
 public:
  SynthesizerProcess() {
    std::vector<std::string> arguments = {AMYTISS_SYNTHESIZER_BIN, "__name:=synthesizer", "__ns:=/amytiss"};
    std::vector<char*> argv;
    for (auto& argument : arguments) argv.push_back(argument.data());
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, argv[0], nullptr, nullptr, argv.data(), environ) != 0) pid_ = 0;
  }
  ~SynthesizerProcess() {
    if (running()) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  bool started() const { return pid_ > 0; }
  bool interrupt() const { return ::kill(pid_, SIGINT) == 0; }
  /// Waits (bounded) for the exit; returns whether it exited, with its wait status in `status`.
  bool wait_for_exit(double seconds, int& status) {
    amytiss_test::poll_until([&] { return !running(); }, seconds);
    status = status_;
    return exited_;
  }

 private:
  bool running() {
    if (exited_ || pid_ <= 0) return false;
    exited_ = ::waitpid(pid_, &status_, WNOHANG) == pid_;
    return !exited_;
  }
  pid_t pid_ = 0;
  int status_ = 0;
  bool exited_ = false;
};

std::string describe_wait_status(int status) {
  if (WIFEXITED(status)) return "exit status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return "killed by signal " + std::to_string(WTERMSIG(status));
  return "wait status " + std::to_string(status);
}

class ShutdownTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(ros::param::get(kSynthesizer + "/policy_file", policy_file_));
    ASSERT_TRUE(synthesizer_.started());
    ASSERT_TRUE(action_.waitForServer(ros::Duration(amytiss_test::kServiceWaitSeconds)));
    ASSERT_TRUE(status_.wait_for(
        [&](const amytiss::PolicyStatus& s) { return s.ready && !s.synthesizing && s.policy_file == policy_file_; },
        amytiss_test::kPolicyWaitSeconds))
        << status_.latest().message;
    old_config_hash_ = status_.latest().config_hash;
    old_bytes_ = file_bytes(policy_file_);
    ASSERT_FALSE(old_bytes_.empty());
  }
  /// Sends a goal for `config_yaml`, interrupts the synthesizer once a status meets `when`, and
  /// expects a clean exit.
  void interrupt_goal_when(const std::string& config_yaml, const std::function<bool(const amytiss::PolicyStatus&)>& when) {
    amytiss::SynthesizeGoal goal;
    goal.config_yaml = config_yaml;
    goal.force = true;
    action_.sendGoal(goal);
    ASSERT_TRUE(status_.wait_for(when, amytiss_test::kActionWaitSeconds)) << status_.latest().message;
    ASSERT_TRUE(synthesizer_.interrupt());
    int wait_status = 0;
    ASSERT_TRUE(synthesizer_.wait_for_exit(kExitWaitSeconds, wait_status)) << "still running after SIGINT";
    EXPECT_TRUE(WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 0) << describe_wait_status(wait_status);
  }
  void expect_no_temporary_file() {
    const std::filesystem::path path(policy_file_);
    for (const auto& entry : std::filesystem::directory_iterator(path.parent_path()))
      EXPECT_NE(0u, entry.path().filename().string().rfind(path.filename().string() + ".tmp", 0))
          << "left behind: " << entry.path();
  }

  ros::NodeHandle handle_;
  amytiss_test::StatusWatcher status_{handle_};
  actionlib::SimpleActionClient<amytiss::SynthesizeAction> action_{"/amytiss/synthesize", true};
  SynthesizerProcess synthesizer_;
  std::string policy_file_, old_config_hash_, old_bytes_;
};

TEST_F(ShutdownTest, InterruptedDuringTheSynthesisExitsCleanlyAndKeepsTheOldFile) {
  interrupt_goal_when(
      amytiss_test::kSlowConfig, [](const amytiss::PolicyStatus& s) { return s.synthesizing && s.phase == "synthesis" && s.percent > 0; });
  EXPECT_EQ(old_bytes_, file_bytes(policy_file_)) << "the old policy file changed";
  expect_no_temporary_file();
}

TEST_F(ShutdownTest, InterruptedWhileWritingExitsCleanlyAndLeavesAWholeFile) {
  interrupt_goal_when(kBigFileConfig,
                      [](const amytiss::PolicyStatus& s) { return s.message.rfind("writing ", 0) == 0; });
  // The write is not interrupted: the file is the old one or the complete new one.
  amytiss::LoadedPolicy loaded;
  ASSERT_NO_THROW(loaded = amytiss::read_policy_file(policy_file_));
  if (loaded.config_hash == old_config_hash_)
    EXPECT_EQ(old_bytes_, file_bytes(policy_file_));
  else
    EXPECT_NE(std::string::npos, loaded.config_yaml.find("big_file_write")) << loaded.config_yaml.substr(0, 200);
  expect_no_temporary_file();
}

}  // namespace

int main(int argc, char** argv) { return amytiss_test::run_rostests(argc, argv, "amytiss_rostest_shutdown", 2); }
