// A miniature packed specimen for the lab-test suites: about 370 grains of 5.6-8 mm (C5n scaled by
// 0.4) packed to 150 kPa in the memo's vessel scaled by 0.3 (51 mm x 72 mm), seed 42. Loaded from
// tests/data/labtests/mini_packed.csv (made by `hilldem triaxial --grading tests/data/labtests/fine.csv
// --scale 0.3 --seed 42`, file specimens/fine_packed.csv) so that each test starts in milliseconds;
// Genesis.* tests pack it from the cloud themselves.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "hilldem/labtests/specimen_io.hpp"
#include "hilldem/labtests/study.hpp"

namespace hilldem::testing {

// A specimen's clumps read back (a file, a copy) are the original's to the bit: the clumps' centres,
// orientations, masses and inertias, the pebbles' body positions and radii, and their balls' positions.
inline void expect_same_clumps(const Simulation& a, const Simulation& b) {
  const ClumpBodies &x = a.clumps, &y = b.clumps;
  ASSERT_EQ(x.size(), y.size());
  ASSERT_EQ(x.pebbles.size(), y.pebbles.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(std::memcmp(&x.state.position[i], &y.state.position[i], sizeof(Vec3)), 0);
    EXPECT_EQ(std::memcmp(&x.state.orientation[i], &y.state.orientation[i], sizeof(Quat)), 0);
    EXPECT_EQ(x.state.mass[i], y.state.mass[i]);
    EXPECT_EQ(std::memcmp(&x.state.principal_inertia[i], &y.state.principal_inertia[i], sizeof(Vec3)), 0);
  }
  for (std::size_t k = 0; k < x.pebbles.size(); ++k) {
    EXPECT_EQ(std::memcmp(&x.pebbles.body_position[k], &y.pebbles.body_position[k], sizeof(Vec3)), 0);
    EXPECT_EQ(x.pebbles.radius[k], y.pebbles.radius[k]);
    EXPECT_EQ(std::memcmp(&a.balls.position[x.ball[k]], &b.balls.position[y.ball[k]], sizeof(Vec3)), 0);
  }
}

inline GenesisSpec mini_spec() {
  GenesisSpec g;
  g.grading = resolve_grading(std::string(HILLDEM_SOURCE_DIR) + "/tests/data/labtests/fine.csv");
  g.vessel_radius = 0.3 * 0.085;
  g.vessel_height = 0.3 * 0.240;
  g.packing.seed = 42;
  return g;
}

inline const Specimen& mini_packed() {
  static const Specimen s = load_packed_specimen(std::string(HILLDEM_SOURCE_DIR) + "/tests/data/labtests/mini_packed.csv");
  return s;
}

// A study of the miniature specimen saved into a fresh folder `dir` (its output in dir/out); the
// caller sets the test.
inline StudySettings mini_study_from_saved(const std::filesystem::path& dir) {
  std::filesystem::remove_all(dir);
  const std::string file = (dir / "mini_packed.csv").string();
  save_packed_specimen(mini_packed(), mini_spec().packing, file);
  StudySettings st;
  st.genesis = mini_spec();
  st.min_grains = 0;  // the miniature vessel as it is
  st.specimen_file = file;
  st.output_dir = (dir / "out").string();
  return st;
}

}  // namespace hilldem::testing
