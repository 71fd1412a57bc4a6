// A grading's grains as a mix of clump templates (issue 32, item 3; docs/clumps.md, "A mix of
// templates"): the mix as text (parsed, checked, written back), each grain's template drawn from the
// seed on its own stream so that the templates' solid volumes come to their fractions, the sizes
// those of one template, the same bits for a seed and any thread count, and the specimen file that
// records each clump's template and loads back bitwise.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <string>

#include "hilldem/core/error.hpp"
#include "hilldem/io/state_io.hpp"
#include "hilldem/labtests/clump_mix.hpp"
#include "hilldem/labtests/specimen_io.hpp"
#include "hilldem/labtests/study.hpp"
#include "mini_specimen.hpp"

namespace hilldem {
namespace {

// The message of the InputError f throws ("" when it throws none).
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string check_error(const std::string& text) {
  return error_of([&] { check_clump_mix(parse_clump_mix(text, "--clump-template"), "--clump-template"); });
}

TEST(ClumpMix, ParsesANameOrAListOfFractionsAndWritesThemBack) {
  EXPECT_TRUE(parse_clump_mix("", "x").empty());
  EXPECT_EQ(parse_clump_mix("elongated2", "x"), (ClumpMix{{"elongated2", 1.0}}));
  EXPECT_EQ(parse_clump_mix("elongated2:1", "x"), (ClumpMix{{"elongated2", 1.0}}));
  const ClumpMix mix = parse_clump_mix(" elongated2:0.6, sphere : 0.4 ", "x");
  EXPECT_EQ(mix, (ClumpMix{{"elongated2", 0.6}, {"sphere", 0.4}}));
  EXPECT_EQ(clump_mix_text(mix), "elongated2:0.6,sphere:0.4");
  EXPECT_EQ(clump_mix_text(ClumpMix{{"elongated2", 1.0}}), "elongated2");  // the single name, as before mixes
  EXPECT_EQ(clump_mix_words(mix), "a mix by solid volume of elongated2 0.6, sphere 0.4");
  // Any fractions come back to the bit from their text.
  const ClumpMix thirds{{"sphere", 1.0 / 3.0}, {"elongated2", 1.0 / 3.0}, {"elongated3", 1.0 / 3.0}};
  EXPECT_EQ(parse_clump_mix(clump_mix_text(thirds), "x"), thirds);
  EXPECT_EQ(check_error(clump_mix_text(thirds)), "");
  EXPECT_EQ(check_error("elongated2:0.6,sphere:0.4"), "");
  EXPECT_EQ(check_error("elongated2:0.3333333333,sphere:0.6666666667"), "");  // sums to 1 within 1e-9
}

TEST(ClumpMix, BadInputIsRefusedNamingTheOptionAndTheRange) {
  EXPECT_EQ(check_error("elongated2,sphere"),
            "--clump-template: expected NAME or NAME:FRACTION,NAME:FRACTION,... (fractions of the solid volume, in (0, 1], "
            "summing to 1), got 'elongated2,sphere'");
  EXPECT_EQ(check_error("elongated2:0.5,sphere"), check_error("elongated2,sphere").replace(
                                                      check_error("elongated2,sphere").find("'elongated2,sphere'"), 19,
                                                      "'elongated2:0.5,sphere'"));
  EXPECT_EQ(check_error("elongated2:half,sphere:0.5"),
            "--clump-template: expected NAME:FRACTION, got 'elongated2:half' in 'elongated2:half,sphere:0.5'");
  EXPECT_EQ(check_error(":0.5,sphere:0.5"), "--clump-template: expected NAME:FRACTION, got ':0.5' in ':0.5,sphere:0.5'");
  EXPECT_EQ(check_error("elongated2:0.6,sphere:0.5"),
            "--clump-template: the fractions must sum to 1 (within 1e-09), got 1.1");
  EXPECT_EQ(check_error("elongated2:0.5,sphere:0.5000001"),
            "--clump-template: the fractions must sum to 1 (within 1e-09), got 1.0000001");
  EXPECT_EQ(check_error("elongated2:0,sphere:1"),
            "--clump-template: the fraction of elongated2 must be in (0, 1] (of the solid volume), got 0");
  EXPECT_EQ(check_error("elongated2:-0.5,sphere:1.5"),
            "--clump-template: the fraction of elongated2 must be in (0, 1] (of the solid volume), got -0.5");
  EXPECT_EQ(check_error("elongated2:nan,sphere:0.5"),
            "--clump-template: the fraction of elongated2 must be in (0, 1] (of the solid volume), got nan");
  EXPECT_EQ(check_error("elongated2:0.5"), "--clump-template: the fractions must sum to 1 (within 1e-09), got 0.5");
  EXPECT_EQ(check_error("sphere:0.5,sphere:0.5"), "--clump-template: template 'sphere' is named twice");
  EXPECT_EQ(check_error("dodecahedron:0.5,sphere:0.5"),
            "--clump-template: unknown clump template 'dodecahedron'; known: sphere, elongated2, elongated3, ellipsoid, cube, "
            "prism, slab, rock");
  EXPECT_EQ(check_error("ball"), "--clump-template: unknown clump template 'ball'; known: sphere, elongated2, elongated3, "
                                 "ellipsoid, cube, prism, slab, rock");
  // Genesis checks the mix it is given (the Python and C++ way in) under the same rules.
  GenesisSpec g = testing::mini_spec();
  g.clump_mix = {{"elongated2", 0.7}, {"sphere", 0.4}};
  EXPECT_EQ(error_of([&] { make_cloud(g); }), "clump templates: the fractions must sum to 1 (within 1e-09), got 1.1");
}

// The C5b grading (19-23 mm grains down to 4.8 mm) in the memo's vessel scaled by 0.3: 367 grains,
// the largest 10 % of the solid; and the fine grading (5.6-8 mm) in it: about 370 even grains.
GenesisSpec mix_spec(const Grading& g, const ClumpMix& mix, SizeMeasure m = SizeMeasure::EqualVolumeDiameter) {
  GenesisSpec spec = testing::mini_spec();
  spec.grading = g;
  spec.packing.seed = 10000;
  spec.clump_mix = mix;
  spec.clump_size = m;
  return spec;
}

// Each template's solid volume is its fraction of the clumps' union volume to within the largest
// clump's volume (the grains laid end to end in a random order, each taking the template its middle
// falls to: only the two grains at the ends of a template's share are split, each off by at most half
// its volume). With the enclosing size the line is in sphere volumes and each template's is weighted
// by its f, so twice that.
TEST(ClumpMix, TheTemplatesSolidVolumesComeToTheirFractions) {
  const ClumpMix two{{"elongated2", 0.6}, {"sphere", 0.4}};
  const ClumpMix three{{"elongated3", 0.2}, {"elongated2", 0.5}, {"sphere", 0.3}};
  for (const Grading& g : {grading_c5b(), testing::mini_spec().grading})
    for (const ClumpMix& mix : {two, three})
      for (const SizeMeasure m : {SizeMeasure::EqualVolumeDiameter, SizeMeasure::EnclosingDiameter}) {
        SCOPED_TRACE(g.name + " " + clump_mix_text(mix) + " " + to_string(m));
        const Specimen s = make_cloud(mix_spec(g, mix, m));
        ASSERT_EQ(s.clump_kind.size(), s.sim.clumps.size());
        EXPECT_GT(s.sim.clumps.size(), 300u);
        double largest = 0.0, total = 0.0;
        for (std::size_t i = 0; i < s.sim.clumps.size(); ++i) {
          const double v = s.sim.clumps.state.mass[i] / s.sim.balls.density[0];
          largest = std::max(largest, v), total += v;
        }
        const double tolerance = (m == SizeMeasure::EqualVolumeDiameter ? 1.0 : 2.0) * largest / total + 1e-12;
        const std::vector<double> f = clump_mix_fractions(s);
        for (std::size_t t = 0; t < mix.size(); ++t) EXPECT_NEAR(f[t], mix[t].second, tolerance) << mix[t].first;
        // The cloud's solid volume is (1 − n_c) of the vessel, as with one template.
        const double vessel = std::numbers::pi * 0.3 * 0.085 * 0.3 * 0.085 * 0.3 * 0.240;
        EXPECT_NEAR(total / vessel, 1.0 - 0.58, 1.5 * largest / vessel);
        // Each template's pebbles: elongated2 two, sphere one, elongated3 three.
        std::vector<std::size_t> pebbles(s.sim.clumps.size(), 0);
        for (std::uint32_t c : s.sim.clumps.pebbles.clump) ++pebbles[c];
        for (std::size_t i = 0; i < pebbles.size(); ++i) {
          const std::string& name = s.clump_mix[s.clump_kind[i]].first;
          EXPECT_EQ(pebbles[i], name == "sphere" ? 1u : name == "elongated2" ? 2u : 3u) << i;
        }
      }
  // With the C5b grading's few large grains the bound is wide (10 % of the solid); with the even
  // fine grading it is a fraction of a percent, and so is the error.
  const Specimen fine = make_cloud(mix_spec(testing::mini_spec().grading, two));
  EXPECT_NEAR(clump_mix_fractions(fine)[0], 0.6, 0.01);
}

TEST(ClumpMix, TheSizesAreThoseOfOneTemplateAndTheDrawIsTheSeeds) {
  const Grading c5b = grading_c5b();
  const Specimen one = make_cloud(mix_spec(c5b, {{"elongated2", 1.0}}));
  const Specimen mix = make_cloud(mix_spec(c5b, {{"elongated2", 0.5}, {"sphere", 0.5}}));
  // The template draw has its own stream: the sizes drawn are those of elongated2 alone.
  std::vector<double> a = one.diameters(), b = mix.diameters();
  std::sort(a.begin(), a.end()), std::sort(b.begin(), b.end());
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], 1e-12 * a[i]) << i;
  // Both templates among the largest grains and the smallest: the order of the draw is random,
  // not that of size.
  std::vector<std::size_t> order(b.size());
  const std::vector<double> d = mix.diameters();
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return d[x] > d[y]; });
  std::size_t big_spheres = 0, small_spheres = 0;
  for (std::size_t k = 0; k < 20; ++k) big_spheres += mix.clump_kind[order[k]], small_spheres += mix.clump_kind[order[order.size() - 1 - k]];
  EXPECT_GT(big_spheres, 0u);
  EXPECT_LT(big_spheres, 20u);
  EXPECT_GT(small_spheres, 0u);
  EXPECT_LT(small_spheres, 20u);
  // The same seed, the same bits; another seed, another draw.
  const Specimen again = make_cloud(mix_spec(c5b, {{"elongated2", 0.5}, {"sphere", 0.5}}));
  EXPECT_EQ(state_bytes(again.sim), state_bytes(mix.sim));
  EXPECT_EQ(again.clump_kind, mix.clump_kind);
  GenesisSpec other = mix_spec(c5b, {{"elongated2", 0.5}, {"sphere", 0.5}});
  other.packing.seed = 43;
  EXPECT_NE(make_cloud(other).clump_kind, mix.clump_kind);
}

