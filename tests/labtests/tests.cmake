# Lab tests (src/hilldem/labtests/): grading, servo, genesis, triaxial, study; included from
# tests/CMakeLists.txt. Every test runs on a miniature specimen (about 340 grains): seconds, not minutes.
add_executable(hilldem_labtests_tests
  labtests/test_gsd.cpp
  labtests/test_servo.cpp
  labtests/test_triaxial.cpp
  labtests/test_measure.cpp
  labtests/test_genesis.cpp
  labtests/test_clump_specimens.cpp
  labtests/test_clump_mix.cpp
)
target_link_libraries(hilldem_labtests_tests PRIVATE hilldem::core GTest::gtest_main)
target_compile_definitions(hilldem_labtests_tests PRIVATE HILLDEM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_compile_options(hilldem_labtests_tests PRIVATE -Wall -Wextra -Wpedantic)
# One thread per test: ctest runs tests side by side, and these specimens are too small to gain from more.
gtest_discover_tests(hilldem_labtests_tests DISCOVERY_TIMEOUT 60
  PROPERTIES TIMEOUT 120 LABELS labtests ENVIRONMENT OMP_NUM_THREADS=1)

# `hilldem triaxial`: bad options stop with exit status 2 before any work (nothing printed, no folder).
set(HILLDEM_TRIAXIAL_OUT ${CMAKE_CURRENT_BINARY_DIR}/triaxial_cli_out)
add_test(NAME cli.triaxial_unknown_grading_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "unknown grading 'C5x'" --stderr "choose C5n, C5b" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --grading C5x -o ${HILLDEM_TRIAXIAL_OUT}/bad1)
add_test(NAME cli.triaxial_negative_packing_pressure_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--packing-pressure must be a finite number > 0 Pa, got -150000" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --packing-pressure=-150e3 -o ${HILLDEM_TRIAXIAL_OUT}/bad2)
add_test(NAME cli.triaxial_nan_packing_pressure_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--packing-pressure must be a finite number > 0 Pa, got nan" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --packing-pressure nan -o ${HILLDEM_TRIAXIAL_OUT}/bad10)
add_test(NAME cli.triaxial_inf_packing_pressure_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--packing-pressure must be a finite number > 0 Pa, got inf" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --packing-pressure inf -o ${HILLDEM_TRIAXIAL_OUT}/bad11)
add_test(NAME cli.triaxial_zero_confinement_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--confinement must be a finite number > 0 Pa, got 0" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --confinement 0 -o ${HILLDEM_TRIAXIAL_OUT}/bad12)
add_test(NAME cli.triaxial_nan_confinement_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--confinement must be a finite number > 0 Pa, got nan" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --confinement nan -o ${HILLDEM_TRIAXIAL_OUT}/bad13)
add_test(NAME cli.triaxial_negative_inf_confinement_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--confinement must be a finite number > 0 Pa, got -inf" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --confinement=-inf -o ${HILLDEM_TRIAXIAL_OUT}/bad14)
# --pressure (packing pressure and confinement at once) is gone: refused like any unknown option.
add_test(NAME cli.triaxial_pressure_option_is_gone_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--pressure" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --pressure 150e3 -o ${HILLDEM_TRIAXIAL_OUT}/bad15)
add_test(NAME cli.triaxial_pack_linear_with_specimen_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--pack-linear and --specimen"
          2 $<TARGET_FILE:hilldem> triaxial --pack-linear --specimen ${HILLDEM_TEST_DATA}/labtests/mini_packed.csv
            --grading ${HILLDEM_TEST_DATA}/labtests/fine.csv -o ${HILLDEM_TRIAXIAL_OUT}/bad16)
add_test(NAME cli.triaxial_cycles_out_of_order_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "cycle strains must be positive and increasing" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --cycles 0.05,0.02 -o ${HILLDEM_TRIAXIAL_OUT}/bad3)
add_test(NAME cli.triaxial_final_below_cycles_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "final strain (0.03 %) must exceed the last cycle strain (0.05 %)"
          2 $<TARGET_FILE:hilldem> triaxial --final-strain 0.03 -o ${HILLDEM_TRIAXIAL_OUT}/bad4)
add_test(NAME cli.triaxial_wet_linear_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--wet needs the hill material"
          2 $<TARGET_FILE:hilldem> triaxial --material linear --wet -o ${HILLDEM_TRIAXIAL_OUT}/bad5)
add_test(NAME cli.triaxial_unknown_material_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "unknown material 'steel'"
          2 $<TARGET_FILE:hilldem> triaxial --material steel -o ${HILLDEM_TRIAXIAL_OUT}/bad6)
add_test(NAME cli.triaxial_bad_grading_file_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "volume fractions sum to 0.9"
          2 $<TARGET_FILE:hilldem> triaxial --grading ${HILLDEM_TEST_DATA}/labtests/bad_sum.csv -o ${HILLDEM_TRIAXIAL_OUT}/bad7)
add_test(NAME cli.triaxial_missing_specimen_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "cannot open the specimen file"
          2 $<TARGET_FILE:hilldem> triaxial --specimen ${HILLDEM_TEST_DATA}/labtests/no_such_specimen.csv -o ${HILLDEM_TRIAXIAL_OUT}/bad8)
add_test(NAME cli.triaxial_bad_density_scaling_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "density scaling factor must be 0 (off) or in [1, 50], got 0.5" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --density-scaling 0.5 -o ${HILLDEM_TRIAXIAL_OUT}/bad9)
# A refused run creates no output folder.
add_test(NAME cli.triaxial_refused_run_writes_nothing
  COMMAND bash -c "rm -rf \"$1\"; \"$0\" triaxial --cycles 0.05,0.02 -o \"$1\" 2>/dev/null; test $? -eq 2 && test ! -e \"$1\""
          $<TARGET_FILE:hilldem> ${HILLDEM_TRIAXIAL_OUT}/refused)
# A miniature run end to end from the stored packed specimen: finalize, wet, one cycle (a few seconds).
add_test(NAME cli.triaxial_miniature_case_exits_0
  COMMAND ${HILLDEM_EXPECT_EXIT} --stdout "resilient modulus M_r (unload fit)" --stdout "| fine_Hill_wet |"
          --stdout "wet contacts" --stdout "summary:"
          0 $<TARGET_FILE:hilldem> triaxial --specimen ${HILLDEM_TEST_DATA}/labtests/mini_packed.csv
            --grading ${HILLDEM_TEST_DATA}/labtests/fine.csv --wet --cycles 0.02 --final-strain 0.1 --strain-rate 0.1
            --final-strain-rate 0.5 --threads 1 --no-plot -o ${HILLDEM_TRIAXIAL_OUT}/mini)
# Genesis only, in vessels too small for an interior measured one D_max in: never `nan`. The memo's
# vessel scaled by 0.15 (25 mm x 36 mm, about 45 grains of 5.6-8 mm): not even D50 fits, "n/a";
# packed with hill contacts (the default) and with --pack-linear.
add_test(NAME cli.triaxial_small_vessel_prints_no_nan
  COMMAND ${HILLDEM_EXPECT_EXIT} --not-stdout "nan" --stdout "n/a (vessel radius under D_max + D50" --stdout "| fine | hill |"
          --stdout "packing contacts hill with friction 0"
          0 $<TARGET_FILE:hilldem> triaxial --pack-only --grading ${HILLDEM_TEST_DATA}/labtests/fine.csv --scale 0.15
            --seed 42 --threads 1 -o ${HILLDEM_TRIAXIAL_OUT}/small_hill)
add_test(NAME cli.triaxial_pack_linear_packs_with_linear_contacts
  COMMAND ${HILLDEM_EXPECT_EXIT} --not-stdout "nan" --stdout "| fine | linear |" --stdout "packing contacts linear with friction 0"
          0 $<TARGET_FILE:hilldem> triaxial --pack-only --pack-linear --grading ${HILLDEM_TEST_DATA}/labtests/fine.csv
            --scale 0.15 --seed 42 --threads 1 -o ${HILLDEM_TRIAXIAL_OUT}/small_linear)
# A confinement apart from the packing pressure: the finalized miniature specimen is brought to it, then tested at it.
add_test(NAME cli.triaxial_confinement_apart_from_packing_pressure_exits_0
  COMMAND ${HILLDEM_EXPECT_EXIT} --stdout "confine fine_Hill" --stdout "triaxial: confinement 100 kPa" --not-stdout "nan"
          0 $<TARGET_FILE:hilldem> triaxial --specimen ${HILLDEM_TEST_DATA}/labtests/mini_packed.csv
            --grading ${HILLDEM_TEST_DATA}/labtests/fine.csv --confinement 100e3 --packing-pressure 150e3 --cycles 0.02
            --final-strain 0.04 --strain-rate 0.1 --final-strain-rate 0.5 --threads 1 --no-plot -o ${HILLDEM_TRIAXIAL_OUT}/confine)
set_tests_properties(cli.triaxial_confinement_apart_from_packing_pressure_exits_0 cli.triaxial_nan_packing_pressure_exits_2 cli.triaxial_inf_packing_pressure_exits_2
  cli.triaxial_zero_confinement_exits_2 cli.triaxial_nan_confinement_exits_2 cli.triaxial_negative_inf_confinement_exits_2
  cli.triaxial_pressure_option_is_gone_exits_2 cli.triaxial_pack_linear_with_specimen_exits_2
  cli.triaxial_small_vessel_prints_no_nan cli.triaxial_pack_linear_packs_with_linear_contacts
  PROPERTIES TIMEOUT 120 LABELS "cli;labtests")
set_tests_properties(cli.triaxial_unknown_grading_exits_2 cli.triaxial_negative_packing_pressure_exits_2
  cli.triaxial_cycles_out_of_order_exits_2 cli.triaxial_final_below_cycles_exits_2 cli.triaxial_wet_linear_exits_2
  cli.triaxial_unknown_material_exits_2 cli.triaxial_bad_grading_file_exits_2 cli.triaxial_missing_specimen_exits_2
  cli.triaxial_miniature_case_exits_0 cli.triaxial_refused_run_writes_nothing cli.triaxial_bad_density_scaling_exits_2
  PROPERTIES TIMEOUT 120 LABELS "cli;labtests")
# The figures script on that run's output (Debian's python3 with python3-matplotlib, from scripts/setup.sh).
add_test(NAME cli.triaxial_plot_script_writes_figures
  COMMAND bash -c "/usr/bin/python3 \"$0\" \"$1\" && test -s \"$1/fig18_grading.png\" && test -s \"$1/fig20_stress_strain.png\" && test -s \"$1/fig21_cycles.png\""
          ${PROJECT_SOURCE_DIR}/scripts/plot_triaxial.py ${HILLDEM_TRIAXIAL_OUT}/mini)
set_tests_properties(cli.triaxial_miniature_case_exits_0 PROPERTIES FIXTURES_SETUP triaxial_mini)
set_tests_properties(cli.triaxial_plot_script_writes_figures PROPERTIES FIXTURES_REQUIRED triaxial_mini TIMEOUT 120 LABELS "cli;labtests")
# Physically broken specimen files (tests/cli/broken_specimen.sh makes them from the miniature one):
# refused with exit status 2 naming the file, line, column, range and value; a packed state far from
# the file's pressure fails with exit status 1 and the reason, no summary.
set(HILLDEM_BROKEN_SPECIMEN ${CMAKE_CURRENT_SOURCE_DIR}/cli/broken_specimen.sh)
foreach(case "one_centre|2|have one centre" "grown|2|of the smaller diameter; at most 1 % is a packed state"
        "poisson|2|pois_ratio[-] must be in (-1, 0.5], got 0.7" "modulus|2|young_mod[Pa] must be in [100000, 1.2e+12], got 1e+300"
        "tiny|2|radius[m] must be in [1e-06, 1], got 1e-300"
        "pressure|1|the packed specimen is physically impossible: sigma_r 149.885 kPa, more than 25 % from the target 1.5 kPa")
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 mode)
  list(GET parts 1 status)
  list(GET parts 2 text)
  set(file ${HILLDEM_TRIAXIAL_OUT}/broken/${mode}.csv)
  add_test(NAME cli.triaxial_broken_specimen_${mode}_exits_${status}
    COMMAND bash -c "bash \"$0\" \"$1\" \"$2\" \"$3\" && shift 4 && exec \"$@\""
            ${HILLDEM_BROKEN_SPECIMEN} ${mode} ${HILLDEM_TEST_DATA}/labtests/mini_packed.csv ${file}
            ${HILLDEM_EXPECT_EXIT} --stderr "${text}" --stderr "${file}" --not-stdout "| fine_Hill |"
            ${status} $<TARGET_FILE:hilldem> triaxial --specimen ${file} --grading ${HILLDEM_TEST_DATA}/labtests/fine.csv
            --cycles 0.02 --final-strain 0.04 --strain-rate 0.1 --final-strain-rate 0.5 --threads 1 --no-plot
            -o ${HILLDEM_TRIAXIAL_OUT}/broken/out_${mode})
  set_tests_properties(cli.triaxial_broken_specimen_${mode}_exits_${status} PROPERTIES TIMEOUT 120 LABELS "cli;labtests")
endforeach()
# Options: a sweep of confinements, the T 307 vessel, the minimum grain count; bad values exit 2.
add_test(NAME cli.triaxial_confinement_sweep_runs_each_case_at_each
  COMMAND ${HILLDEM_EXPECT_EXIT} --stdout "| fine_Hill_100kPa |" --stdout "| fine_Hill_150kPa |" --stdout "triaxial: confinement 100 kPa"
          --not-stdout "nan"
          0 $<TARGET_FILE:hilldem> triaxial --specimen ${HILLDEM_TEST_DATA}/labtests/mini_packed.csv
            --grading ${HILLDEM_TEST_DATA}/labtests/fine.csv --confinement 100e3,150e3 --cycles 0.02
            --final-strain 0.04 --strain-rate 0.1 --final-strain-rate 0.5 --threads 1 --jobs 1 --no-plot -o ${HILLDEM_TRIAXIAL_OUT}/sweep)
add_test(NAME cli.triaxial_repeated_confinement_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--confinement lists 100000 Pa twice" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --confinement 100e3,100e3 -o ${HILLDEM_TRIAXIAL_OUT}/bad17)
add_test(NAME cli.triaxial_negative_confinement_in_a_sweep_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--confinement must be a finite number > 0 Pa, got -5" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --confinement=100e3,-5 -o ${HILLDEM_TRIAXIAL_OUT}/bad18)
add_test(NAME cli.triaxial_unknown_vessel_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "unknown vessel 'cube': choose memo (170 mm x 240 mm) or t307" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --vessel cube -o ${HILLDEM_TRIAXIAL_OUT}/bad19)
# The T 307 shape (H/D = 2) scaled by 0.15: 23 mm x 46 mm.
add_test(NAME cli.triaxial_t307_vessel_has_h_over_d_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stdout "in a 23 mm x 46 mm vessel" --not-stdout "nan"
          0 $<TARGET_FILE:hilldem> triaxial --pack-only --vessel t307 --grading ${HILLDEM_TEST_DATA}/labtests/fine.csv --scale 0.15
            --seed 42 --threads 1 -o ${HILLDEM_TRIAXIAL_OUT}/t307)
set_tests_properties(cli.triaxial_confinement_sweep_runs_each_case_at_each cli.triaxial_repeated_confinement_exits_2
  cli.triaxial_negative_confinement_in_a_sweep_exits_2 cli.triaxial_unknown_vessel_exits_2 cli.triaxial_t307_vessel_has_h_over_d_2
  PROPERTIES TIMEOUT 120 LABELS "cli;labtests")

# SIGINT / SIGTERM stop a lab test after the cycle it is in: exit 128 + N, a message naming the
# signal, the step and the packed specimens kept, no results (tests/cli/lab_stop.sh).
foreach(mode t307 packing)
  add_test(NAME cli.lab_test_stopped_by_signal_${mode}
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/lab_stop.sh $<TARGET_FILE:hilldem> ${HILLDEM_TEST_DATA} ${mode})
  set_tests_properties(cli.lab_test_stopped_by_signal_${mode} PROPERTIES TIMEOUT 300 LABELS "cli;labtests;reliability"
                       ENVIRONMENT OMP_NUM_THREADS=1)
endforeach()

# Clumped grains (docs/clumps.md, "Specimens of clumps"): what does not apply is refused before any work.
add_test(NAME cli.triaxial_unknown_clump_template_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "unknown clump template 'dodecahedron'; known: sphere, elongated2, elongated3, ellipsoid, cube" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --clump-template dodecahedron -o ${HILLDEM_TRIAXIAL_OUT}/clump1)
add_test(NAME cli.triaxial_clump_density_scaling_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "density scaling does not apply to clumps" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --clump-template elongated2 --density-scaling 2 -o ${HILLDEM_TRIAXIAL_OUT}/clump2)
add_test(NAME cli.triaxial_clump_size_without_template_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--clump-size needs --clump-template" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --clump-size enclosing -o ${HILLDEM_TRIAXIAL_OUT}/clump3)
add_test(NAME cli.triaxial_clumps_with_a_ball_specimen_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "the file's grains are balls"
          2 $<TARGET_FILE:hilldem> triaxial --clump-template elongated2 --specimen ${HILLDEM_TEST_DATA}/labtests/mini_packed.csv
            --grading ${HILLDEM_TEST_DATA}/labtests/fine.csv -o ${HILLDEM_TRIAXIAL_OUT}/clump4)
# A mix of templates (NAME:FRACTION,...): bad fractions and names refused naming the option and the
# range; a good one packs, says the mix and writes each clump's template into the specimen file.
add_test(NAME cli.triaxial_clump_mix_bad_sum_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--clump-template: the fractions must sum to 1 (within 1e-09), got 1.1" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --clump-template elongated2:0.6,sphere:0.5 -o ${HILLDEM_TRIAXIAL_OUT}/clump5)
add_test(NAME cli.triaxial_clump_mix_bad_fraction_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--clump-template: the fraction of sphere must be in (0, 1] (of the solid volume), got 0"
          --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --clump-template elongated2:1,sphere:0 -o ${HILLDEM_TRIAXIAL_OUT}/clump6)
add_test(NAME cli.triaxial_clump_mix_unknown_name_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--clump-template: unknown clump template 'ball'; known: sphere, elongated2" --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --clump-template ball:0.5,sphere:0.5 -o ${HILLDEM_TRIAXIAL_OUT}/clump7)
add_test(NAME cli.triaxial_clump_mix_malformed_exits_2
  COMMAND ${HILLDEM_EXPECT_EXIT} --stderr "--clump-template: expected NAME or NAME:FRACTION,NAME:FRACTION,..." --not-stdout "cloud"
          2 $<TARGET_FILE:hilldem> triaxial --clump-template elongated2,sphere -o ${HILLDEM_TRIAXIAL_OUT}/clump8)
add_test(NAME cli.triaxial_clump_mix_packs
  COMMAND bash -c "set -e; rm -rf \"$1\"; mkdir -p \"$(dirname \"$1\")\"; \"$0\" triaxial --pack-only --grading \"$2\" --scale 0.15 --seed 42 --threads 1 --jobs 1 \
          --clump-template elongated2:0.5,sphere:0.5 -o \"$1\" > \"$1.log\"; \
          grep -F 'grains: clumps of a mix by solid volume of elongated2 0.5, sphere 0.5' \"$1.log\"; \
          grep -F 'clumps of a mix by solid volume of elongated2 0.5, sphere 0.5 (realised 0.' \"$1.log\"; \
          f=\"$1/specimens/fine_hill_packed.csv\"; grep -Fx 'clump_template,elongated2:0.5,sphere:0.5' \"$f\"; \
          grep -F 'id,template,x[m]' \"$f\"; grep -qE '^[0-9]+,sphere,' \"$f\"; grep -qE '^[0-9]+,elongated2,' \"$f\"; \
          \"$0\" triaxial --specimen \"$f\" --grading \"$2\" --clump-template elongated2 -o \"$1/again\" 2>&1 \
            | grep -F \"the file's grains are clumps of elongated2:0.5,sphere:0.5\""
          $<TARGET_FILE:hilldem> ${HILLDEM_TRIAXIAL_OUT}/clump_mix ${HILLDEM_TEST_DATA}/labtests/fine.csv)
set_tests_properties(cli.triaxial_unknown_clump_template_exits_2 cli.triaxial_clump_density_scaling_exits_2
  cli.triaxial_clump_size_without_template_exits_2 cli.triaxial_clumps_with_a_ball_specimen_exits_2
  cli.triaxial_clump_mix_bad_sum_exits_2 cli.triaxial_clump_mix_bad_fraction_exits_2 cli.triaxial_clump_mix_unknown_name_exits_2
  cli.triaxial_clump_mix_malformed_exits_2 cli.triaxial_clump_mix_packs
  PROPERTIES TIMEOUT 120 LABELS "cli;labtests;clumps")
