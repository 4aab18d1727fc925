#pragma once
// The process behind a running ROS node, for tests and benchmarks on the node's machine.
#include <string>

namespace amytiss_ros {

/// The process id of a node (e.g. "/amytiss/policy_server"), asked through its XML-RPC API (as
/// `rosnode info` does); -1 when the master or the node does not answer.
int node_pid(const std::string& node);

/// CPU time (user + system, all threads) the process `pid` of this machine has used, in seconds;
/// -1 when /proc has no such process.
double process_cpu_seconds(int pid);

}  // namespace amytiss_ros
