// Asks /amytiss/get_input once, as a robot's client would; exit status 0 on a successful answer.
#include <amytiss/GetInput.h>
#include <amytiss/SynthesizeAction.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "amytiss_client_check");
  ros::NodeHandle handle;
  amytiss::SynthesizeGoal goal;  // the action's types are there too
  goal.force = false;
  amytiss::GetInput service;
  service.request.state = {-4.0, -4.0};
  service.request.time_step = 0;
  if (!ros::service::call("/amytiss/get_input", service)) return 2;
  ROS_INFO("success %d, policy %s run %s: %s", service.response.success, service.response.config_hash.c_str(),
           service.response.run_id.c_str(), service.response.message.c_str());
  const int status = service.response.success ? 0 : 1;
  ros::shutdown();
  return status;
}
