// A miniature packed specimen for the lab-test suites: about 370 grains of 5.6-8 mm (C5n scaled by
// 0.4) packed to 150 kPa in the memo's vessel scaled by 0.3 (51 mm x 72 mm), seed 42. Loaded from
// tests/data/labtests/mini_packed.csv (made by `hilldem triaxial --grading tests/data/labtests/fine.csv
// --scale 0.3 --seed 42`, file specimens/fine_packed.csv) so that each test starts in milliseconds;
// Genesis.* tests pack it from the cloud themselves.
#pragma once

#include <string>

#include "hilldem/labtests/specimen_io.hpp"

namespace hilldem::testing {

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

}  // namespace hilldem::testing
