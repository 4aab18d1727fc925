# ROS part 1: catkin, messages/services/actions, catkin_package(). Included before the core.
find_package(catkin REQUIRED COMPONENTS
  roscpp std_msgs geometry_msgs visualization_msgs actionlib actionlib_msgs message_generation)

add_message_files(DIRECTORY msg)
add_service_files(DIRECTORY srv)
add_action_files(DIRECTORY action)
generate_messages(DEPENDENCIES std_msgs geometry_msgs actionlib_msgs)

catkin_package(
  INCLUDE_DIRS include
  LIBRARIES amytiss_core
  CATKIN_DEPENDS roscpp std_msgs geometry_msgs visualization_msgs actionlib actionlib_msgs message_runtime)
