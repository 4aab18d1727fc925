# ROS part 2: the thin ROS layer (src/ros), nodes, and rostests. Included after the core.
