#pragma once
// Rostest helpers that act on the nodes themselves: starting a node binary in the background
// and stopping it (the process id of a running node: amytiss_ros::node_pid).
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "node_process.hpp"

namespace amytiss_test {

/// Starts `arguments` (the binary first, then e.g. "__name:=policy_server", "__ns:=/amytiss");
/// returns its process id, or 0 when it could not be started.
inline pid_t spawn_node(std::vector<std::string> arguments) {
  std::vector<char*> argv;
  for (auto& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  return posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) == 0 ? pid : 0;
}

/// SIGINT to a node started by spawn_node(), and waits for it to end.
inline void stop_node(pid_t pid) {
  if (pid <= 0) return;
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
}

}  // namespace amytiss_test
