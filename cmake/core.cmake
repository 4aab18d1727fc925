# The ROS-free core: links only the standard library, Eigen, OpenCL, yaml-cpp and HDF5.
find_package(Eigen3 REQUIRED NO_MODULE)
find_package(OpenCL REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(HDF5 REQUIRED COMPONENTS C CXX)
find_package(Threads REQUIRED)

# OpenCL C sources (kernels, and model sources valid both in C++ and OpenCL C) are embedded in the
# library so the binary runs from any directory.
file(GLOB AMYTISS_EMBEDDED_INPUTS CONFIGURE_DEPENDS
  ${CMAKE_CURRENT_SOURCE_DIR}/src/core/opencl/kernels/*.cl
  ${CMAKE_CURRENT_SOURCE_DIR}/src/core/model/models/*.h)
set(AMYTISS_EMBEDDED_CPP ${CMAKE_CURRENT_BINARY_DIR}/generated/embedded_sources.cpp)
string(REPLACE ";" "|" AMYTISS_EMBEDDED_ARG "${AMYTISS_EMBEDDED_INPUTS}")
add_custom_command(OUTPUT ${AMYTISS_EMBEDDED_CPP}
  COMMAND ${CMAKE_COMMAND} -DOUT=${AMYTISS_EMBEDDED_CPP} "-DINPUTS=${AMYTISS_EMBEDDED_ARG}"
          -P ${CMAKE_CURRENT_SOURCE_DIR}/cmake/embed.cmake
  DEPENDS ${AMYTISS_EMBEDDED_INPUTS} ${CMAKE_CURRENT_SOURCE_DIR}/cmake/embed.cmake
  COMMENT "Embedding OpenCL and model sources"
  VERBATIM)

file(GLOB_RECURSE AMYTISS_CORE_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/src/core/*.cpp)
add_library(amytiss_core ${AMYTISS_CORE_SOURCES} ${AMYTISS_EMBEDDED_CPP})
target_include_directories(amytiss_core PUBLIC
  $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
  PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/core ${HDF5_INCLUDE_DIRS})
target_compile_definitions(amytiss_core PUBLIC CL_TARGET_OPENCL_VERSION=120)
target_link_libraries(amytiss_core PUBLIC Eigen3::Eigen OpenCL::OpenCL yaml-cpp ${HDF5_LIBRARIES} Threads::Threads)
set_target_properties(amytiss_core PROPERTIES POSITION_INDEPENDENT_CODE ON)

# MPI (optional): amytiss_synth runs under mpirun, its ranks splitting one synthesis
# (docs/scale_out.md). The core does not link MPI; the CLI passes it a Communicator.
find_package(MPI COMPONENTS C QUIET)
if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src/cli/amytiss_synth.cpp)
  add_executable(amytiss_synth src/cli/amytiss_synth.cpp src/cli/mpi_session.cpp src/cli/options.cpp src/cli/printing.cpp
    src/cli/simulation.cpp)
  target_link_libraries(amytiss_synth amytiss_core)
  if(MPI_C_FOUND)
    # OMPI_SKIP_MPICXX: the C API only (the deprecated C++ bindings need libmpi_cxx).
    target_compile_definitions(amytiss_synth PRIVATE AMYTISS_WITH_MPI OMPI_SKIP_MPICXX MPICH_SKIP_MPICXX)
    target_link_libraries(amytiss_synth MPI::MPI_C)
    message(STATUS "amytiss: MPI found (${MPIEXEC_EXECUTABLE}): amytiss_synth runs under mpirun")
  else()
    message(STATUS "amytiss: MPI not found: amytiss_synth runs as one process")
  endif()
endif()
# What the CLI tests need to know about MPI: the launcher, when the CLI was built with MPI.
if(MPI_C_FOUND)
  set(AMYTISS_TEST_MPIEXEC "${MPIEXEC_EXECUTABLE}")
else()
  set(AMYTISS_TEST_MPIEXEC "")
endif()

if(AMYTISS_WITH_ROS)
  set_target_properties(amytiss_core PROPERTIES
    LIBRARY_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_LIB_DESTINATION})
  set_target_properties(amytiss_synth PROPERTIES
    RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
  install(TARGETS amytiss_core amytiss_synth
    ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
    LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
    RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
  install(DIRECTORY include/amytiss/ DESTINATION ${CATKIN_PACKAGE_INCLUDE_DESTINATION})
endif()

# Core tests: one gtest binary from every test/core/test_*.cpp. Tests find example configurations
# through AMYTISS_SOURCE_DIR.
file(GLOB AMYTISS_CORE_TESTS CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/test/core/test_*.cpp)
if(AMYTISS_CORE_TESTS)
  if(AMYTISS_WITH_ROS)
    catkin_add_gtest(amytiss_core_tests ${AMYTISS_CORE_TESTS})
    # Debian's catkin_add_gtest links gtest but not its main().
    target_link_libraries(amytiss_core_tests gtest_main)
  else()
    enable_testing()
    find_package(GTest REQUIRED)
    add_executable(amytiss_core_tests ${AMYTISS_CORE_TESTS})
    target_link_libraries(amytiss_core_tests GTest::gtest GTest::gtest_main)
    add_test(NAME amytiss_core_tests COMMAND amytiss_core_tests)
    # One executable per test file as well (plain CMake only), so one area can be built and run
    # alone: make amytiss_test_noise && ./amytiss_test_noise
    foreach(test_file IN LISTS AMYTISS_CORE_TESTS)
      get_filename_component(test_name "${test_file}" NAME_WE)
      string(REGEX REPLACE "^test_" "" test_name "${test_name}")
      add_executable(amytiss_test_${test_name} ${test_file})
      target_link_libraries(amytiss_test_${test_name} amytiss_core GTest::gtest GTest::gtest_main)
      target_include_directories(amytiss_test_${test_name} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/core ${HDF5_INCLUDE_DIRS})
      target_compile_definitions(amytiss_test_${test_name} PRIVATE
        AMYTISS_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
        AMYTISS_SYNTH_BIN="$<TARGET_FILE:amytiss_synth>"
        AMYTISS_MPIEXEC="${AMYTISS_TEST_MPIEXEC}")
    endforeach()
  endif()
  target_link_libraries(amytiss_core_tests amytiss_core)
  target_include_directories(amytiss_core_tests PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/core ${HDF5_INCLUDE_DIRS})
  target_compile_definitions(amytiss_core_tests PRIVATE
    AMYTISS_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
    AMYTISS_SYNTH_BIN="$<TARGET_FILE:amytiss_synth>"
    AMYTISS_MPIEXEC="${AMYTISS_TEST_MPIEXEC}")
endif()
