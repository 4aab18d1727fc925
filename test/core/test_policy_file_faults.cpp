// Policy files against a hostile system: a full disk (a file size limit without privileges, a tiny
// tmpfs with them), a rename that cannot happen, an unreadable file, signals during a write and
// the orphans of killed writers. The steps that change the process run in a child.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "amytiss/errors.hpp"
#include "amytiss/policy_file.hpp"

#include "child_process.hpp"
#include "policy_test_data.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;
using test_support::ChildOutcome;
using test_support::run_in_child;

// A file size limit well below the policy file of kLargeCells^2 cells (about 140 KiB).
constexpr rlim_t kFileSizeLimit = 64 * 1024;
constexpr std::size_t kLargeCells = 40;
constexpr unsigned kLargeHorizon = 10;
// The signal test needs a write long enough to be caught in the act: about 10 MB.
constexpr std::size_t kHugeCells = 200;
constexpr unsigned kHugeHorizon = 20;
constexpr auto kSignalTestPatience = std::chrono::seconds(60);
constexpr uid_t kUnprivilegedUser = 65534;  // "nobody"
constexpr const char* kCannotDropPrivileges = "setuid failed";

class PolicyFileFaults : public ::testing::Test {
 protected:
  void SetUp() override { directory_ = test_support::fresh_test_directory("amytiss_policy_faults_"); }
  void TearDown() override { fs::remove_all(directory_); }
  std::string path(const std::string& name) const { return (directory_ / name).string(); }
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(directory_)) names.push_back(entry.path().filename().string());
    return names;
  }

  fs::path directory_;
};

// Writes `policy` and returns the PolicyFileError's message ("" when the write succeeds).
std::string write_refusal(const std::string& file, const Policy& policy, const Config& config) {
  try {
    write_policy_file(file, policy, config);
  } catch (const PolicyFileError& error) {
    return error.what();
  }
  return "";
}

std::string contains(const std::string& text) { return "expected to contain \"" + text + "\""; }

TEST_F(PolicyFileFaults, AFileSizeLimitIsReportedWithItsReasonAndTheProcessEndsCleanly) {
  const Config config = test_support::square_policy_config(kLargeCells, kLargeHorizon);
  const Policy policy = test_support::tiny_policy(config);
  const ChildOutcome outcome = run_in_child([&] {
    ::signal(SIGXFSZ, SIG_IGN);  // then a write past the limit fails with EFBIG
    const rlimit limit{kFileSizeLimit, kFileSizeLimit};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    return write_refusal(path("p.h5"), policy, config);
  });
  // The exit runs HDF5's cleanup: it crashed when a file's close had failed.
  EXPECT_TRUE(outcome.exited_normally()) << outcome.describe();
  EXPECT_NE(std::string::npos, outcome.message.find("cannot write policy file " + path("p.h5"))) << outcome.message;
  EXPECT_NE(std::string::npos, outcome.message.find(std::strerror(EFBIG)))
      << outcome.message << " " << contains(std::strerror(EFBIG));
  EXPECT_TRUE(entries().empty()) << "left: " << testing::PrintToString(entries());
}

TEST_F(PolicyFileFaults, AFullDiskIsReportedAsSuchAndLeavesTheOlderFileIntact) {
  const fs::path disk = directory_ / "disk";
  fs::create_directories(disk);
  if (::mount("tmpfs", disk.c_str(), "tmpfs", 0, "size=64k") != 0)
    GTEST_SKIP() << "mounting a 64 KiB tmpfs needs privileges: " << std::strerror(errno)
                 << " (the file size limit test covers a full disk without them)";
  const Config small_config = test_support::tiny_config();
  write_policy_file((disk / "p.h5").string(), test_support::tiny_policy(small_config), small_config);
  const Config config = test_support::square_policy_config(kLargeCells, kLargeHorizon);
  const Policy policy = test_support::tiny_policy(config);
  const ChildOutcome outcome = run_in_child([&] { return write_refusal((disk / "p.h5").string(), policy, config); });
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(disk)) left.push_back(entry.path().filename().string());
  std::string older_file_check;
  try {
    read_policy_file_for((disk / "p.h5").string(), small_config);
  } catch (const PolicyFileError& error) {
    older_file_check = error.what();
  }
  ::umount(disk.c_str());
  EXPECT_TRUE(outcome.exited_normally()) << outcome.describe();
  EXPECT_NE(std::string::npos, outcome.message.find(std::strerror(ENOSPC)))
      << outcome.message << " " << contains(std::strerror(ENOSPC));
  EXPECT_EQ(std::vector<std::string>{"p.h5"}, left);
  EXPECT_EQ("", older_file_check);
}

TEST_F(PolicyFileFaults, AFailedRenameGivesItsReasonAndLeavesNoTemporaryFile) {
  const Config config = test_support::tiny_config();
  // The target is a directory that is not empty: the temporary file is written, the rename fails.
  fs::create_directories(path("occupied.h5/inside"));
  const std::string message = write_refusal(path("occupied.h5"), test_support::tiny_policy(config), config);
  EXPECT_NE(std::string::npos, message.find("rename")) << message;
  EXPECT_NE(std::string::npos, message.find(std::strerror(EISDIR)))
      << message << " " << contains(std::strerror(EISDIR));
  EXPECT_EQ(std::vector<std::string>{"occupied.h5"}, entries());
}

