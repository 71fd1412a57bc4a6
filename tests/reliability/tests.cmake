# Issue 34, "nothing lost, nothing silently wrong": output-folder locks, resume checks, torn files,
# graceful stop on signals, the stage-end checkpoint budget, input ranges, non-regular files and out
# of memory (tests/reliability/reliability.sh, tests/cli/kill_and_resume.sh, tests/cli/expect_exit.sh).
set(HILLDEM_RELIABILITY bash ${CMAKE_CURRENT_SOURCE_DIR}/reliability/reliability.sh $<TARGET_FILE:hilldem> ${HILLDEM_RESTART_BED})
foreach(c lock_held lock_two_runs second_signal resume_checks resume_elsewhere torn_files stage_end_budget out_of_memory)
  add_test(NAME reliability.${c} COMMAND ${HILLDEM_RELIABILITY} ${c})
  list(APPEND HILLDEM_RELIABILITY_TESTS reliability.${c})
endforeach()
# Item 4: SIGINT, SIGTERM, SIGHUP stop at a cycle with a checkpoint; the resumed run is bitwise the
# uninterrupted one.
foreach(sig INT TERM HUP)
  add_test(NAME reliability.resume_after_sig${sig}
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/kill_and_resume.sh $<TARGET_FILE:hilldem> ${HILLDEM_RESTART_BED} signal=${sig})
  list(APPEND HILLDEM_RELIABILITY_TESTS reliability.resume_after_sig${sig})
endforeach()
# Item 7: what passed `check` and failed in `run` is refused by both, exit status 2, naming the key.
set(HILLDEM_SED_BED "sed 's/^density = 2650/density = 1e-300/' ${HILLDEM_RESTART_BED}")
add_test(NAME reliability.check_tiny_density_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "material[1].density" --stderr "[0.001, 1e+06] [kg/m^3]" --stderr "1e-300"
          2 sh -c "${HILLDEM_SED_BED} > rel_density.toml && $<TARGET_FILE:hilldem> check rel_density.toml")
add_test(NAME reliability.run_far_position_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "ball[1].position" --stderr "[-1e+06, 1e+06] [m]" --not-stdout "[1/"
          2 sh -c "sed 's/^position = \\[-6.337883040e-03/position = [1e300/' ${HILLDEM_RESTART_BED} > rel_pos.toml && $<TARGET_FILE:hilldem> run rel_pos.toml -o rel_out/pos")
add_test(NAME reliability.check_huge_gravity_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "simulation.gravity" --stderr "[-10000, 10000] [m/s^2]"
          2 sh -c "sed 's/^gravity = .*/gravity = [0.0, 0.0, 1e300]/' ${HILLDEM_RESTART_BED} > rel_grav.toml && $<TARGET_FILE:hilldem> check rel_grav.toml")
add_test(NAME reliability.check_small_periodic_box_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "periodic_small.toml: key 'simulation.box_max'" --stderr "3 interaction lengths"
          2 sh -c "sed 's/^box_max = .*/box_max = [10e-3, 17.6e-3, 0.05]/' ${CMAKE_CURRENT_SOURCE_DIR}/data/restart/periodic_bed.toml > periodic_small.toml && $<TARGET_FILE:hilldem> check periodic_small.toml")
add_test(NAME reliability.check_history_file_dotdot_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "output.history_file" --stderr "got \"..\""
          2 sh -c "sed 's/^history_every = 50/history_every = 50\\nhistory_file = \"..\"/' ${HILLDEM_RESTART_BED} > rel_hf.toml && $<TARGET_FILE:hilldem> check rel_hf.toml")
add_test(NAME reliability.run_empty_output_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "-o: the output folder name is empty" 2 sh -c "$<TARGET_FILE:hilldem> run -q ${HILLDEM_RESTART_BED} -o ''")
add_test(NAME reliability.resume_empty_output_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "-o: the output folder name is empty" 2 sh -c "$<TARGET_FILE:hilldem> resume -q ${HILLDEM_TEST_DATA}/cli -o ''")
add_test(NAME reliability.check_unwritable_output_dir_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "key 'output.dir'" --stderr "is not a folder"
          2 sh -c "sed 's|^history_every = 50|history_every = 50\\ndir = \"/dev/null/out\"|' ${HILLDEM_RESTART_BED} > rel_dir.toml && $<TARGET_FILE:hilldem> check rel_dir.toml")
add_test(NAME reliability.triaxial_unwritable_output_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "/proc/x" --stderr "cannot create the output folder"
          2 $<TARGET_FILE:hilldem> triaxial -q --no-plot -o /proc/x)
# Item 8: NaN and inf on the command line are refused as the TOML keys refuse them.
foreach(opt blowup-fraction checkpoint-seconds)
  foreach(v nan inf)
    add_test(NAME reliability.run_${opt}_${v}_exits_2
      COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--${opt}: must be a finite number in [0, 1e+09]" --stderr "got ${v}"
              2 $<TARGET_FILE:hilldem> run -q ${HILLDEM_RESTART_BED} -o rel_out/nan --${opt} ${v})
    list(APPEND HILLDEM_RELIABILITY_TESTS reliability.run_${opt}_${v}_exits_2)
  endforeach()
endforeach()
add_test(NAME reliability.triaxial_nan_strain_rate_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--strain-rate: must be a finite number" 2 $<TARGET_FILE:hilldem> triaxial -q --no-plot --strain-rate nan)
# Item 9: non-regular files are refused before anything is read (a FIFO would block, /dev/zero
# would be read forever).
add_test(NAME reliability.resume_dev_zero_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "/dev/zero: is not a regular file (a device)" 2 timeout 20 $<TARGET_FILE:hilldem> resume /dev/zero)
add_test(NAME reliability.inspect_fifo_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "rel.fifo: is not a regular file (a FIFO)"
          2 sh -c "rm -f rel.fifo && mkfifo rel.fifo && timeout 20 $<TARGET_FILE:hilldem> inspect rel.fifo")
add_test(NAME reliability.inspect_folder_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "is a folder, not a checkpoint file" 2 $<TARGET_FILE:hilldem> inspect --digest ${HILLDEM_TEST_DATA})
list(APPEND HILLDEM_RELIABILITY_TESTS reliability.check_tiny_density_exits_2 reliability.run_far_position_exits_2
  reliability.check_huge_gravity_exits_2 reliability.check_small_periodic_box_exits_2 reliability.check_history_file_dotdot_exits_2
  reliability.run_empty_output_exits_2 reliability.resume_empty_output_exits_2 reliability.check_unwritable_output_dir_exits_2
  reliability.triaxial_unwritable_output_exits_2 reliability.triaxial_nan_strain_rate_exits_2 reliability.resume_dev_zero_exits_2
  reliability.inspect_fifo_exits_2 reliability.inspect_folder_exits_2)
set_tests_properties(${HILLDEM_RELIABILITY_TESTS} PROPERTIES TIMEOUT 180 LABELS "cli;io;reliability")