// The fine grading in the memo's vessel scaled by 0.2 (34 mm x 48 mm): about 110 clumps.
GenesisSpec small_mix() {
  GenesisSpec spec = testing::mini_spec();
  spec.vessel_radius = 0.2 * 0.085;
  spec.vessel_height = 0.2 * 0.240;
  spec.clump_mix = {{"elongated2", 0.5}, {"sphere", 0.5}};
  return spec;
}

TEST(ClumpMix, ASmallMixPacksToTheSameBitsOnOneAndTwoThreadsAndItsFileLoadsBitwise) {
  const GenesisSpec spec = small_mix();
  omp_set_num_threads(1);
  const Specimen s = pack_specimen(spec, nullptr);
  omp_set_num_threads(2);
  const Specimen two = pack_specimen(spec, nullptr);
  omp_set_num_threads(1);
  EXPECT_EQ(state_bytes(two.sim), state_bytes(s.sim));
  EXPECT_EQ(two.clump_kind, s.clump_kind);
  const SpecimenState st = measure(s);
  EXPECT_NEAR(st.radial_stress, 150e3, 0.01 * 150e3);
  EXPECT_LE(st.ratio, spec.packing.equilibrium.ratio);

  // The file records the mix and each clump's template; loaded, it is the same specimen to the bit
  // and writes the same text.
  const std::string text = packed_specimen_text(s, spec.packing);
  EXPECT_NE(text.find("\nclump_template,elongated2:0.5,sphere:0.5\nclump_size,equal-volume\n"), std::string::npos);
  EXPECT_NE(text.find("\nid,template,x[m],"), std::string::npos);
  EXPECT_NE(text.find(",sphere,"), std::string::npos);
  EXPECT_NE(text.find(",elongated2,"), std::string::npos);
  const Specimen back = parse_packed_specimen(text, "mem");
  EXPECT_EQ(packed_specimen_text(back, spec.packing), text);
  EXPECT_EQ(back.clump_mix, s.clump_mix);
  EXPECT_EQ(back.clump_kind, s.clump_kind);
  testing::expect_same_clumps(s.sim, back.sim);
  EXPECT_EQ(clump_mix_fractions(back), clump_mix_fractions(s));
  EXPECT_EQ(measure(back).porosity, st.porosity);
  EXPECT_EQ(measure(back).coordination, st.coordination);

  // A row's template must be one of the mix's; the mix is checked as the option is, at its line.
  std::string wrong = text;
  wrong.replace(wrong.find(",sphere,"), 8, ",elongated3,");
  EXPECT_NE(error_of([&] { parse_packed_specimen(wrong, "mem"); }).find("template 'elongated3' is not in the file's clump_template (elongated2:0.5,sphere:0.5)"),
            std::string::npos);
  std::string sum = text;
  sum.replace(sum.find("sphere:0.5"), 10, "sphere:0.6");
  const std::string e = error_of([&] { parse_packed_specimen(sum, "mem"); });
  EXPECT_NE(e.find("mem:"), std::string::npos) << e;
  EXPECT_NE(e.find("clump_template: the fractions must sum to 1 (within 1e-09), got 1.1"), std::string::npos) << e;
  // A mix's file without the template column is refused (only one template's may omit it).
  std::string no_column = text;
  no_column.replace(no_column.find("id,template,"), 12, "id,");
  EXPECT_NE(error_of([&] { parse_packed_specimen(no_column, "mem"); }).find("expected the header id,template,x[m]"), std::string::npos);

  // A study refuses a specimen whose mix is not the one asked for.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "hilldem_labtests_clump_mix_kind";
  std::filesystem::remove_all(dir);
  StudySettings st2;
  st2.genesis = spec;
  st2.min_grains = 0;
  st2.specimen_file = (dir / "mix.csv").string();
  save_packed_specimen(s, spec.packing, st2.specimen_file);
  st2.genesis.clump_mix = {{"elongated2", 0.6}, {"sphere", 0.4}};
  EXPECT_NE(error_of([&] { validate(st2, {CaseSpec{std::string(HILLDEM_SOURCE_DIR) + "/tests/data/labtests/fine.csv", GrainModel::Hill, false}}); })
                .find("--clump-template elongated2:0.6,sphere:0.4 and --specimen " + st2.specimen_file +
                      ": the file's grains are clumps of elongated2:0.5,sphere:0.5"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

// A file of one template written before mixes (no template column) loads as that template's, and
// writes the new form.
TEST(ClumpMix, AOneTemplateFileWithoutTheTemplateColumnLoads) {
  GenesisSpec spec = small_mix();
  spec.clump_mix = {{"elongated2", 1.0}};
  Specimen s = make_cloud(spec);
  relax_cloud(s, spec.packing, nullptr);  // the file's checks: a packed state's overlaps
  const std::string text = packed_specimen_text(s, spec.packing);
  std::string old = text;
  old.replace(old.find("id,template,"), 12, "id,");
  for (std::size_t at = old.find(",elongated2,"); at != std::string::npos; at = old.find(",elongated2,", at + 1)) old.erase(at, 11);
  ASSERT_EQ(old.find(",elongated2,"), std::string::npos);
  const Specimen back = parse_packed_specimen(old, "old");
  EXPECT_EQ(back.clump_mix, spec.clump_mix);
  EXPECT_EQ(packed_specimen_text(back, spec.packing), text);
}

}  // namespace
}  // namespace hilldem
