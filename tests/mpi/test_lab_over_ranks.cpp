// The lab-test drivers over MPI ranks (docs/mpi.md, "The lab tests over ranks"), under mpirun with
// any number of ranks (tests/mpi/tests.cmake: 1 to 4): every reading they take of the balls and
// contacts, every decision and the final state are those of one process, bit for bit. Each rank runs
// the one-process reference itself (Specimen::ranks null), then the same drivers on its part.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <regex>
#include <sstream>
#include <string>

#include "../labtests/mini_specimen.hpp"
#include "hilldem/io/state_io.hpp"
#include "hilldem/labtests/genesis.hpp"
#include "hilldem/labtests/t307.hpp"
#include "hilldem/labtests/triaxial.hpp"
#include "hilldem/parallel/run_mpi.hpp"

namespace hilldem {
namespace {

// Every field of a state, doubles in hexadecimal: equal text = bitwise-equal readings.
std::string text(const SpecimenState& s) {
  return fmt::format("grains {} n {:a} interior {:a} margin {} {:a} Z {:a} Zm {:a} sr {:a} sb {:a} st {:a} R {:a} H {:a} "
                     "ratio {:a} wet {} dt {:a}",
                     s.grains, s.porosity, s.interior_porosity, static_cast<int>(s.interior_margin), s.interior_margin_length,
                     s.coordination, s.mech_coordination, s.radial_stress, s.bottom_stress, s.top_stress, s.radius, s.height,
                     s.ratio, s.wet_contacts, s.timestep);
}
std::string text(const std::vector<PhaseReport>& phases) {
  std::string out;
  for (const PhaseReport& p : phases)
    out += fmt::format("{}: {} steps, dn {:a}, {}\n", p.name, p.steps, p.porosity_change, text(p.state));
  return out;
}
// The lines of a log that carry no wall-clock time (none with a number of seconds in it).
std::string timeless(const std::string& log) {
  static const std::regex seconds(R"(\d s([ ;),]|$))");
  std::istringstream in(log);
  std::string out, line;
  while (std::getline(in, line))
    if (!std::regex_search(line, seconds)) out += line + "\n";
  return out;
}

int world_size() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

TEST(LabOverRanks, FinalizeAndMakeWetAreTheWholeRunsBitwise) {
  const EquilibriumSettings e;
  Specimen one = testing::mini_packed();
  std::ostringstream one_log;
  finalize(one, Class5Material{}, WallContact{}, e, &one_log);
  make_specimen_wet(one, 20e3, 3e-3, e, &one_log);

  parallel::RunOverRanks ranks(MPI_COMM_WORLD);
  Specimen part = testing::mini_packed();
  part.ranks = &ranks;
  std::ostringstream part_log;
  {
    const RanksScope on_ranks(part, 3e-3);  // (the ghosts cover make_wet's gap)
    ASSERT_TRUE(decomposed(part));
    finalize(part, Class5Material{}, WallContact{}, e, &part_log);
    make_specimen_wet(part, 20e3, 3e-3, e, &part_log);
    if (world_size() > 1) EXPECT_LT(part.sim.balls.size(), one.sim.balls.size());  // (a part, not the whole)
    EXPECT_EQ(text(measure(part)), text(measure(one)));
    const Specimen whole = whole_run(part);
    EXPECT_FALSE(decomposed(part));
    EXPECT_EQ(state_digest(whole.sim), state_digest(one.sim));
  }
  EXPECT_EQ(text(part.phases), text(one.phases));
  EXPECT_EQ(timeless(part_log.str()), timeless(one_log.str()));  // make_wet's count among them
  EXPECT_NE(one_log.str().find(" wet contacts"), std::string::npos);
}

TriaxialSettings mini_test() {
  TriaxialSettings t;
  t.cycle_strains = {2e-4};
  t.final_strain = 1e-3;
  t.strain_rate = 0.1;
  t.final_strain_rate = 0.5;
  t.final_records = 50;
  return t;
}

TEST(LabOverRanks, TriaxialTestIsTheWholeRunsBitwise) {
  const EquilibriumSettings e;
  Specimen one = testing::mini_packed();
  finalize(one, Class5Material{}, WallContact{}, e, nullptr);
  const TriaxialResult a = run_triaxial(one, mini_test(), nullptr);

  parallel::RunOverRanks ranks(MPI_COMM_WORLD);
  Specimen part = testing::mini_packed();
  part.ranks = &ranks;
  const RanksScope on_ranks(part, 0.0);
  finalize(part, Class5Material{}, WallContact{}, e, nullptr);
  const TriaxialResult b = run_triaxial(part, mini_test(), nullptr);
  ASSERT_GT(a.history.size(), 20u);
  EXPECT_EQ(b.history_csv(), a.history_csv());  // porosity and coordination in every row
  EXPECT_EQ(b.loops_text(), a.loops_text());
  EXPECT_EQ(b.steps, a.steps);
  EXPECT_EQ(state_digest(whole_run(part).sim), state_digest(one.sim));
}

TEST(LabOverRanks, T307IsTheWholeRunsBitwise) {
  T307Settings t;
  const auto all = t307_base_sequences();
  t.sequences = {all[0], all[1], all[14]};
  t.timing.pulse_duration = 5e-3;
  t.timing.rest_duration = 2e-3;
  t.timing.settle_duration = 1e-3;
  t.timing.cycles = 2;
  t.timing.averaged_cycles = 1;
  t.timing.conditioning_cycles = 1;
  const EquilibriumSettings e;
  Specimen one = testing::mini_packed();
  finalize(one, Class5Material{}, WallContact{}, e, nullptr);
  const T307Result a = run_t307(one, t, nullptr);

  parallel::RunOverRanks ranks(MPI_COMM_WORLD);
  Specimen part = testing::mini_packed();
  part.ranks = &ranks;
  const RanksScope on_ranks(part, 0.0);
  finalize(part, Class5Material{}, WallContact{}, e, nullptr);
  const T307Result b = run_t307(part, t, nullptr);
  EXPECT_EQ(b.sequences_csv(), a.sequences_csv());
  EXPECT_EQ(b.cycles_csv(), a.cycles_csv());
  EXPECT_EQ(state_digest(whole_run(part).sim), state_digest(one.sim));
}

TEST(LabOverRanks, GenesisFromASeedIsTheWholeRunsBitwise) {
  GenesisSpec g = testing::mini_spec();
  g.vessel_radius = 0.2 * 0.085;  // (about 110 grains: the cloud, its relaxation and the packing in seconds)
  g.vessel_height = 0.2 * 0.240;
  std::ostringstream one_log;
  const Specimen one = pack_specimen(g, &one_log);

  parallel::RunOverRanks ranks(MPI_COMM_WORLD);
  g.ranks = &ranks;
  std::ostringstream part_log;
  const Specimen part = pack_specimen(g, &part_log);  // (decomposed from the cloud on; the whole run returned)
  EXPECT_FALSE(decomposed(part));
  EXPECT_EQ(part.sim.balls.size(), one.sim.balls.size());
  EXPECT_EQ(state_digest(part.sim), state_digest(one.sim));
  EXPECT_EQ(text(part.phases), text(one.phases));  // the cloud's relaxation steps (its overlap) and the packing's
  EXPECT_EQ(timeless(part_log.str()), timeless(one_log.str()));
  EXPECT_EQ(text(measure(part)), text(measure(one)));
}

}  // namespace
}  // namespace hilldem
