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

# `hilldem t307`: bad options stop with exit status 2 before any work, naming the option and its range.
set(HILLDEM_T307_OUT ${CMAKE_CURRENT_BINARY_DIR}/t307_cli_out)
add_test(NAME cli.t307_zero_pulse_duration_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "pulse duration [s] must be in [1e-05, 1], got 0" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> t307 --pulse-duration 0 -o ${HILLDEM_T307_OUT}/bad1)
add_test(NAME cli.t307_sequence_out_of_range_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--sequences: each must be in [0, 15], got 16" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> t307 --sequences 1,16 -o ${HILLDEM_T307_OUT}/bad2)
add_test(NAME cli.t307_averaged_above_cycles_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "averaged cycles must be in [1, 3], got 5" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> t307 --cycles 3 -o ${HILLDEM_T307_OUT}/bad3)
add_test(NAME cli.t307_wet_linear_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--wet needs the hill material"
          2 $<TARGET_FILE:hilldem> t307 --material linear --wet -o ${HILLDEM_T307_OUT}/bad4)
add_test(NAME cli.t307_bad_permanent_strain_limit_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--max-permanent-strain must be in (0, 50] %, got 0"
          2 $<TARGET_FILE:hilldem> t307 --max-permanent-strain 0 -o ${HILLDEM_T307_OUT}/bad5)
add_test(NAME cli.t307_refused_run_writes_nothing
  COMMAND bash -c "rm -rf \"$1\"; \"$0\" t307 --cycles 0 -o \"$1\" 2>/dev/null; test $? -eq 2 && test ! -e \"$1\""
          $<TARGET_FILE:hilldem> ${HILLDEM_T307_OUT}/refused)
# A miniature run end to end from the stored packed specimen: finalize, four sequences, the fit, the figure.
add_test(NAME cli.t307_miniature_run_exits_0
  COMMAND bash -c "rm -rf \"$1\"; mkdir -p \"$(dirname \"$1\")\"; \"$0\" t307 --specimen \"$2/labtests/mini_packed.csv\" --grading \"$2/labtests/fine.csv\" \
                   --sequences 0,1,7,11,14 --cycles 3 --averaged-cycles 2 --conditioning-cycles 1 --pulse-duration 5e-3 \
                   --rest-duration 2e-3 -o \"$1\" > \"$1.log\" && grep -q 'universal model M_r = k1' \"$1.log\" \
                   && test $(wc -l < \"$1/t307_sequences.csv\") -eq 5 && test -s \"$1/t307_fit.csv\" && test -s \"$1/t307_mr_theta.png\" \
                   && ! grep -q nan \"$1/t307_sequences.csv\""
          $<TARGET_FILE:hilldem> ${HILLDEM_T307_OUT}/mini ${HILLDEM_TEST_DATA})
# Like every command, t307 holds its output folder (io/output_folder.hpp): an unwritable one is bad input.
add_test(NAME cli.t307_unwritable_output_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "/proc/x" --stderr "cannot create the output folder"
          2 $<TARGET_FILE:hilldem> t307 -q --no-plot -o /proc/x)
set_tests_properties(cli.t307_unwritable_output_exits_2 cli.t307_zero_pulse_duration_exits_2 cli.t307_sequence_out_of_range_exits_2 cli.t307_averaged_above_cycles_exits_2
  cli.t307_wet_linear_exits_2 cli.t307_bad_permanent_strain_limit_exits_2 cli.t307_refused_run_writes_nothing
  cli.t307_miniature_run_exits_0 PROPERTIES TIMEOUT 120 LABELS "cli;labtests")
# The time-scaling figure: the miniature run and one with a longer pulse, M_r against the pulse duration
# (scripts/plot_t307.py --against-pulse prints each sequence's M_r at both pulses, in pulse order).
add_test(NAME cli.t307_plot_against_pulse
  COMMAND bash -c "rm -rf \"$1/pulse8\"; \"$0\" t307 --specimen \"$2/labtests/mini_packed.csv\" --grading \"$2/labtests/fine.csv\" \
                   --sequences 0,1,7 --cycles 3 --averaged-cycles 2 --conditioning-cycles 1 --pulse-duration 8e-3 \
                   --rest-duration 2e-3 -q --no-plot -o \"$1/pulse8\" > /dev/null \
                   && /usr/bin/python3 \"$3/scripts/plot_t307.py\" --against-pulse \"$1/mini\" \"$1/pulse8\" --out \"$1/pulse.png\" > \"$1/pulse.txt\" \
                   && grep -Eq '^fine_Hill seq 1: 5 ms \\(3 cycles\\) [0-9.]+ MPa, 8 ms \\(3 cycles\\) [0-9.]+ MPa$' \"$1/pulse.txt\" \
                   && grep -q '^fine_Hill seq 7: 5 ms' \"$1/pulse.txt\" && test -s \"$1/pulse.png\""
          $<TARGET_FILE:hilldem> ${HILLDEM_T307_OUT} ${HILLDEM_TEST_DATA} ${PROJECT_SOURCE_DIR})
set_tests_properties(cli.t307_miniature_run_exits_0 PROPERTIES FIXTURES_SETUP t307_mini)
set_tests_properties(cli.t307_plot_against_pulse PROPERTIES FIXTURES_REQUIRED t307_mini TIMEOUT 120 LABELS "cli;labtests")
