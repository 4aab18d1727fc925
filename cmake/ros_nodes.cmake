# ROS part 2: the thin ROS layer (src/ros), nodes, and rostests. Included after the core.

# The ROS layer: parameter/message conversions and the nodes' logic; nodes' main()s are tiny.
add_library(amytiss_ros
  src/ros/checked_get_input.cpp
  src/ros/config_from_params.cpp
  src/ros/conversions.cpp
  src/ros/immediate_callback_queue.cpp
  src/ros/node_process.cpp
  src/ros/plant_model.cpp
  src/ros/plant_simulator.cpp
  src/ros/policy_follower.cpp
  src/ros/policy_server.cpp
  src/ros/synthesizer.cpp
  src/ros/synthesizer_monitor.cpp)
target_include_directories(amytiss_ros PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/src/ros ${catkin_INCLUDE_DIRS})
target_link_libraries(amytiss_ros PUBLIC amytiss_core ${catkin_LIBRARIES})
add_dependencies(amytiss_ros ${${PROJECT_NAME}_EXPORTED_TARGETS} ${catkin_EXPORTED_TARGETS})
set_target_properties(amytiss_ros PROPERTIES POSITION_INDEPENDENT_CODE ON)
# The plant simulator runs the plot script with the interpreter catkin was configured with.
target_compile_definitions(amytiss_ros PRIVATE AMYTISS_PYTHON_EXECUTABLE="${PYTHON_EXECUTABLE}")

foreach(node synthesizer policy_server plant_simulator)
  add_executable(${node} src/nodes/${node}_node.cpp)
  target_link_libraries(${node} amytiss_ros)
endforeach()

# Load test client of the service (scripts/bench_service runs it).
add_executable(bench_service src/tools/bench_service.cpp src/tools/tcpros_service_client.cpp)
target_link_libraries(bench_service amytiss_ros)

install(TARGETS amytiss_ros synthesizer policy_server plant_simulator bench_service
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(DIRECTORY launch rviz config DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/scripts/plot_episodes.py)
  catkin_install_python(PROGRAMS scripts/plot_episodes.py DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
  # Also where launch files find it, $(find amytiss)/scripts, as in the source tree.
  install(PROGRAMS scripts/plot_episodes.py scripts/inspect_policy.py
          DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/scripts)
endif()
install(FILES LICENSE DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  find_package(rostest REQUIRED)
  # Conversions and parameters, no master needed.
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/test_conversions.cpp)
    catkin_add_gtest(amytiss_ros_unit_tests test/ros/test_conversions.cpp test/ros/test_synthesizer_monitor.cpp
                     test/ros/test_policy_follower.cpp test/ros/test_checked_get_input.cpp
                     test/ros/test_immediate_callback_queue.cpp)
    target_link_libraries(amytiss_ros_unit_tests amytiss_ros)
    target_compile_definitions(amytiss_ros_unit_tests PRIVATE AMYTISS_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  endif()

  # Node-level tests (map_server's rtest style): one gtest node per .test file.
  foreach(rostest_name service resynthesis closed_loop robustness restart shutdown)
    if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/test/ros/rostest_${rostest_name}.cpp)
      add_rostest_gtest(amytiss_rostest_${rostest_name} test/ros/${rostest_name}.test
                        test/ros/rostest_${rostest_name}.cpp)
      target_link_libraries(amytiss_rostest_${rostest_name} amytiss_ros)
      # The robustness test corrupts a policy file where HDF5 says its chunks lie.
      target_include_directories(amytiss_rostest_${rostest_name} PRIVATE ${HDF5_INCLUDE_DIRS})
      target_compile_definitions(amytiss_rostest_${rostest_name} PRIVATE
        AMYTISS_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
        AMYTISS_SYNTHESIZER_BIN="$<TARGET_FILE:synthesizer>"
        AMYTISS_POLICY_SERVER_BIN="$<TARGET_FILE:policy_server>")
    endif()
  endforeach()
  # The service test checks the load test's TCPROS client too.
  if(TARGET amytiss_rostest_service)
    target_sources(amytiss_rostest_service PRIVATE src/tools/tcpros_service_client.cpp)
    target_include_directories(amytiss_rostest_service PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/tools)
  endif()
  # The service test again, on a policy of continuous-system bounds (guarantee: system).
  if(TARGET amytiss_rostest_service)
    add_rostest(test/ros/service_system.test DEPENDENCIES amytiss_rostest_service)
  endif()
endif()
