# ROS part 1: catkin and catkin_package(). Included before the core. The messages, the service
# and the action are in the separate package amytiss_msgs (amytiss_msgs/ in this repository).
find_package(catkin REQUIRED COMPONENTS
  roscpp std_msgs geometry_msgs visualization_msgs actionlib actionlib_msgs diagnostic_updater amytiss_msgs)

catkin_package(
  INCLUDE_DIRS include
  LIBRARIES amytiss_core
  CATKIN_DEPENDS roscpp std_msgs geometry_msgs visualization_msgs actionlib actionlib_msgs diagnostic_updater
                 amytiss_msgs)
