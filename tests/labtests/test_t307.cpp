// The T 307 driver on the miniature specimen (about 370 grains): a few short sequences through the
// engine; the stress follows the haversine target, M_r and ν are positive and finite, M_r rises with
// the bulk stress, and the results reach the CSV and the fit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "hilldem/core/error.hpp"
#include "hilldem/io/state_io.hpp"
#include "hilldem/labtests/t307.hpp"
#include "mini_specimen.hpp"

namespace hilldem {
namespace {

T307Settings mini_settings() {
  T307Settings t;
  const auto all = t307_base_sequences();
  t.sequences = {all[0], all[1], all[7], all[11], all[14]};  // σ_max/σ₃ = 1: within the spheres' strength
  t.timing.pulse_duration = 5e-3;
  t.timing.rest_duration = 2e-3;
  t.timing.settle_duration = 1e-3;
  t.timing.cycles = 4;
  t.timing.averaged_cycles = 2;
  t.timing.conditioning_cycles = 2;
  return t;
}

TEST(T307Driver, SequencesFollowTheTargetAndGivePositiveModuli) {
  Specimen s = testing::mini_packed();
  finalize(s, Class5Material{}, WallContact{}, EquilibriumSettings{}, nullptr);
  const T307Settings t = mini_settings();
  const T307Result r = run_t307(s, t, nullptr);
  ASSERT_EQ(r.rows.size(), 5u);
  EXPECT_EQ(r.cycles.size(), 2u + 4u * 4u);
  for (const T307Row& row : r.rows) {
    SCOPED_TRACE(row.nominal.number);
    EXPECT_EQ(row.cycles, row.nominal.number == 0 ? 2 : 4);
    EXPECT_EQ(row.averaged, 2);
    EXPECT_TRUE(std::isfinite(row.modulus));
    EXPECT_GT(row.modulus, 1e6);  // > 1 MPa
    EXPECT_TRUE(std::isfinite(row.poisson));
    EXPECT_GT(row.poisson, 0.0);
    // The deviator pulse reaches its target amplitude and the confinement is held.
    // With peak compensation, the averaged cycles' deviator amplitude within 5 % of σ_cyclic.
    EXPECT_NEAR(row.cyclic_stress, row.nominal.cyclic, 0.05 * row.nominal.cyclic);
    EXPECT_LT(std::abs(row.amplitude_error), 0.05);
    EXPECT_NEAR(row.confining, row.nominal.confining, 0.1 * row.nominal.confining);
    EXPECT_GT(row.steps, 0);
  }
  // Stress-dependent stiffness: M_r at sequence 14 (θ 551 kPa) above sequence 1 (θ 83 kPa).
  EXPECT_GT(r.rows[4].modulus, 1.5 * r.rows[1].modulus);
  // The command was raised above the target to make up for the servo's lag.
  EXPECT_GT(r.cycles.back().command, r.rows[4].nominal.cyclic);
  EXPECT_FALSE(r.stopped);
  ASSERT_TRUE(r.fitted) << r.fit_error;
  EXPECT_EQ(r.fit.points, 4);
  EXPECT_GT(r.fit.k2, 0.0);
  // The CSV: a header and the four sequences (conditioning left out).
  const std::string csv = r.sequences_csv();
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
  EXPECT_EQ(csv.rfind("seq,sigma3[Pa],", 0), 0u);
  EXPECT_NE(csv.find("\n14,137900,137900,124100,13800,"), std::string::npos) << csv;
  // The test leaves no controller behind and the walls at rest.
  EXPECT_TRUE(s.sim.controllers.empty());
  EXPECT_EQ(s.sim.walls.walls[s.vessel.top].velocity.z, 0.0);
}

// The driver reads only the walls and the clock between cycles, so Simulation::drive writes the
// results of one cycle per settle and per pulse: the same bits as a run in which a no-op observer
// makes every cycle write everything (as cycle(1) after each cycle did).
TEST(T307Driver, DrivenCyclesGiveTheResultsOfWatchedCycles) {
  Specimen driven = testing::mini_packed();
  finalize(driven, Class5Material{}, WallContact{}, EquilibriumSettings{}, nullptr);
  Specimen watched = driven;
  watched.sim.observers.push_back([](const Simulation&) {});
  T307Settings t = mini_settings();
  t.sequences.resize(3);
  t.timing.cycles = 2;
  t.timing.averaged_cycles = 1;
  const std::int64_t passes_driven = driven.sim.live_record_passes(), passes_watched = watched.sim.live_record_passes();
  const T307Result a = run_t307(driven, t, nullptr);
  const T307Result b = run_t307(watched, t, nullptr);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.cycles_csv(), b.cycles_csv());
  EXPECT_EQ(a.sequences_csv(), b.sequences_csv());
  ASSERT_EQ(a.cycles.size(), b.cycles.size());
  for (std::size_t k = 0; k < a.cycles.size(); ++k) {
    EXPECT_EQ(a.cycles[k].q_peak, b.cycles[k].q_peak);
    EXPECT_EQ(a.cycles[k].eps_a_end, b.cycles[k].eps_a_end);
  }
  EXPECT_EQ(state_digest(driven.sim), state_digest(watched.sim));
  EXPECT_GT(driven.sim.live_record_passes() - passes_driven, a.steps / 2);
  EXPECT_EQ(watched.sim.live_record_passes(), passes_watched);  // (a watched cycle never runs them)
}

// The standard's stop: past the permanent strain limit, no later sequence runs and no fit is made.
TEST(T307Driver, StopsAtThePermanentStrainLimit) {
  Specimen s = testing::mini_packed();
  finalize(s, Class5Material{}, WallContact{}, EquilibriumSettings{}, nullptr);
  T307Settings t = mini_settings();
  t.timing.conditioning_cycles = 0;
  t.max_permanent_strain = 1e-6;
  const T307Result r = run_t307(s, t, nullptr);
  EXPECT_TRUE(r.stopped);
  EXPECT_NE(r.stop_reason.find("sequence 1, cycle 1"), std::string::npos) << r.stop_reason;
  ASSERT_EQ(r.rows.size(), 1u);
  EXPECT_EQ(r.rows[0].cycles, 1);
  EXPECT_FALSE(r.fitted);
}

TEST(T307Driver, StopsInTheConditioningToo) {
  Specimen s = testing::mini_packed();
  finalize(s, Class5Material{}, WallContact{}, EquilibriumSettings{}, nullptr);
  T307Settings t = mini_settings();
  t.max_permanent_strain = 1e-6;
  const T307Result r = run_t307(s, t, nullptr);
  EXPECT_TRUE(r.stopped);
  EXPECT_NE(r.stop_reason.find("sequence 0, cycle 1"), std::string::npos) << r.stop_reason;
  ASSERT_EQ(r.rows.size(), 1u);
  EXPECT_EQ(r.rows[0].nominal.number, 0);
}

TEST(T307Driver, RefusesBadSettingsBeforeAnyWork) {
  Specimen s = testing::mini_packed();
  T307Settings t = mini_settings();
  t.sequences[1].confining = -1.0;
  const std::int64_t steps = s.sim.steps;
  EXPECT_THROW(run_t307(s, t, nullptr), InputError);
  t = mini_settings();
  t.timing.cycles = 0;
  EXPECT_THROW(run_t307(s, t, nullptr), InputError);
  t = mini_settings();
  t.max_permanent_strain = 0.0;
  EXPECT_THROW(run_t307(s, t, nullptr), InputError);
  EXPECT_EQ(s.sim.steps, steps);
}

}  // namespace
}  // namespace hilldem
