// amytiss synthesizer node: configuration from private parameters -> policy file (see
// src/ros/synthesizer.hpp for topics, action and parameters).
#include <ros/ros.h>

#include "synthesizer.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "synthesizer");
  ros::NodeHandle public_handle, private_handle("~");
  amytiss_ros::SynthesizerNode node(public_handle, private_handle);
  node.start();
  // Two threads: the action server's and the status publisher's callbacks never wait on synthesis.
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ros::waitForShutdown();
  return 0;
}
