#include "node_process.hpp"

#include <unistd.h>

#include <fstream>
#include <sstream>

#include <XmlRpcClient.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/this_node.h>

namespace amytiss_ros {

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

double process_cpu_seconds(int pid) {
  std::ifstream file("/proc/" + std::to_string(pid) + "/stat");
  std::string stat;
  if (!std::getline(file, stat)) return -1;
  // Fields after the command name (which may hold spaces, so skip to its closing parenthesis):
  // state is field 3, utime and stime fields 14 and 15, in clock ticks.
  std::istringstream fields(stat.substr(stat.rfind(')') + 2));
  std::string field;
  for (int index = 3; index < 14; ++index) fields >> field;
  long long user_ticks = 0, system_ticks = 0;
  if (!(fields >> user_ticks >> system_ticks)) return -1;
  return double(user_ticks + system_ticks) / double(sysconf(_SC_CLK_TCK));
}

}  // namespace amytiss_ros
