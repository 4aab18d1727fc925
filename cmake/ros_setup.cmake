# ROS part 1: catkin, the package's messages, service and action (msg/, srv/, action/), and
# catkin_package(). Included before the core.
find_package(catkin REQUIRED COMPONENTS
  roscpp std_msgs geometry_msgs visualization_msgs actionlib actionlib_msgs diagnostic_updater message_generation)

add_message_files(DIRECTORY msg)
add_service_files(DIRECTORY srv)
add_action_files(DIRECTORY action)
generate_messages(DEPENDENCIES std_msgs actionlib_msgs)

# A client of this package gets the messages, the service and the action, and nothing of the
# core: no library and no include folder are exported, so a client that only calls the service
# links neither OpenCL nor HDF5 (scripts/test_install checks it against the install space).
catkin_package(CATKIN_DEPENDS message_runtime std_msgs actionlib_msgs)
