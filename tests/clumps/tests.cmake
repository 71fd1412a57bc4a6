# Clumps (issue 32): quaternions, clump templates and their mass properties, shapes, the rigid-body
# law of motion. Included from tests/CMakeLists.txt.
add_executable(hilldem_clump_tests
  clumps/test_quaternion.cpp
  clumps/test_clump_template.cpp
  clumps/test_rigid_body.cpp
  clumps/test_clump_shapes.cpp
  clumps/test_clump_fill.cpp
  clumps/test_clump_bed.cpp
  clumps/test_clump_pebbles.cpp
  clumps/test_clump_engine.cpp
  clumps/test_clump_scenario.cpp
)
target_link_libraries(hilldem_clump_tests PRIVATE hilldem::core GTest::gtest_main)
target_compile_options(hilldem_clump_tests PRIVATE -Wall -Wextra -Wpedantic)
gtest_discover_tests(hilldem_clump_tests DISCOVERY_TIMEOUT 60 PROPERTIES LABELS clumps)
