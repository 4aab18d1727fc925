// amytiss synthesizer node: configuration from private parameters -> policy file (see
// src/ros/synthesizer.hpp for topics, action and parameters).
#include <csignal>

#include <ros/ros.h>

#include "synthesizer.hpp"

namespace {

volatile std::sig_atomic_t stop_signal = 0;

void on_stop_signal(int) { stop_signal = 1; }

}  // namespace

int main(int argc, char** argv) {
  // Our own SIGINT handler: ROS's would shut ROS down at once, while a synthesis still runs and
  // before its cancelled status and goal result could go out.
  ros::init(argc, argv, "synthesizer", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
  ros::NodeHandle public_handle, private_handle("~");
  amytiss_ros::SynthesizerNode node(public_handle, private_handle);
  node.start();
  // Two threads: the action server's and the status publisher's callbacks never wait on synthesis.
  ros::AsyncSpinner spinner(2);
  spinner.start();
  // ros::ok() turns false on a shutdown through the master (rosnode kill).
  constexpr double kSignalPollSeconds = 0.05;
  while (!stop_signal && ros::ok()) ros::WallDuration(kSignalPollSeconds).sleep();
  node.shutdown();
  spinner.stop();
  ros::shutdown();
  return 0;
}
