// amytiss policy server node: serves /amytiss/get_input and the closed loop (see
// src/ros/policy_server.hpp for topics, service and parameters).
#include <ros/ros.h>

#include "policy_server.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "policy_server");
  ros::NodeHandle public_handle, private_handle("~");
  amytiss_ros::PolicyServerNode node(public_handle, private_handle);
  // get_input is answered on roscpp's network thread (see PolicyServerNode); the spinners run the
  // rest: statuses, states, timers, and the get_input calls handed over. Two, so that a status
  // that waits for the previous load to end does not hold up the others.
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ros::waitForShutdown();
  return 0;
}
