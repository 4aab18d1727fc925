# libFuzzer target for the expression parser and configuration validation (scripts/fuzz builds it
# with clang: cmake -DAMYTISS_FUZZ=ON -DAMYTISS_WITH_ROS=OFF -DCMAKE_CXX_COMPILER=clang++).
# Included before the core, so the core is instrumented (coverage, address, undefined) too.
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "AMYTISS_FUZZ needs clang (libFuzzer): -DCMAKE_CXX_COMPILER=clang++")
endif()
add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -g -O1)
add_link_options(-fsanitize=address,undefined)
