# ---- mpi: the domain decomposition (docs/mpi.md), only with HILLDEM_MPI ----
# Every test runs under mpirun with 1, 2, 3 and 4 ranks, oversubscribed (this machine has 2 cores) and
# allowed as root (OpenMPI refuses root otherwise), one thread a rank.
set(HILLDEM_MPIRUN ${MPIEXEC_EXECUTABLE} --allow-run-as-root --oversubscribe)
add_executable(hilldem_mpi_tests mpi/test_domain.cpp)
target_link_libraries(hilldem_mpi_tests PRIVATE hilldem_parallel GTest::gtest)
foreach(ranks 1 2 3 4)
  # The bench bed decomposed gives the digest of one process (cli.bench_digest_*).
  add_test(NAME mpi.bench_digest_${ranks}_ranks
    COMMAND ${HILLDEM_EXPECT_EXIT} --stdout "digest=${HILLDEM_BENCH_DIGEST}" --stdout "ranks=${ranks} "
            0 ${HILLDEM_MPIRUN} -np ${ranks} $<TARGET_FILE:hilldem> bench --steps 60 --warmup 0 --threads 1 --digest)
  # Balls sliding across the sub-domains keep their rows' history: bitwise the whole run.
  add_test(NAME mpi.sliding_across_ranks_${ranks}_ranks
    COMMAND ${HILLDEM_MPIRUN} -np ${ranks} $<TARGET_FILE:hilldem_mpi_tests>)
  set_tests_properties(mpi.bench_digest_${ranks}_ranks mpi.sliding_across_ranks_${ranks}_ranks
    PROPERTIES TIMEOUT 300 LABELS mpi ENVIRONMENT "OMP_NUM_THREADS=1")
endforeach()
# Commands that do not run decomposed yet say so once, with exit status 2.
add_test(NAME mpi.run_on_two_ranks_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "does not run decomposed"
          2 ${HILLDEM_MPIRUN} -np 2 $<TARGET_FILE:hilldem> check ${PROJECT_SOURCE_DIR}/examples/assembly_27.toml)
set_tests_properties(mpi.run_on_two_ranks_exits_2 PROPERTIES TIMEOUT 120 LABELS mpi)
