# AASHTO T 307 resilient-modulus protocol (src/hilldem/labtests/t307*, universal_model*); included
# from tests/CMakeLists.txt. The driver test runs on the miniature specimen (tests/data/labtests/).
add_executable(hilldem_t307_tests
  labtests/test_t307_sequences.cpp
  labtests/test_universal_model.cpp
  labtests/test_t307.cpp
)
target_link_libraries(hilldem_t307_tests PRIVATE hilldem::core GTest::gtest_main)
target_compile_definitions(hilldem_t307_tests PRIVATE HILLDEM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_compile_options(hilldem_t307_tests PRIVATE -Wall -Wextra -Wpedantic)
gtest_discover_tests(hilldem_t307_tests DISCOVERY_TIMEOUT 60
  PROPERTIES TIMEOUT 300 LABELS labtests ENVIRONMENT OMP_NUM_THREADS=1)
