// amytiss policy server node: serves /amytiss/get_input and the closed loop (see
// src/ros/policy_server.hpp for topics, service and parameters).
#include <ros/ros.h>

#include "policy_server.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "policy_server");
  ros::NodeHandle public_handle, private_handle("~");
  amytiss_ros::PolicyServerNode node(public_handle, private_handle);
  // Several threads: requests are answered while a new policy is being loaded.
  ros::AsyncSpinner spinner(4);
  spinner.start();
  ros::waitForShutdown();
  return 0;
}