TEST_F(PolicyFileFaults, AnUnreadableFileIsReportedAsPermissionDenied) {
  const Config config = test_support::tiny_config();
  write_policy_file(path("p.h5"), test_support::tiny_policy(config), config);
  ASSERT_EQ(0, ::chmod(path("p.h5").c_str(), 0));
  const ChildOutcome outcome = run_in_child([&] {
    // root reads any file: read as an unprivileged user instead.
    if (::geteuid() == 0 && ::setuid(kUnprivilegedUser) != 0) return std::string(kCannotDropPrivileges);
    try {
      read_policy_file(path("p.h5"));
    } catch (const PolicyFileError& error) {
      return std::string(error.what());
    }
    return std::string("read without an error");
  });
  if (outcome.message == kCannotDropPrivileges) GTEST_SKIP() << "root cannot become user " << kUnprivilegedUser;
  EXPECT_TRUE(outcome.exited_normally()) << outcome.describe();
  EXPECT_NE(std::string::npos, outcome.message.find(std::strerror(EACCES)))
      << outcome.message << " " << contains(std::strerror(EACCES));
  EXPECT_EQ(std::string::npos, outcome.message.find("corrupt")) << outcome.message;
}

TEST_F(PolicyFileFaults, TheNextWriteRemovesTheTemporaryFileOfADeadWriter) {
  const Config config = test_support::tiny_config();
  const pid_t live_writer = ::fork();
  if (live_writer == 0) {
    ::pause();
    ::_exit(0);
  }
  const std::string orphan = path("p.h5.tmp." + std::to_string(test_support::pid_of_an_ended_process()));
  const std::string of_a_live_writer = path("p.h5.tmp." + std::to_string(live_writer));
  const std::string of_another_file = path("q.h5.tmp." + std::to_string(test_support::pid_of_an_ended_process()));
  for (const std::string& name : {orphan, of_a_live_writer, of_another_file}) std::ofstream(name) << "partial";
  write_policy_file(path("p.h5"), test_support::tiny_policy(config), config);
  ::kill(live_writer, SIGKILL);
  ::waitpid(live_writer, nullptr, 0);
  EXPECT_FALSE(fs::exists(orphan));
  EXPECT_TRUE(fs::exists(of_a_live_writer));
  EXPECT_TRUE(fs::exists(of_another_file));
  EXPECT_TRUE(fs::exists(path("p.h5")));
}

// Waits (bounded) until `child` has ended, without reaping it; kills it when it does not end.
void expect_end_of(pid_t child) {
  const auto deadline = std::chrono::steady_clock::now() + kSignalTestPatience;
  while (std::chrono::steady_clock::now() < deadline) {
    siginfo_t info{};
    if (::waitid(P_PID, id_t(child), &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == child) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ADD_FAILURE() << "the child did not end after the signal";
  ::kill(child, SIGKILL);
}

// The child writes the policy again and again; the parent waits until it sees the temporary file
// (bounded polling), then sends the signal.
ChildOutcome signal_during_writes(const std::string& file, int signal_number, const Policy& policy,
                                  const Config& config, bool& caught_in_the_act) {
  caught_in_the_act = false;
  return run_in_child(
      [&] {
        // Default dispositions, whatever the test runner inherited (a background job ignores SIGINT).
        ::signal(signal_number, SIG_DFL);
        for (;;) write_policy_file(file, policy, config);
        return std::string();
      },
      [&](pid_t child) {
        const std::string temporary = file + ".tmp." + std::to_string(child);
        const auto deadline = std::chrono::steady_clock::now() + kSignalTestPatience;
        while (!fs::exists(temporary) && std::chrono::steady_clock::now() < deadline)
          std::this_thread::sleep_for(std::chrono::microseconds(100));
        caught_in_the_act = fs::exists(temporary);
        ::kill(child, signal_number);
        expect_end_of(child);
      });
}

TEST_F(PolicyFileFaults, SigtermOrSigintDuringAWriteLeavesNoTemporaryFile) {
  const Config config = test_support::square_policy_config(kHugeCells, kHugeHorizon);
  const Policy policy = test_support::tiny_policy(config);
  for (int signal_number : {SIGTERM, SIGINT}) {
    bool caught_in_the_act = false;
    const ChildOutcome outcome = signal_during_writes(path("p.h5"), signal_number, policy, config, caught_in_the_act);
    EXPECT_TRUE(caught_in_the_act) << "the temporary file never appeared within the patience";
    EXPECT_TRUE(outcome.killed_by(signal_number)) << outcome.describe();
    for (const std::string& name : entries())
      EXPECT_EQ(std::string::npos, name.find(".tmp.")) << "signal " << signal_number << " left " << name;
  }
}

}  // namespace
}  // namespace amytiss
