# ---- mpi: the domain decomposition (docs/mpi.md), only with HILLDEM_MPI ----
# Every test runs under mpirun with 1, 2, 3 and 4 ranks, oversubscribed (this machine has 2 cores) and
# allowed as root (OpenMPI refuses root otherwise), one thread a rank.
set(HILLDEM_MPIRUN ${MPIEXEC_EXECUTABLE} --allow-run-as-root --oversubscribe)
add_executable(hilldem_mpi_tests mpi/test_domain.cpp mpi/gtest_main.cpp)
target_link_libraries(hilldem_mpi_tests PRIVATE hilldem_parallel GTest::gtest)
# The lab-test drivers (finalize, make_wet, triaxial, T 307, genesis from a seed) over N ranks against
# one process (tests/mpi/test_lab_over_ranks.cpp).
add_executable(hilldem_mpi_lab_tests mpi/test_lab_over_ranks.cpp mpi/gtest_main.cpp)
target_link_libraries(hilldem_mpi_lab_tests PRIVATE hilldem_parallel GTest::gtest)
target_compile_definitions(hilldem_mpi_lab_tests PRIVATE HILLDEM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
foreach(ranks 1 2 3 4)
  add_test(NAME mpi.lab_drivers_${ranks}_ranks COMMAND ${HILLDEM_MPIRUN} -np ${ranks} $<TARGET_FILE:hilldem_mpi_lab_tests>)
  set_tests_properties(mpi.lab_drivers_${ranks}_ranks PROPERTIES TIMEOUT 600 LABELS mpi ENVIRONMENT "OMP_NUM_THREADS=1")
endforeach()
foreach(ranks 1 2 3 4)
  # The bench bed decomposed gives the digest of one process (cli.bench_digest_*).
  add_test(NAME mpi.bench_digest_${ranks}_ranks
    COMMAND ${HILLDEM_EXPECT_EXIT} --stdout "digest=${HILLDEM_BENCH_DIGEST}" --stdout "ranks=${ranks} "
            0 ${HILLDEM_MPIRUN} -np ${ranks} $<TARGET_FILE:hilldem> bench --steps 60 --warmup 0 --threads 1 --digest)
  # Balls sliding across the sub-domains keep their rows' history: bitwise the whole run.
  add_test(NAME mpi.sliding_across_ranks_${ranks}_ranks
    COMMAND ${HILLDEM_MPIRUN} -np ${ranks} $<TARGET_FILE:hilldem_mpi_tests>)
  # The bench bed as clumps (pebble pairs) decomposed: one process's digest (cli.bench_pair_bed_digest_*).
  add_test(NAME mpi.bench_pair_bed_digest_${ranks}_ranks
    COMMAND ${HILLDEM_EXPECT_EXIT} --stdout "digest=${HILLDEM_PAIR_BED_DIGEST}" --stdout "ranks=${ranks} "
            0 ${HILLDEM_MPIRUN} -np ${ranks} $<TARGET_FILE:hilldem> bench --steps 60 --warmup 0 --threads 1 --digest --clumps pairs)
  set_tests_properties(mpi.bench_digest_${ranks}_ranks mpi.bench_pair_bed_digest_${ranks}_ranks mpi.sliding_across_ranks_${ranks}_ranks
    PROPERTIES TIMEOUT 300 LABELS mpi ENVIRONMENT "OMP_NUM_THREADS=1")
endforeach()
# Scenarios under `hilldem run` over N ranks: every checkpoint's state digest (the one after
# make_wet included), the history and the probes are one process's. A wet hill bed in a box under a
# servo lid (make_wet, set_servo, histories, probes, checkpoints), and a small triaxial test.
set(HILLDEM_MPI_SCENARIO bash ${CMAKE_CURRENT_SOURCE_DIR}/mpi/scenario_over_ranks.sh $<TARGET_FILE:hilldem>)
foreach(ranks 1 2 3 4)
  add_test(NAME mpi.wet_servo_run_${ranks}_ranks
    COMMAND ${HILLDEM_MPI_SCENARIO} ${CMAKE_CURRENT_BINARY_DIR}/mpi_wet_servo_${ranks}
            ${CMAKE_CURRENT_SOURCE_DIR}/mpi/wet_servo_box.toml run ${ranks})
  # A small triaxial test: a radial servo on the cell and an axial one on the top platen.
  add_test(NAME mpi.triaxial_servos_run_${ranks}_ranks
    COMMAND ${HILLDEM_MPI_SCENARIO} ${CMAKE_CURRENT_BINARY_DIR}/mpi_triaxial_${ranks}
            ${CMAKE_CURRENT_SOURCE_DIR}/mpi/triaxial_servos.toml run ${ranks})
  # Stages that impose balls' motion and position (translate, rotate, set): a plough ball dragged
  # across the sub-domains' cuts.
  add_test(NAME mpi.moving_balls_run_${ranks}_ranks
    COMMAND ${HILLDEM_MPI_SCENARIO} ${CMAKE_CURRENT_BINARY_DIR}/mpi_moving_balls_${ranks}
            ${CMAKE_CURRENT_SOURCE_DIR}/mpi/moving_balls.toml run ${ranks})
  # Clumps thrown about a box: they migrate between the ranks with their state and pebbles.
  add_test(NAME mpi.clumps_thrown_run_${ranks}_ranks
    COMMAND ${HILLDEM_MPI_SCENARIO} ${CMAKE_CURRENT_BINARY_DIR}/mpi_clumps_thrown_${ranks}
            ${CMAKE_CURRENT_SOURCE_DIR}/mpi/clumps_thrown.toml run ${ranks})
  list(APPEND HILLDEM_MPI_SCENARIO_TESTS mpi.wet_servo_run_${ranks}_ranks mpi.triaxial_servos_run_${ranks}_ranks
       mpi.moving_balls_run_${ranks}_ranks mpi.clumps_thrown_run_${ranks}_ranks)
endforeach()
# examples/assembly_27.toml (hill grains in a box of facets, the automatic time step, solve) on 2 and 4.
foreach(ranks 2 4)
  add_test(NAME mpi.assembly_27_run_${ranks}_ranks
    COMMAND ${HILLDEM_MPI_SCENARIO} ${CMAKE_CURRENT_BINARY_DIR}/mpi_assembly_27_${ranks}
            ${PROJECT_SOURCE_DIR}/examples/assembly_27.toml run ${ranks})
  list(APPEND HILLDEM_MPI_SCENARIO_TESTS mpi.assembly_27_run_${ranks}_ranks)
endforeach()
# The wet bed's checkpoints from 4 ranks (after make_wet, and in the middle of a stage) resumed on 2 ranks, on
# 1 and without mpirun: the uninterrupted run's final digest, history and probes.
add_test(NAME mpi.checkpoint_of_4_ranks_resumes_on_2_and_1
  COMMAND ${HILLDEM_MPI_SCENARIO} ${CMAKE_CURRENT_BINARY_DIR}/mpi_wet_servo_resume
          ${CMAKE_CURRENT_SOURCE_DIR}/mpi/wet_servo_box.toml resume)
# The moving balls' checkpoints from 4 ranks in the middle of the translate and of the rotate stage
# (the fixities to restore at the stage's end saved in them) resumed likewise.
add_test(NAME mpi.moving_balls_checkpoint_of_4_ranks_resumes_on_2_and_1
  COMMAND ${HILLDEM_MPI_SCENARIO} ${CMAKE_CURRENT_BINARY_DIR}/mpi_moving_balls_resume
          ${CMAKE_CURRENT_SOURCE_DIR}/mpi/moving_balls.toml resume 000005 000009)
# The thrown clumps' checkpoints from 4 ranks in flight (step 9,000) and after the set stage (step 20,000).
add_test(NAME mpi.clumps_checkpoint_of_4_ranks_resumes_on_2_and_1
  COMMAND ${HILLDEM_MPI_SCENARIO} ${CMAKE_CURRENT_BINARY_DIR}/mpi_clumps_thrown_resume
          ${CMAKE_CURRENT_SOURCE_DIR}/mpi/clumps_thrown.toml resume 000004 000009)
list(APPEND HILLDEM_MPI_SCENARIO_TESTS mpi.checkpoint_of_4_ranks_resumes_on_2_and_1
     mpi.moving_balls_checkpoint_of_4_ranks_resumes_on_2_and_1 mpi.clumps_checkpoint_of_4_ranks_resumes_on_2_and_1)
string(REPLACE ";" " " HILLDEM_MPIRUN_LINE "${HILLDEM_MPIRUN}")
set_tests_properties(${HILLDEM_MPI_SCENARIO_TESTS} PROPERTIES TIMEOUT 300 LABELS mpi
  ENVIRONMENT "OMP_NUM_THREADS=1;MPIRUN=${HILLDEM_MPIRUN_LINE}")
# `hilldem triaxial` (a wet case from a saved specimen, and a genesis from the seed) and `hilldem t307`
# over N ranks: every CSV file they write is one process's, byte for byte (tests/mpi/lab_over_ranks.sh).
foreach(ranks 1 2 3 4)
  add_test(NAME mpi.lab_commands_${ranks}_ranks
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/mpi/lab_over_ranks.sh $<TARGET_FILE:hilldem>
            ${CMAKE_CURRENT_BINARY_DIR}/mpi_lab_${ranks} ${CMAKE_CURRENT_SOURCE_DIR}/data ${ranks})
  set_tests_properties(mpi.lab_commands_${ranks}_ranks PROPERTIES TIMEOUT 600 LABELS mpi
    ENVIRONMENT "OMP_NUM_THREADS=1;MPIRUN=${HILLDEM_MPIRUN_LINE}")
endforeach()
# Commands that are not decomposed run on rank 0 alone, and every rank ends with its status.
add_test(NAME mpi.check_on_two_ranks_runs_on_rank_0
  COMMAND ${HILLDEM_EXPECT_EXIT} --stdout "assembly_27.toml: valid (27 balls"
          0 ${HILLDEM_MPIRUN} -np 2 $<TARGET_FILE:hilldem> check ${PROJECT_SOURCE_DIR}/examples/assembly_27.toml)
add_test(NAME mpi.check_of_a_missing_file_on_two_ranks_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "cannot open the scenario file"
          2 ${HILLDEM_MPIRUN} -np 2 $<TARGET_FILE:hilldem> check ${PROJECT_SOURCE_DIR}/examples/no_such_file.toml)
set_tests_properties(mpi.check_on_two_ranks_runs_on_rank_0 mpi.check_of_a_missing_file_on_two_ranks_exits_2
  PROPERTIES TIMEOUT 120 LABELS mpi)
