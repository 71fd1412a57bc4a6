// Specimens of clumped grains (issue 32, item 3; docs/clumps.md, "Specimens of clumps"): genesis
// makes clumps of the drawn sizes at random orientations, deterministic for a seed and a thread
// count; the porosity of clumps with pebble overlaps counted once, in the vessel and in a
// measurement region; coordination per clump; a packed specimen of clumps saved and loaded bitwise;
// a small clump specimen packs and runs a short triaxial test.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include "hilldem/bodies/clump_shapes.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/io/state_io.hpp"
#include "hilldem/labtests/measure_region.hpp"
#include "hilldem/labtests/specimen_io.hpp"
#include "hilldem/labtests/study.hpp"
#include "mini_specimen.hpp"

namespace hilldem {
namespace {

// The fine grading (5.6-8 mm) in the memo's vessel scaled by 0.2 (34 mm x 48 mm) as clumps: about 110.
GenesisSpec clump_spec(const std::string& name, SizeMeasure m = SizeMeasure::EqualVolumeDiameter) {
  GenesisSpec spec = testing::mini_spec();
  spec.vessel_radius = 0.2 * 0.085;
  spec.vessel_height = 0.2 * 0.240;
  spec.clump_mix = {{name, 1.0}};
  spec.clump_size = m;
  return spec;
}

// The sizes the cloud draws: sample_grains with the seed's first draws, largest first (the order the
// cloud places them in).
std::vector<double> drawn_sizes(const GenesisSpec& spec, double volume_factor) {
  Rng rng(spec.packing.seed);
  const double v = std::numbers::pi * spec.vessel_radius * spec.vessel_radius * spec.vessel_height;
  std::vector<double> d = sample_grains(spec.grading, spec.d_mult, (1.0 - spec.packing.cloud_porosity) * v / volume_factor, rng).diameters;
  std::stable_sort(d.begin(), d.end(), std::greater<>());
  return d;
}

TEST(ClumpGenesis, GrainsAreClumpsOfTheDrawnSizesAtRandomOrientations) {
  for (const SizeMeasure m : {SizeMeasure::EqualVolumeDiameter, SizeMeasure::EnclosingDiameter}) {
    SCOPED_TRACE(to_string(m));
    const GenesisSpec spec = clump_spec("elongated2", m);
    const Specimen s = make_cloud(spec);
    const ClumpTemplate unit = named_template("elongated2", spec.grain.density);
    const double du = unit.size(m);
    const double f = unit.volume / (std::numbers::pi * du * du * du / 6.0);
    if (m == SizeMeasure::EqualVolumeDiameter) EXPECT_DOUBLE_EQ(f, 1.0);
    else EXPECT_LT(f, 0.8);  // two unit pebbles 1 apart: V = 2 (4π/3) − lens, in a sphere of radius 1.5
    const std::vector<double> want = drawn_sizes(spec, f);
    const std::vector<double> got = s.diameters();
    ASSERT_EQ(s.sim.clumps.size(), want.size());
    ASSERT_EQ(got.size(), want.size());
    EXPECT_EQ(s.sim.clumps.pebbles.size(), 2 * want.size());
    EXPECT_EQ(grain_count(s.sim), want.size());
    EXPECT_GT(want.size(), 80u);
    for (std::size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(got[i], want[i], 1e-12 * want[i]) << i;
    // The cloud's solid volume is (1 − n_c) of the vessel by the clumps' union volumes, to one grain.
    const SpecimenState st = measure(s, false);
    EXPECT_NEAR(st.porosity, spec.packing.cloud_porosity, 1.5 * std::pow(want.front(), 3) / (0.2 * 0.085 * 0.2 * 0.085 * 0.2 * 0.240));
    // Random orientations: the long axis (principal axis 1, the smallest moment) along z is uniform,
    // |cos| of mean 1/2 (standard deviation 1/√12 of each, ~0.03 for the mean of ~100).
    double mean = 0.0;
    for (const Quat& q : s.sim.clumps.state.orientation) mean += std::abs(rotate(q, Vec3{1, 0, 0}).z);
    mean /= static_cast<double>(s.sim.clumps.size());
    EXPECT_NEAR(mean, 0.5, 0.1);
    // Deterministic for a seed; another seed gives other orientations.
    const Specimen again = make_cloud(spec);
    EXPECT_EQ(state_bytes(again.sim), state_bytes(s.sim));
    GenesisSpec other = spec;
    other.packing.seed = 43;
    EXPECT_NE(state_bytes(make_cloud(other).sim), state_bytes(s.sim));
  }
}

TEST(ClumpGenesis, WhatDoesNotApplyIsRefused) {
  GenesisSpec spec = clump_spec("dodecahedron");
  try {
    make_cloud(spec);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown clump template 'dodecahedron'; known: sphere, elongated2, elongated3, ellipsoid, cube"), std::string::npos)
        << e.what();
  }
  StudySettings st;
  st.genesis = clump_spec("elongated2");
  st.min_grains = 0;
  st.triaxial.density_scaling = 2.0;
  try {
    validate(st, {CaseSpec{}});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("density scaling does not apply to clumps"), std::string::npos) << e.what();
  }
}

// A region cut through two-pebble clumps: the part inside by columns against the exact solid of
// revolution (the union's radius at height z is max_k √(r² − (z − z_k)²), integrated in discs).
TEST(ClumpMeasure, VolumeInsideARegionOfAClumpCutByAPlaneAndByTheMantle) {
  const double r = 1e-3, d = 1e-3;  // elongated2 scaled: pebbles of radius 1 mm, centres 1 mm apart
  const double volume = named_template("elongated2", 1.0).scaled_by(r).volume;
  auto below = [&](double zc, double z) {  // the union (axis z, centre zc) below height z, by 2e5 discs
    const int n = 200000;
    const double lo = zc - d / 2 - r, hi = std::min(z, zc + d / 2 + r), h = (hi - lo) / n;
    double v = 0.0;
    for (int k = 0; k < n; ++k) {
      const double zz = lo + (k + 0.5) * h;
      const double a = std::max(r * r - (zz - (zc - d / 2)) * (zz - (zc - d / 2)), r * r - (zz - (zc + d / 2)) * (zz - (zc + d / 2)));
      if (a > 0) v += std::numbers::pi * a * h;
    }
    return v;
  };
  EXPECT_NEAR(below(0.0, 1.0), volume, 1e-6 * volume);  // the disc integration itself
  const MeasurementCylinder m{0.05, 0.0, 0.1};
  double worst = 0.0;
  for (const double zc : {-1.2e-3, -0.5e-3, 0.0, 0.3e-3, 1.1e-3, 1.9e-3}) {
    const std::vector<Vec3> c{{0.01, 0.0, zc - d / 2}, {0.01, 0.0, zc + d / 2}};
    const double inside = clump_volume_inside(m, c, {r, r}, volume);
    const double exact = volume - below(zc, 0.0);
    worst = std::max(worst, std::abs(inside - exact) / volume);
  }
  EXPECT_LT(worst, 2e-3);
  // Symmetric about the plane: exactly half (the columns' chords split at their middles).
  EXPECT_NEAR(clump_volume_inside(m, {{0.01, 0.0, -d / 2}, {0.01, 0.0, d / 2}}, {r, r}, volume), 0.5 * volume, 1e-12 * volume);
  // Lying along x across the mantle x = 0.05 m at its middle: half, to the curvature of the mantle
  // (the region's radius is 25 clump lengths).
  EXPECT_NEAR(clump_volume_inside(m, {{0.05 - d / 2, 0.0, 0.05}, {0.05 + d / 2, 0.0, 0.05}}, {r, r}, volume), 0.5 * volume,
              3e-3 * volume);
  // Wholly in, wholly out: exact; one pebble: the sphere's.
  EXPECT_DOUBLE_EQ(clump_volume_inside(m, {{0.0, 0.0, 0.05 - d / 2}, {0.0, 0.0, 0.05 + d / 2}}, {r, r}, volume), volume);
  EXPECT_DOUBLE_EQ(clump_volume_inside(m, {{0.0, 0.0, -0.01}, {0.0, 0.0, -0.01 + d}}, {r, r}, volume), 0.0);
  EXPECT_DOUBLE_EQ(clump_volume_inside(m, {{0.0, 0.0, 0.0}}, {r}, 4.0), sphere_volume_inside(m, Vec3{0.0, 0.0, 0.0}, r));
}

// A synthetic packing: elongated2 clumps (pebbles of radius 1 mm, centres 1 mm apart: union volume
// V, enclosing radius 1.5 mm) on a cubic lattice of spacing a = 3.2 mm (9 x 9 x 11 sites) at random
// orientations. In the cylinder of radius 20 mm and z in [−11.2, 11.2] mm the layers |k| ≤ 3 lie
// wholly inside (9.6 + 1.5 < 11.2) and the others wholly outside (12.8 − 1.5 > 11.2): the porosity
// is 1 − 9·9·7 V / the region's volume, to rounding. With the top at z = 4a the plane cuts layer 4
// through the clumps' centres: each is half inside, exactly (a clump is symmetric about its centre,
// and so is its grid of columns).
TEST(ClumpMeasure, InteriorAndVesselPorosityOfASyntheticClumpPacking) {
  Simulation sim;
  const double a = 3.2e-3;
  const ClumpTemplate t = named_template("elongated2", 2650.0).scaled_by(1e-3);
  EXPECT_NEAR(t.size(SizeMeasure::EnclosingDiameter), 3e-3, 1e-15);
  Rng rng(7);
  std::int64_t id = 1;
  for (int i = -4; i <= 4; ++i)
    for (int j = -4; j <= 4; ++j)
      for (int k = -5; k <= 5; ++k) {
        const double u1 = rng.uniform(), u2 = 2 * std::numbers::pi * rng.uniform(), u3 = 2 * std::numbers::pi * rng.uniform();
        ClumpInit c;
        c.first_ball_id = id;
        c.position = Vec3{i * a, j * a, k * a};
        c.orientation = normalized(Quat{std::sqrt(1 - u1) * std::sin(u2), std::sqrt(1 - u1) * std::cos(u2), std::sqrt(u1) * std::sin(u3),
                                        std::sqrt(u1) * std::cos(u3)});
        c.young_mod = 29e9;
        c.pois_ratio = 0.15;
        sim.clumps.add(sim.balls, t, c);
        id += 2;
      }
  const MeasurementCylinder m{20e-3, -11.2e-3, 11.2e-3};
  EXPECT_NEAR(interior_porosity(m, sim), 1.0 - 9 * 9 * 7 * t.volume / m.volume(), 1e-12);
  const MeasurementCylinder cut{20e-3, -11.2e-3, 4 * a};
  EXPECT_NEAR(interior_porosity(cut, sim), 1.0 - 9 * 9 * 7.5 * t.volume / cut.volume(), 1e-12);
  // The vessel porosity counts each clump's union volume once (its pebbles overlap by a lens).
  EXPECT_NEAR(solid_volume(sim), 9 * 9 * 11 * t.volume, 1e-12 * solid_volume(sim));
  EXPECT_LT(t.volume, 2 * 4.0 / 3.0 * std::numbers::pi * 1e-9 * 0.9);
  EXPECT_EQ(grain_count(sim), sim.clumps.size());
  // A ball beside them counts as a sphere.
  BallInit b;
  b.id = id;
  b.position = Vec3{0.0, 0.0, 0.0};
  b.radius = 1e-3;
  b.density = 2650.0;
  sim.balls.add(b);
  EXPECT_EQ(grain_count(sim), sim.clumps.size() + 1);
  EXPECT_NEAR(solid_volume(sim), 9 * 9 * 11 * t.volume + 4.0 / 3.0 * std::numbers::pi * 1e-9, 1e-12 * solid_volume(sim));
}

// Pack a small specimen of clumps with one thread and with two: the same bits; it reaches the
// pressure, counts coordination per clump, saves and loads bitwise, finalizes, wets and runs a
// short triaxial test.
TEST(ClumpGenesis, ASmallClumpSpecimenPacksDeterministicallyAndRunsATriaxialTest) {
  const GenesisSpec spec = clump_spec("elongated2");
  omp_set_num_threads(1);
  Specimen s = pack_specimen(spec, nullptr);
  omp_set_num_threads(2);
  const Specimen two = pack_specimen(spec, nullptr);
  omp_set_num_threads(1);
  EXPECT_EQ(state_bytes(two.sim), state_bytes(s.sim));
  const SpecimenState st = measure(s);
  EXPECT_EQ(st.grains, s.sim.clumps.size());
  EXPECT_NEAR(st.radial_stress, 150e3, 0.01 * 150e3);
  EXPECT_NEAR(st.top_stress, 150e3, 0.01 * 150e3);
  EXPECT_LE(st.ratio, spec.packing.equilibrium.ratio);
  EXPECT_GT(st.porosity, 0.25);
  EXPECT_LT(st.porosity, 0.55);
  // Coordination per clump: every touching pebble contact counted for both clumps.
  std::size_t touching = 0;
  for (std::size_t c = 0; c < s.sim.contacts.size(); ++c)
    touching += s.sim.contacts.exists[c] && s.sim.contacts.active[c] && s.sim.contacts.key[c].kind == ContactKind::BallBall &&
                s.sim.contacts.gap[c] < 0.0;
  EXPECT_DOUBLE_EQ(st.coordination, 2.0 * static_cast<double>(touching) / static_cast<double>(s.sim.clumps.size()));
  EXPECT_GT(st.coordination, 3.0);

  // Saved and loaded: the same clumps to the bit, the same text again.
  const std::string text = packed_specimen_text(s, spec.packing);
  EXPECT_NE(text.find("\nclump_template,elongated2\nclump_size,equal-volume\n"), std::string::npos);
  const Specimen back = parse_packed_specimen(text, "mem");
  EXPECT_EQ(packed_specimen_text(back, spec.packing), text);
  testing::expect_same_clumps(s.sim, back.sim);
  const SpecimenState sb = measure(back);
  EXPECT_EQ(sb.porosity, st.porosity);
  EXPECT_EQ(interior_text(sb), interior_text(st));
  EXPECT_NEAR(sb.radial_stress, st.radial_stress, 1e-9 * st.radial_stress);
  EXPECT_EQ(sb.coordination, st.coordination);
  // A ball file where clumps are asked for is refused, naming both.
  {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "hilldem_labtests_clump_specimen_kind";
    StudySettings bad = testing::mini_study_from_saved(dir);
    bad.genesis.clump_mix = {{"elongated2", 1.0}};
    try {
      validate(bad, {CaseSpec{std::string(HILLDEM_SOURCE_DIR) + "/tests/data/labtests/fine.csv", GrainModel::Hill, false}});
      FAIL() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--clump-template elongated2 and --specimen"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("the file's grains are balls"), std::string::npos) << e.what();
    }
  }

  // Finalized (the clumps' mass follows the material's density), then a short triaxial test.
  Class5Material mat;
  mat.density = 2 * spec.grain.density;
  const double m0 = s.sim.clumps.state.mass[0];
  finalize(s, mat, WallContact{}, EquilibriumSettings{}, nullptr);
  EXPECT_DOUBLE_EQ(s.sim.clumps.state.mass[0], 2 * m0);
  EXPECT_EQ(s.sim.balls.mass[s.sim.clumps.ball[0]], s.sim.clumps.state.mass[0]);
  EXPECT_NEAR(measure(s).porosity, st.porosity, 0.02);
  make_specimen_wet(s, 20e3, 3e-3, EquilibriumSettings{}, nullptr);
  EXPECT_GT(measure(s).wet_contacts, 0u);
  TriaxialSettings t;
  t.cycle_strains = {2e-4};
  t.final_strain = 1e-3;
  t.strain_rate = 0.1;
  t.final_strain_rate = 0.5;
  t.final_records = 20;
  const TriaxialResult r = run_triaxial(s, t, nullptr);
  ASSERT_EQ(r.loops.size(), 1u);
  EXPECT_TRUE(r.loops[0].closed);
  EXPECT_GT(r.loops[0].unload.slope, 20e6);
  EXPECT_LT(r.loops[0].unload.slope, 2000e6);
  EXPECT_GT(r.peak_q, r.loops[0].q_a);
  EXPECT_LT(r.worst_confinement_error, 0.03);
}

// The study's summary says when a case's grains are clumps.
TEST(ClumpStudy, TheSummarySaysTheGrainsAreClumps) {
  StudyResult r;
  CaseResult c;
  c.packed_with = GrainModel::Hill;
  c.clump_template = "elongated2";
  r.cases.push_back(c);
  EXPECT_NE(r.summary_markdown().find("| hill (clumps of elongated2) |"), std::string::npos) << r.summary_markdown();
  r.cases[0].clump_template.clear();
  EXPECT_EQ(r.summary_markdown().find("clumps of"), std::string::npos);
}

}  // namespace
}  // namespace hilldem
