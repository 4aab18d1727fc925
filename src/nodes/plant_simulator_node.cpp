// amytiss plant simulator node: runs closed-loop episodes against the policy server, reports the
// success rate next to V_0, writes CSV and pictures, and exits (see src/ros/plant_simulator.hpp).
#include <ros/ros.h>

#include "plant_simulator.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "plant_simulator");
  ros::NodeHandle public_handle, private_handle("~");
  amytiss_ros::PlantSimulatorNode node(public_handle, private_handle);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int exit_code = node.run();
  ros::shutdown();
  return exit_code;
}
