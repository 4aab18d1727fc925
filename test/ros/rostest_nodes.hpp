#pragma once
// Rostest helpers that act on the nodes themselves: the process id of a running node, and
// starting a node binary in the background.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

#include <XmlRpcClient.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>

namespace amytiss_test {

/// The process id of a node (e.g. "/amytiss/policy_server"), asked through its XML-RPC API (as
/// `rosnode info` does); -1 when the master or the node does not answer.
inline int node_pid(const std::string& node) {
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
