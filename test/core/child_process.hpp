#pragma once
// Runs a test step in a forked child process, for what a test must not do to its own process:
// lower the file size limit, drop privileges, die by a signal, or end through the libraries'
// exit-time cleanup (HDF5 closes what is still open there, and crashed on a half-closed file).
//
//   const ChildOutcome outcome = run_in_child([] { ...; return std::string("what happened"); });
//   EXPECT_TRUE(outcome.exited_normally()) << outcome.describe();
//   EXPECT_NE(std::string::npos, outcome.message.find("No space left on device"));
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <string>

namespace amytiss {
namespace test_support {

struct ChildOutcome {
  int wait_status = 0;
  std::string message;  ///< what the child's body returned (or the exception it let escape)

  bool exited_normally() const { return WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 0; }
  bool killed_by(int signal_number) const { return WIFSIGNALED(wait_status) && WTERMSIG(wait_status) == signal_number; }
  std::string describe() const {
    const std::string how = WIFSIGNALED(wait_status) ? "killed by signal " + std::to_string(WTERMSIG(wait_status))
                                                     : "exit status " + std::to_string(WEXITSTATUS(wait_status));
    return "child: " + how + ", message: \"" + message + "\"";
  }
};

/// Forks; the child runs `body`, sends back its text and leaves through std::exit(0), so every
/// exit-time cleanup runs. The parent waits for it. `started` (optional) runs in the parent with
/// the child's pid before the wait.
inline ChildOutcome run_in_child(const std::function<std::string()>& body,
                                 const std::function<void(pid_t)>& started = nullptr) {
  int channel[2];
  if (::pipe(channel) != 0) return {-1, "pipe failed"};
  // The child leaves through exit(), which flushes the stdio buffers it inherited: with output
  // redirected to a file, that write would meet the child's own limits (a lowered file size
  // limit kills it with SIGXFSZ). Nothing is left to flush when the parent flushes first.
  std::fflush(nullptr);
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(channel[0]);
    std::string message;
    try {
      message = body();
    } catch (const std::exception& error) {
      message = std::string("unexpected exception: ") + error.what();
    }
    for (std::size_t at = 0; at < message.size();) {
      const ssize_t written = ::write(channel[1], message.data() + at, message.size() - at);
      if (written <= 0) break;
      at += std::size_t(written);
    }
    ::close(channel[1]);
    std::exit(0);
  }
  ::close(channel[1]);
  ChildOutcome outcome;
  if (child < 0) {
    ::close(channel[0]);
    outcome.message = "fork failed";
    return outcome;
  }
  if (started) started(child);
  char buffer[4096];
  for (ssize_t got; (got = ::read(channel[0], buffer, sizeof buffer)) > 0;)
    outcome.message.append(buffer, std::size_t(got));
  ::close(channel[0]);
  ::waitpid(child, &outcome.wait_status, 0);
  return outcome;
}

/// A pid that no process has: that of a child that has ended and been waited for.
inline pid_t pid_of_an_ended_process() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  return child;
}

}  // namespace test_support
}  // namespace amytiss
