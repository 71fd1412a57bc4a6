// Triaxial test: the loop analysis on known paths, a miniature test with cycles through the engine,
// finalization, wetting and the saved packed specimen.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <numbers>
#include <random>

#include "hilldem/core/error.hpp"
#include "hilldem/io/state_io.hpp"
#include "hilldem/labtests/specimen_io.hpp"
#include "hilldem/labtests/study.hpp"
#include "hilldem/labtests/triaxial.hpp"
#include "mini_specimen.hpp"

namespace hilldem {
namespace {

// ---------------------------------------------------------------------------------------------------
// Loop analysis on paths with known answers.

// Load linearly to A = (1e-3, 100 kPa) with slope E_l, unload along a straight line to B = (0.6e-3,
// 20 kPa), reload along a parabola through B and C = (1e-3, 96 kPa) bulging above the chord by h.
TEST(LoopTracker, SecantsAndAreaOfAKnownLoop) {
  LoopTracker t;
  const double ea = 1e-3, qa = 100e3, eb = 0.6e-3, qb = 20e3, qc = 96e3, h = 5e3;
  const int n = 4000;
  for (int k = 0; k <= n; ++k) t.add(TriaxialPhase::Load, 1, ea * k / n, qa * k / n);
  for (int k = 1; k <= n; ++k) {
    const double s = static_cast<double>(k) / n;
    t.add(TriaxialPhase::Unload, 1, ea + (eb - ea) * s, qa + (qb - qa) * s);
  }
  for (int k = 1; k <= n + 10; ++k) {  // past ε_A: C is interpolated
    const double s = static_cast<double>(k) / n;
    const double e = eb + (ea - eb) * s;
    const double q = qb + (qc - qb) * s + 4 * h * s * (1 - s);
    t.add(TriaxialPhase::Reload, 1, e, q);
  }
  t.add(TriaxialPhase::Load, 2, ea + 1e-5, qc + 1e3);
  const auto loops = t.loops();
  ASSERT_EQ(loops.size(), 1u);
  const LoopResult& l = loops[0];
  EXPECT_TRUE(l.closed);
  EXPECT_DOUBLE_EQ(l.eps_a, ea);
  EXPECT_DOUBLE_EQ(l.q_a, qa);
  EXPECT_NEAR(l.eps_b, eb, 1e-15);
  EXPECT_NEAR(l.q_b, qb, 1e-9);
  EXPECT_NEAR(l.unload_secant, (qa - qb) / (ea - eb), 1e-6 * 200e6);  // 200 MPa
  EXPECT_NEAR(l.q_c, qc, 1.0);
  EXPECT_NEAR(l.reload_secant, (qc - qb) / (ea - eb), 1e-4 * 190e6);
  // Area: reload integral minus unload integral = chord difference (qc − qa)/2·Δε + parabola 2/3·h·Δε.
  const double de = ea - eb;
  const double exact = 0.5 * (qc - qa) * de + 2.0 / 3.0 * h * de;
  EXPECT_NEAR(l.loop_area, exact, 1e-4 * std::abs(exact));
  EXPECT_NEAR(l.damping_ratio, 2 * exact / (std::numbers::pi * (qa - qb) * de), 1e-6);
}

TEST(LoopTracker, AnUnclosedLoopIsReportedAsSuch) {
  LoopTracker t;
  t.add(TriaxialPhase::Load, 1, 0.0, 0.0);
  t.add(TriaxialPhase::Load, 1, 2e-4, 40e3);
  t.add(TriaxialPhase::Unload, 1, 1.5e-4, 20e3);
  t.add(TriaxialPhase::Unload, 1, 1e-4, 4e3);
  t.add(TriaxialPhase::Reload, 1, 1.5e-4, 25e3);
  const auto loops = t.loops();
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_FALSE(loops[0].closed);
  EXPECT_NEAR(loops[0].unload_secant, 36e3 / 1e-4, 1e-3);
  EXPECT_EQ(loops[0].reload_secant, 0.0);
}

// A loop that rings: straight unload and reload branches of known slopes, with a decaying oscillation
// after each reversal (1.5 kPa, as the engine's signal) and white noise (0.3 kPa) on top. Returns the
// tracker's loop.
LoopResult ringing_loop(double m_unload, double m_reload, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> noise(0.0, 300.0);
  LoopTracker t;
  const double ea = 1e-3, qa = 100e3, qb = 10e3;
  const double eb = ea - (qa - qb) / m_unload;
  const int n = 3000;
  auto ring = [](int k) { return 1.5e3 * std::exp(-k / 400.0) * std::sin(2 * std::numbers::pi * k / 90.0); };
  for (int k = 0; k <= 200; ++k) t.add(TriaxialPhase::Load, 1, ea * k / 200, qa * k / 200);
  for (int k = 1; k <= n; ++k) {
    const double e = ea + (eb - ea) * k / n;
    t.add(TriaxialPhase::Unload, 1, e, qa - m_unload * (ea - e) + ring(k) + noise(gen));
  }
  for (int k = 1; k <= n + 5; ++k) {
    const double e = eb + (ea - eb) * k / n;
    t.add(TriaxialPhase::Reload, 1, e, qb + m_reload * (e - eb) + ring(k) + noise(gen));
  }
  t.add(TriaxialPhase::Load, 2, ea + 1e-5, qa);
  const auto loops = t.loops();
  EXPECT_EQ(loops.size(), 1u);
  return loops.at(0);
}

TEST(LoopTracker, FittedModulusRecoversTheSlopeOfARingingLoopWithinItsUncertainty) {
  const double mu = 250e6, mr = 270e6;  // [Pa]
  const LoopResult l = ringing_loop(mu, mr, 7);
  ASSERT_TRUE(l.unload.valid);
  ASSERT_TRUE(l.reload.valid);
  EXPECT_TRUE(l.closed);
  // The fitted part: the middle 80 % of q_B..q_A, most of the branch's 3000 points.
  EXPECT_GT(l.unload.points, 2000u);
  EXPECT_LT(l.unload.points, 2800u);
  EXPECT_LE(std::abs(l.unload.slope - mu), 2 * l.unload.slope_se) << l.unload.slope << " +- " << l.unload.slope_se;
  EXPECT_LE(std::abs(l.reload.slope - mr), 2 * l.reload.slope_se) << l.reload.slope << " +- " << l.reload.slope_se;
  // An uncertainty that says something: under 2 % of the slope, and larger than the textbook one,
  // which takes the ringing's correlated residuals for independent ones.
  EXPECT_LT(l.unload.slope_se, 0.02 * mu);
  EXPECT_GT(l.unload.slope_se, 1.5 * l.unload.ols_se);
  // The two-point secant is kept beside the fit.
  EXPECT_NEAR(l.unload_secant, (l.q_a - l.q_b) / (l.eps_a - l.eps_b), 1e-9 * mu);
  TriaxialResult res;
  res.loops = {l};
  EXPECT_NE(res.loops_text().find(fit_text(l.unload) + " MPa, unload secant"), std::string::npos) << res.loops_text();
}

TEST(LoopTracker, FittedModulusUncertaintyCoversTheTrueSlope) {
  // Over many noise draws, the true slope lies within two standard errors in most (about 95 % for
  // an honest uncertainty).
  int covered = 0;
  const int draws = 40;
  for (int k = 0; k < draws; ++k) {
    const LoopResult l = ringing_loop(250e6, 270e6, 100 + k);
    covered += std::abs(l.unload.slope - 250e6) <= 2 * l.unload.slope_se;
  }
  EXPECT_GE(covered, 34) << covered << " of " << draws;
}

TEST(LineFit, StandardErrorOfIndependentNoiseAndTooFewPoints) {
  // White noise: the jackknife agrees with the textbook s_b = σ / sqrt(Σ (x − x̄)²) (within its own
  // scatter, about 16 % for 20 blocks).
  std::mt19937_64 gen(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<double> x, y;
  for (int i = 0; i < 1000; ++i) x.push_back(i * 1e-3), y.push_back(5.0 + 2.0 * i * 1e-3 + noise(gen));
  const LineFit f = fit_line(x, y);
  ASSERT_TRUE(f.valid);
  double sxx = 0, mx = 0.4995;
  for (double v : x) sxx += (v - mx) * (v - mx);
  EXPECT_NEAR(f.ols_se, 1.0 / std::sqrt(sxx), 0.1 / std::sqrt(sxx));
  EXPECT_NEAR(f.slope_se, f.ols_se, 0.4 * f.ols_se);
  EXPECT_EQ(f.blocks, 20);
  EXPECT_NEAR(f.slope, 2.0, 3 * f.slope_se);
  EXPECT_FALSE(fit_line({1.0, 2.0}, {1.0, 2.0}).valid);
  EXPECT_FALSE(fit_line(std::vector<double>(8, 1.0), std::vector<double>(8, 2.0)).valid);  // fewer than 9 points
  EXPECT_FALSE(fit_line(std::vector<double>(9, 1.0), std::vector<double>(9, 2.0)).valid);  // x all equal
  EXPECT_EQ(fit_text(fit_line({1.0, 2.0}, {1.0, 2.0})), "n/a (2 points in the fitted part)");
}

TEST(TriaxialSettings, BadValuesAreRefusedBeforeAnyWork) {
  TriaxialSettings t;
  EXPECT_NO_THROW(validate(t));
  t.cycle_strains = {5e-4, 2e-4};
  EXPECT_THROW(validate(t), InputError);
  t = TriaxialSettings{};
  t.final_strain = 3e-4;  // below the 0.05 % cycle
  EXPECT_THROW(validate(t), InputError);
  t = TriaxialSettings{};
  t.confinement = -150e3;
  EXPECT_THROW(validate(t), InputError);
  t = TriaxialSettings{};
  t.strain_rate = 0;
  EXPECT_THROW(validate(t), InputError);
  t = TriaxialSettings{};
  t.unload_fraction = 1.0;
  EXPECT_THROW(validate(t), InputError);
  t = TriaxialSettings{};
  t.density_scaling = 0.5;  // 0 (off) or in [1, 50]
  EXPECT_THROW(validate(t), InputError);
  t.density_scaling = 51;
  EXPECT_THROW(validate(t), InputError);
  t.density_scaling = 4;
  EXPECT_NO_THROW(validate(t));
}

// ---------------------------------------------------------------------------------------------------
// The miniature test through the engine.

TriaxialSettings mini_test() {
  TriaxialSettings t;
  t.cycle_strains = {2e-4, 5e-4};
  t.final_strain = 3e-3;
  t.strain_rate = 0.1;
  t.final_strain_rate = 0.5;
  t.final_records = 50;
  return t;
}

TEST(Triaxial, MiniatureTestRunsTheCyclesAndComputesTheModuli) {
  Specimen s = testing::mini_packed();
  finalize(s, Class5Material{}, WallContact{}, EquilibriumSettings{}, nullptr);
  const TriaxialSettings t = mini_test();
  const TriaxialResult r = run_triaxial(s, t, nullptr);
  ASSERT_EQ(r.loops.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const LoopResult& l = r.loops[k];
    SCOPED_TRACE(k);
    EXPECT_EQ(l.cycle, static_cast<int>(k) + 1);
    EXPECT_TRUE(l.closed);
    EXPECT_DOUBLE_EQ(l.target_strain, t.cycle_strains[k]);
    EXPECT_GE(l.eps_a, t.cycle_strains[k]);
    EXPECT_LT(l.eps_a, t.cycle_strains[k] * 1.01);  // reversed within a step of the target
    EXPECT_GT(l.q_a, 0.0);
    EXPECT_LE(l.q_b, t.unload_fraction * l.q_a + 1e-9);  // unloaded to 10 % of q_A
    EXPECT_LT(l.eps_b, l.eps_a);
    // Moduli of a granular specimen at 150 kPa: tens to hundreds of MPa.
    EXPECT_GT(l.unload_secant, 20e6);
    EXPECT_LT(l.unload_secant, 2000e6);
    EXPECT_GT(l.reload_secant, 0.5 * l.unload_secant);
    EXPECT_LT(l.reload_secant, 1.5 * l.unload_secant);
    EXPECT_GT(l.loop_area, 0.0);  // energy is dissipated: friction
    EXPECT_GT(l.damping_ratio, 0.0);
    EXPECT_LT(l.damping_ratio, 0.5);
    EXPECT_NEAR(l.unload_secant, (l.q_a - l.q_b) / (l.eps_a - l.eps_b), 1e-6 * l.unload_secant);
  }
  EXPECT_GT(r.loops[1].loop_area, r.loops[0].loop_area);  // a larger cycle dissipates more
  EXPECT_LT(r.worst_confinement_error, 0.02);
  EXPECT_GT(r.peak_q, r.loops[1].q_a);
  EXPECT_GT(r.steps, 1000);

  // The history: phases in order, strains and stresses consistent, confinement held.
  ASSERT_GT(r.history.size(), 50u);
  const std::vector<TriaxialPhase> order{TriaxialPhase::Load,   TriaxialPhase::Unload, TriaxialPhase::Reload, TriaxialPhase::Load,
                                         TriaxialPhase::Unload, TriaxialPhase::Reload, TriaxialPhase::Final};
  std::size_t stage = 0;
  for (const TriaxialRow& row : r.history) {
    if (row.phase != order[stage]) {
      ++stage;
      ASSERT_LT(stage, order.size());
      ASSERT_EQ(row.phase, order[stage]) << "row at step " << row.step;
    }
    EXPECT_NEAR(row.eps_v, row.eps_a + 2 * row.eps_r, 1e-15);
    EXPECT_NEAR(row.q, row.sigma_a - row.sigma_r, 1e-9 * std::abs(row.sigma_a));
    EXPECT_NEAR(row.sigma_a, 0.5 * (row.sigma_top + row.sigma_bottom), 1e-9 * row.sigma_a);
    EXPECT_NEAR(row.sigma_r, 150e3, 0.02 * 150e3);
    EXPECT_GT(row.porosity, 0.2);
    EXPECT_LT(row.porosity, 0.6);
    EXPECT_GT(row.coordination, 2.0);
  }
  EXPECT_EQ(stage, order.size() - 1);
  EXPECT_GE(r.history.back().eps_a, mini_test().final_strain);
  EXPECT_EQ(r.history.front().step, 0);
  const std::string csv = r.history_csv();
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "step,time[s],phase,cycle,eps_a[-],eps_r[-],eps_v[-],sigma_a[Pa],sigma_r[Pa],q[Pa],sigma_top[Pa],sigma_bottom[Pa],"
            "porosity[-],coordination[-],platen_mismatch[-]");
  EXPECT_NE(r.loops_text().find("resilient modulus M_r (unload fit)"), std::string::npos);

  // Quasi-static: the platens carry the same force.
  EXPECT_LT(r.worst_platen_mismatch, 0.05);
  for (const TriaxialRow& row : r.history) EXPECT_LE(row.platen_mismatch, r.worst_platen_mismatch + 1e-15);
}

// The lab drivers step the engine through Simulation::drive, which writes the results only of the
// cycles after which they read the specimen. A no-op observer makes every cycle write everything,
// as cycle(1) after each cycle did: finalization (servo_equilibrium) and the test must give the same
// bits either way, every history row (its porosity and coordination read the contacts) included.
TEST(Triaxial, DrivenCyclesGiveTheResultsOfWatchedCycles) {
  Specimen driven = testing::mini_packed();
  Specimen watched = testing::mini_packed();
  int observed = 0;
  watched.sim.observers.push_back([&observed](const Simulation&) { ++observed; });
  finalize(driven, Class5Material{}, WallContact{}, EquilibriumSettings{}, nullptr);
  finalize(watched, Class5Material{}, WallContact{}, EquilibriumSettings{}, nullptr);
  EXPECT_EQ(observed, watched.sim.steps - testing::mini_packed().sim.steps);
  EXPECT_EQ(state_digest(driven.sim), state_digest(watched.sim));
  const std::int64_t passes_driven = driven.sim.live_record_passes(), passes_watched = watched.sim.live_record_passes();
  const TriaxialResult a = run_triaxial(driven, mini_test(), nullptr);
  const TriaxialResult b = run_triaxial(watched, mini_test(), nullptr);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.history_csv(), b.history_csv());  // every value printed to 9 digits, the step of every row
  ASSERT_EQ(a.history.size(), b.history.size());
  for (std::size_t k = 0; k < a.history.size(); ++k) {
    SCOPED_TRACE(k);
    EXPECT_EQ(a.history[k].step, b.history[k].step);
    EXPECT_EQ(a.history[k].q, b.history[k].q);
    EXPECT_EQ(a.history[k].porosity, b.history[k].porosity);
    EXPECT_EQ(a.history[k].coordination, b.history[k].coordination);
  }
  EXPECT_EQ(a.loops_text(), b.loops_text());
  EXPECT_EQ(a.peak_q, b.peak_q);
  EXPECT_EQ(state_digest(driven.sim), state_digest(watched.sim));
  // Unwatched cycles ran: the engine's live records served most force passes of the driven test.
  EXPECT_GT(driven.sim.live_record_passes() - passes_driven, a.steps / 2);
  EXPECT_EQ(watched.sim.live_record_passes(), passes_watched);  // (a watched cycle never runs them)
  EXPECT_TRUE(driven.sim.controllers.empty());
}

// Density scaling: about F times fewer steps, the same moduli (the half-size C5b study specimen
// gives M_r within 0.1 % at F = 2 and 4, docs/lab-tests.md); the settings are restored after.
TEST(Triaxial, DensityScalingSameModuliInFewerSteps) {
  Specimen base = testing::mini_packed();
  finalize(base, Class5Material{}, WallContact{}, EquilibriumSettings{}, nullptr);
  Specimen scaled = base;
  const TriaxialSettings t = mini_test();
  TriaxialSettings ts = t;
  ts.density_scaling = 2;
  const SimulationSettings before = scaled.sim.settings;
  const TriaxialResult r0 = run_triaxial(base, t, nullptr);
  const TriaxialResult r3 = run_triaxial(scaled, ts, nullptr);
  ASSERT_EQ(r3.loops.size(), 2u);
  EXPECT_LT(r3.steps, 0.6 * r0.steps);
  for (std::size_t k = 0; k < 2; ++k) {
    SCOPED_TRACE(k);
    EXPECT_NEAR(r3.loops[k].unload_secant, r0.loops[k].unload_secant, 0.01 * r0.loops[k].unload_secant);
  }
  // This miniature test loads 5 times faster than the study's default rate; at F = 2 its peak moves
  // by 2.8 % and its worst confinement error is 3.4 % (1,688 grains at the default rate: 0.6 %, 0.8 %).
  EXPECT_NEAR(r3.peak_q, r0.peak_q, 0.05 * r0.peak_q);
  EXPECT_LT(r3.worst_confinement_error, 0.05);
  EXPECT_EQ(scaled.sim.settings.auto_timestep, before.auto_timestep);
  EXPECT_EQ(scaled.sim.settings.density_scaling, before.density_scaling);
}

// ---------------------------------------------------------------------------------------------------
// Finalization, wetting, the saved specimen.

TEST(Finalize, InstallsTheMaterialThroughTheTable) {
  Specimen s = testing::mini_packed();
  finalize(s, Class5Material{}, WallContact{}, EquilibriumSettings{}, nullptr);
  EXPECT_EQ(s.material, "fine_Hill");
  std::size_t hill = 0, linear_walls = 0;
  for (std::size_t c = 0; c < s.sim.contacts.size(); ++c) {
    if (!s.sim.contacts.exists[c]) continue;
    if (s.sim.contacts.key[c].kind == ContactKind::BallBall) {
      EXPECT_EQ(s.sim.contacts.model[c], ModelKind::Hill);
      EXPECT_DOUBLE_EQ(s.sim.contacts.hill_params[c].fric_coef, 0.4);
      ++hill;
    } else {
      EXPECT_EQ(s.sim.contacts.model[c], ModelKind::Linear);
      EXPECT_DOUBLE_EQ(s.sim.contacts.linear_params[c].emod, 500e6);
      ++linear_walls;
    }
  }
  EXPECT_GT(hill, 300u);
  EXPECT_GT(linear_walls, 50u);

  Specimen lin = testing::mini_packed();
  Class5Material m;
  m.model = GrainModel::Linear;
  const PhaseReport p = finalize(lin, m, WallContact{}, EquilibriumSettings{}, nullptr);
  EXPECT_NEAR(p.state.radial_stress, 150e3, 1.5e3);
  for (std::size_t c = 0; c < lin.sim.contacts.size(); ++c)
    if (lin.sim.contacts.exists[c] && lin.sim.contacts.key[c].kind == ContactKind::BallBall) {
      EXPECT_EQ(lin.sim.contacts.model[c], ModelKind::Linear);
      EXPECT_DOUBLE_EQ(lin.sim.contacts.linear_params[c].kratio, 1.5);
      EXPECT_DOUBLE_EQ(lin.sim.contacts.linear_params[c].fric, 0.4);
    }
  EXPECT_THROW(make_specimen_wet(lin, 20e3, 3e-3, EquilibriumSettings{}, nullptr), InputError);
}

TEST(Wet, MakeWetThenReEquilibrate) {
  Specimen s = testing::mini_packed();
  finalize(s, Class5Material{}, WallContact{}, EquilibriumSettings{}, nullptr);
  const SpecimenState dry = measure(s);
  const PhaseReport p = make_specimen_wet(s, 20e3, 3e-3, EquilibriumSettings{}, nullptr);
  EXPECT_TRUE(s.wet);
  EXPECT_GT(p.state.wet_contacts, dry.coordination * dry.grains / 2);  // every touching pair and more
  EXPECT_NEAR(p.state.radial_stress, 150e3, 1.5e3);
  EXPECT_NEAR(p.state.top_stress, 150e3, 1.5e3);
  // Suction pulls the grains together: at the same wall pressure the specimen is denser.
  EXPECT_LT(p.state.porosity, dry.porosity);
}

TEST(SpecimenFile, SavedPackedSpecimenReloadsToTheSameState) {
  const Specimen& s = testing::mini_packed();
  const PackingSettings ps = testing::mini_spec().packing;
  const std::string text = packed_specimen_text(s, ps);
  PackingSettings back;
  const Specimen t = parse_packed_specimen(text, "mem", &back);
  EXPECT_EQ(t.sim.balls.size(), s.sim.balls.size());
  EXPECT_EQ(t.grading, s.grading);
  EXPECT_EQ(t.seed, s.seed);
  EXPECT_DOUBLE_EQ(back.contact.emod, ps.contact.emod);
  const SpecimenState a = measure(s), b = measure(t);
  EXPECT_DOUBLE_EQ(a.porosity, b.porosity);
  // Contact forces of the packing contacts follow from the positions: the wall pressures are the same.
  EXPECT_NEAR(b.radial_stress, a.radial_stress, 1e-9 * a.radial_stress);
  EXPECT_NEAR(b.top_stress, a.top_stress, 1e-9 * a.top_stress);
  EXPECT_NEAR(b.bottom_stress, a.bottom_stress, 1e-9 * a.bottom_stress);
  EXPECT_DOUBLE_EQ(b.coordination, a.coordination);
  // Only packed specimens are saved; broken files are refused with the line.
  Specimen fin = testing::mini_packed();
  fin.material = "C5b_Hill";
  EXPECT_THROW(packed_specimen_text(fin, ps), InputError);
  std::string broken = text;
  broken.replace(broken.rfind('\n', broken.size() - 2) + 1, std::string::npos, "7,1,2\n");
  try {
    parse_packed_specimen(broken, "broken.csv");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.csv:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_packed_specimen("format,something-else,1\n", "x.csv"), InputError);
}

// Broken specimen files are refused like scenarios: the file, the line, the column, the range, the value.
std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}
std::string join_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string c; std::getline(ss, c, ',');) out.push_back(c);
  return out;
}
std::string row(const std::vector<std::string>& c) {
  std::string out;
  for (const std::string& x : c) out += (out.empty() ? "" : ",") + x;
  return out;
}
std::string refusal(const std::string& text) {
  try {
    parse_packed_specimen(text, "broken.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(SpecimenFile, PhysicallyBrokenSpecimensAreRefusedWithTheLineAndRange) {
  const std::string text = packed_specimen_text(testing::mini_packed(), testing::mini_spec().packing);
  std::vector<std::string> lines = split_lines(text);
  std::size_t first = 0;  // the first grain row
  while (cells(lines[first])[0] != "id") ++first;
  ++first;
  const std::string at = fmt::format("broken.csv:{}:", first + 1);
  auto with = [&](std::size_t line, int column, const std::string& value) {
    std::vector<std::string> l = lines;
    auto c = cells(l[line]);
    c[column] = value;
    l[line] = row(c);
    return join_lines(l);
  };
  EXPECT_EQ(refusal(text), "accepted");
  std::string e = refusal(with(first, 4, "1e-300"));
  EXPECT_NE(e.find(at), std::string::npos) << e;
  EXPECT_NE(e.find("radius[m] must be in [1e-06, 1], got 1e-300"), std::string::npos) << e;
  e = refusal(with(first, 7, "0.7"));
  EXPECT_NE(e.find("pois_ratio[-] must be in (-1, 0.5], got 0.7"), std::string::npos) << e;
  e = refusal(with(first, 6, "1e300"));
  EXPECT_NE(e.find("young_mod[Pa] must be in [100000, 1.2e+12], got 1e+300"), std::string::npos) << e;
  e = refusal(with(first, 5, "0"));
  EXPECT_NE(e.find("density[kg/m3] must be in [100, 25000], got 0"), std::string::npos) << e;
  // Two grains at one centre: the second row takes the first row's position.
  {
    std::vector<std::string> l = lines;
    auto a = cells(l[first]), b = cells(l[first + 1]);
    b[1] = a[1], b[2] = a[2], b[3] = a[3];
    l[first + 1] = row(b);
    e = refusal(join_lines(l));
    EXPECT_NE(e.find(fmt::format("broken.csv:{}: grains {} and {} (line {}) have one centre", first + 2, a[0], b[0], first + 1)),
              std::string::npos)
        << e;
  }
  // A grain grown into its neighbours: the grain nearest the vessel's centre, its radius × 1.3.
  {
    const Specimen& s = testing::mini_packed();
    const double zc = 0.5 * (s.vessel.bottom_z(s.sim) + s.vessel.top_z(s.sim));
    std::size_t best = first;
    double best_d = 1e9;
    for (std::size_t i = first; i < lines.size(); ++i) {
      const auto c = cells(lines[i]);
      const double d = std::hypot(std::stod(c[1]), std::stod(c[2]), std::stod(c[3]) - zc);
      if (d < best_d) best_d = d, best = i;
    }
    e = refusal(with(best, 4, fmt::format("{}", 1.3 * std::stod(cells(lines[best])[4]))));
    EXPECT_NE(e.find("overlap by"), std::string::npos) << e;
    EXPECT_NE(e.find("of the smaller diameter; at most 1 % is a packed state"), std::string::npos) << e;
    EXPECT_NE(e.find(cells(lines[best])[0]), std::string::npos) << e;
  }
  // A grain pushed through the lateral wall (its centre still inside).
  {
    const Specimen& s = testing::mini_packed();
    const double R = s.vessel.radius(s.sim);
    const auto c = cells(lines[first]);
    const double r = std::stod(c[4]);
    std::vector<std::string> l = lines;
    auto m = c;
    m[1] = fmt::format("{}", R - 0.5 * r), m[2] = "0";
    l[first] = row(m);
    e = refusal(join_lines(l));
    EXPECT_NE(e.find(at), std::string::npos) << e;
    EXPECT_NE(e.find("beyond a vessel wall"), std::string::npos) << e;
  }
}

// States and results that cannot be physical are named (run_study then fails with exit status 1).
// A sweep runs every case at each confinement, named by it; the findings compare cases of one confinement.
TEST(Study, ConfinementSweepNamesTheCasesAndGroupsTheFindings) {
  const auto cases = sweep_confinements(memo_cases(), {50e3, 100e3});
  ASSERT_EQ(cases.size(), 10u);
  EXPECT_EQ(cases[0].name(), "C5n_Linear_50kPa");
  EXPECT_EQ(cases[9].name(), "C5b_Hill_wet_100kPa");
  EXPECT_EQ(memo_cases()[3].name(), "C5b_Hill");  // no sweep: no suffix
  StudySettings st;
  EXPECT_DOUBLE_EQ(confinement_of(st, cases[9]), 100e3);
  EXPECT_DOUBLE_EQ(confinement_of(st, memo_cases()[0]), st.triaxial.confinement);
  StudyResult r;
  for (const CaseSpec& c : cases) {
    CaseResult cr;
    cr.spec = c;
    cr.grading.name = c.grading;
    LoopResult l;
    l.closed = true;
    l.loop_area = c.model == GrainModel::Hill ? 2.0 : 1.0;
    l.unload.valid = true;
    l.unload.slope = (c.grading == "C5b" ? 200e6 : 100e6) * c.confinement / 100e3;
    l.unload.slope_se = 1e6;
    cr.test.loops = {l};
    cr.test.peak_q = c.confinement;
    r.cases.push_back(cr);
  }
  const auto f = r.findings();
  ASSERT_EQ(f.size(), 10u);  // five claims at each of two confinements
  EXPECT_EQ(f[0].rfind("at sigma_c = 50 kPa: hysteresis loops larger", 0), 0u) << f[0];
  EXPECT_EQ(f[5].rfind("at sigma_c = 100 kPa: hysteresis loops larger", 0), 0u) << f[5];
  // Within one confinement C5b is stiffer (across them a 50 kPa C5b would not be).
  EXPECT_NE(f[1].find("HOLDS (2 of 2 comparisons)"), std::string::npos) << f[1];
  EXPECT_NE(f[6].find("M_r C5b 200.0 +- 1.0 vs C5n 100.0 +- 1.0 MPa"), std::string::npos) << f[6];
}

// The default vessel: a grading holding fewer than min_grains gets the same shape scaled up.
TEST(Study, MinGrainsScalesUpTheVesselOfACoarseGrading) {
  StudySettings st;
  st.genesis.vessel_radius = 0.0425;
  st.genesis.vessel_height = 0.120;
  const Grading n = grading_c5n(), b = grading_c5b();
  const double n_half = expected_grains(n, 1.0, 0.0425, 0.120, 0.58);
  EXPECT_GT(n_half, 90);  // about 110 grains of 14-20 mm in the half-size vessel
  EXPECT_LT(n_half, 130);
  st.min_grains = 0;
  EXPECT_EQ(vessel_for(st, n), std::make_pair(0.0425, 0.120));  // min_grains 0: as given
  st.min_grains = 500;
  const auto [rn, hn] = vessel_for(st, n);
  EXPECT_NEAR(rn / 0.0425, hn / 0.120, 1e-12);  // the same shape
  EXPECT_NEAR(expected_grains(n, 1.0, rn, hn, 0.58), 500, 1e-6);
  EXPECT_EQ(vessel_for(st, b), std::make_pair(0.0425, 0.120));  // C5b holds ~1,700: never scaled down
}

// StudySettings{} is the CLI's default study (`hilldem triaxial --study`): the memo's vessel scaled by
// 0.5, each grading's scaled up to hold 500 grains (C5n: 0.83), not the memo's full vessel.
TEST(Study, DefaultSettingsAreTheCLIsDefaultStudy) {
  const StudySettings st;
  EXPECT_DOUBLE_EQ(st.genesis.vessel_radius, 0.0425);
  EXPECT_DOUBLE_EQ(st.genesis.vessel_height, 0.120);
  EXPECT_EQ(st.min_grains, 500);
  EXPECT_EQ(vessel_for(st, grading_c5b()), std::make_pair(0.0425, 0.120));
  const auto [rn, hn] = vessel_for(st, grading_c5n());
  EXPECT_NEAR(rn / kMemoVesselRadius, 0.83, 0.01);
  EXPECT_NEAR(hn / kMemoVesselHeight, 0.83, 0.01);
  // Everything else is the genesis defaults.
  const GenesisSpec g;
  EXPECT_EQ(st.genesis.grading.name, g.grading.name);
  EXPECT_EQ(st.genesis.packing.seed, g.packing.seed);
  EXPECT_EQ(st.genesis.packing.equilibrium.pressure, g.packing.equilibrium.pressure);
}

TEST(Study, ImpossibleStatesAndResultsAreNamed) {
  SpecimenState st;
  st.porosity = 0.35;
  st.radial_stress = st.bottom_stress = st.top_stress = 151e3;
  EXPECT_TRUE(impossible_state(st, 150e3).empty());
  st.radial_stress = 215817e3;  // a grain grown into its neighbours
  auto bad = impossible_state(st, 150e3);
  ASSERT_EQ(bad.size(), 1u);
  EXPECT_NE(bad[0].find("sigma_r 215817 kPa, more than 25 % from the target 150 kPa"), std::string::npos) << bad[0];
  TriaxialResult r;
  LoopResult l;
  l.cycle = 1;
  l.q_a = 30e3;
  l.closed = true;
  l.loop_area = 2.0;
  l.damping_ratio = 0.05;
  r.loops = {l};
  r.peak_q = 200e3;
  EXPECT_TRUE(impossible_results(r).empty());
  r.loops[0].loop_area = -1.5;
  r.loops[0].damping_ratio = -0.02;
  bad = impossible_results(r);
  ASSERT_EQ(bad.size(), 2u);
  EXPECT_NE(bad[0].find("cycle 1: loop area -1.5 J/m^3 < 0"), std::string::npos) << bad[0];
  EXPECT_NE(bad[1].find("damping ratio -0.02 < 0"), std::string::npos) << bad[1];
  r.loops[0] = l;
  r.loops[0].q_a = -4e3;
  r.peak_q = -1e3;
  bad = impossible_results(r);
  ASSERT_EQ(bad.size(), 2u);
  EXPECT_NE(bad[0].find("q_A = -4 kPa under compression"), std::string::npos) << bad[0];
  EXPECT_NE(bad[1].find("peak deviator -1 kPa"), std::string::npos) << bad[1];
}

// ---------------------------------------------------------------------------------------------------
// The study driver on the miniature specimen: files, summary, findings.

// A study of the miniature specimen, saved into a fresh folder `dir`: one cycle at 0.02 %, then on to
// final_strain [-].
StudySettings mini_study(const std::filesystem::path& dir, double final_strain) {
  StudySettings st = testing::mini_study_from_saved(dir);
  st.triaxial = mini_test();
  st.triaxial.cycle_strains = {2e-4};
  st.triaxial.final_strain = final_strain;
  return st;
}

TEST(Study, TwoCasesFromASavedSpecimenWriteTheirFilesAndSummary) {
  const auto dir = std::filesystem::temp_directory_path() / "hilldem_labtests_study";
  const StudySettings st = mini_study(dir, 5e-4);
  const std::string grading = std::string(HILLDEM_SOURCE_DIR) + "/tests/data/labtests/fine.csv";
  const StudyResult r = run_study(st, {{grading, GrainModel::Linear, false}, {grading, GrainModel::Hill, false}}, nullptr);
  ASSERT_EQ(r.cases.size(), 2u);
  for (const CaseResult& c : r.cases) {
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(c.dir) / "history.csv"));
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(c.dir) / "gsd.csv"));
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(c.dir) / "loops.csv"));
    EXPECT_EQ(c.packed.grains, testing::mini_packed().sim.balls.size());
    ASSERT_EQ(c.test.loops.size(), 1u);
  }
  EXPECT_EQ(r.cases[0].spec.name(), "fine_Linear");
  EXPECT_EQ(r.cases[1].spec.name(), "fine_Hill");
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "summary.csv"));
  const std::string md = r.summary_markdown();
  EXPECT_NE(md.find("| fine_Linear |"), std::string::npos);
  EXPECT_NE(md.find("M_r c1 [MPa]"), std::string::npos);
  EXPECT_TRUE(r.findings().empty());  // no C5n/C5b cases here
  std::filesystem::remove_all(dir);
}

// Cases run at once (--jobs) give the same bits as one after the other: each case is computed alone.
TEST(Study, CasesRunAtOnceGiveTheSameResultsAsOneAfterTheOther) {
  const auto dir = std::filesystem::temp_directory_path() / "hilldem_labtests_study_jobs";
  StudySettings st = mini_study(dir, 4e-4);
  const std::string grading = std::string(HILLDEM_SOURCE_DIR) + "/tests/data/labtests/fine.csv";
  const std::vector<CaseSpec> cases{{grading, GrainModel::Linear, false}, {grading, GrainModel::Hill, false},
                                    {grading, GrainModel::Hill, true}};
  auto run = [&](int jobs, std::ostringstream& log) {
    st.jobs = jobs;
    st.output_dir = (dir / ("jobs" + std::to_string(jobs))).string();
    return run_study(st, cases, &log);
  };
  std::ostringstream log1, log3;
  const StudyResult one = run(1, log1);
  const StudyResult three = run(3, log3);
  ASSERT_EQ(three.cases.size(), cases.size());
  for (std::size_t k = 0; k < cases.size(); ++k) {
    EXPECT_EQ(three.cases[k].spec.name(), cases[k].name());  // case order kept
    EXPECT_EQ(three.cases[k].test.history_csv(), one.cases[k].test.history_csv()) << cases[k].name();
  }
  // The summary too, but for its last column (the wall-clock seconds of each case).
  auto without_seconds = [](const std::string& csv) {
    std::istringstream in(csv);
    std::string out;
    for (std::string line; std::getline(in, line);) out += line.substr(0, line.rfind(',')) + "\n";
    return out;
  };
  EXPECT_EQ(without_seconds(three.summary_csv()), without_seconds(one.summary_csv()));
  // With several jobs every log line names its case, and no line is cut by another case's output.
  std::istringstream lines(log3.str());
  std::size_t count = 0;
  for (std::string line; std::getline(lines, line); ++count) {
    const bool named = line.rfind("[fine_Linear] ", 0) == 0 || line.rfind("[fine_Hill] ", 0) == 0 ||
                       line.rfind("[fine_Hill_wet] ", 0) == 0 || line.rfind("[specimen fine] ", 0) == 0;
    EXPECT_TRUE(named) << line;
  }
  EXPECT_GT(count, 10u);
  EXPECT_EQ(log1.str().find("[fine_Hill]"), std::string::npos);  // one job: the log as before
  std::filesystem::remove_all(dir);
}

TEST(Study, BadJobsCountIsRefused) {
  StudySettings st;
  st.genesis = testing::mini_spec();
  st.jobs = -1;
  const std::string grading = std::string(HILLDEM_SOURCE_DIR) + "/tests/data/labtests/fine.csv";
  try {
    validate(st, {{grading, GrainModel::Hill, false}});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--jobs"), std::string::npos) << e.what();
  }
}

TEST(Study, FindingsAreComputedFromTheNumbers) {
  auto make = [](const char* g, GrainModel m, bool wet, double area, double mr, double peak) {
    CaseResult c;
    c.spec = {g, m, wet};
    c.grading.name = g;
    LoopResult l;
    l.loop_area = area;
    l.unload_secant = mr;
    l.unload.slope = mr;
    l.unload.slope_se = 1e6;  // 1 MPa
    l.unload.points = 100;
    l.unload.valid = true;
    l.closed = true;
    c.test.loops = {l};
    c.test.peak_q = peak;
    return c;
  };
  StudyResult r;
  r.cases = {make("C5n", GrainModel::Linear, false, 1.0, 100e6, 200e3), make("C5n", GrainModel::Hill, false, 2.0, 110e6, 210e3),
             make("C5b", GrainModel::Linear, false, 1.5, 150e6, 250e3), make("C5b", GrainModel::Hill, false, 3.0, 200e6, 300e3),
             make("C5b", GrainModel::Hill, true, 3.5, 190e6, 320e3)};
  const auto f = r.findings();
  ASSERT_EQ(f.size(), 5u);
  EXPECT_NE(f[0].find("HOLDS (2 of 2 comparisons)"), std::string::npos) << f[0];
  EXPECT_NE(f[0].find("x2.00"), std::string::npos) << f[0];
  EXPECT_NE(f[1].find("HOLDS"), std::string::npos) << f[1];
  EXPECT_NE(f[2].find("HOLDS"), std::string::npos) << f[2];
  EXPECT_NE(f[3].find("HOLDS"), std::string::npos) << f[3];  // hill 200/110 = 1.82 > linear 1.5; peaks 1.43 > 1.25
  EXPECT_NE(f[4].find("DOES NOT HOLD (0 of 1 comparisons)"), std::string::npos) << f[4];  // wet 190 < dry 200
  // A claim that holds for some comparisons only says so.
  r.cases[1].test.loops[0].loop_area = 0.5;  // C5n hill loop now smaller than linear's
  EXPECT_NE(r.findings()[0].find("HOLDS IN PART (1 of 2 comparisons)"), std::string::npos) << r.findings()[0];
  // Moduli that differ by less than twice the standard error of their difference (1.4 MPa) are
  // within noise, whichever is larger.
  r.cases[4].test.loops[0].unload.slope = 201e6;  // wet 201 +- 1 vs dry 200 +- 1 MPa
  EXPECT_NE(r.findings()[4].find("WITHIN NOISE (1 of 1 comparisons within 2 standard errors)"), std::string::npos) << r.findings()[4];
  EXPECT_NE(r.findings()[4].find("wet 201.0 +- 1.0 vs dry 200.0 +- 1.0 MPa"), std::string::npos) << r.findings()[4];
  r.cases[4].test.loops[0].unload.slope = 203e6;  // beyond 2 x 1.41 MPa
  EXPECT_NE(r.findings()[4].find("HOLDS (1 of 1 comparisons)"), std::string::npos) << r.findings()[4];
  // The same M_r with a large uncertainty: within noise.
  r.cases[4].test.loops[0].unload.slope_se = 3e6;
  EXPECT_NE(r.findings()[4].find("WITHIN NOISE"), std::string::npos) << r.findings()[4];
  // A C5n fit too uncertain to tell: that stiffness comparison is within noise, the claim holds in part.
  r.cases[0].test.loops[0].unload.slope_se = 40e6;  // C5n linear 100 +- 40 vs C5b linear 150 +- 1
  EXPECT_NE(r.findings()[1].find("HOLDS IN PART (1 of 2 comparisons; 1 within noise)"), std::string::npos) << r.findings()[1];
}

// Where the time goes: a packing shared by two cases is listed once, every case phase and test has
// its row, grain-steps are grains × steps and their shares add up to 100 %.
TEST(Study, TimeTableListsEachPackingOnceAndEveryCasePhase) {
  auto phase = [](const std::string& name, std::size_t grains, std::int64_t steps, double seconds) {
    PhaseReport p;
    p.name = name;
    p.state.grains = grains;
    p.steps = steps;
    p.seconds = seconds;
    return p;
  };
  auto make = [&](bool wet) {
    CaseResult c;
    c.spec = {"C5b", GrainModel::Hill, wet};
    c.grading.name = "C5b";
    c.packed_with = GrainModel::Hill;
    c.phases = {phase("cloud", 1000, 2000, 1.0), phase("packing", 1000, 100000, 50.0), phase("finalize C5b_Hill", 1000, 5000, 2.5)};
    if (wet) c.phases.push_back(phase("wet C5b_Hill", 1000, 6000, 3.0));
    c.initial.grains = 1000;
    c.test.steps = wet ? 140000 : 110000;
    c.test.seconds = wet ? 80.0 : 60.0;
    return c;
  };
  StudyResult r;
  r.cases = {make(false), make(true)};
  const std::string t = r.time_markdown();
  auto count = [&](const std::string& s) {
    std::size_t n = 0;
    for (std::size_t p = t.find(s); p != std::string::npos; p = t.find(s, p + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("| packing C5b hill: servo packing | 1000 | 100000 | 100.0 |"), 1u) << t;
  EXPECT_EQ(count("| packing C5b hill: cloud relaxation | 1000 | 2000 | 2.0 |"), 1u) << t;
  EXPECT_EQ(count("| C5b_Hill: finalize C5b_Hill | 1000 | 5000 | 5.0 |"), 1u) << t;
  EXPECT_EQ(count("| C5b_Hill_wet: finalize C5b_Hill | 1000 | 5000 | 5.0 |"), 1u) << t;
  EXPECT_EQ(count("| C5b_Hill_wet: wet C5b_Hill | 1000 | 6000 | 6.0 |"), 1u) << t;
  EXPECT_EQ(count("| C5b_Hill_wet: triaxial test | 1000 | 140000 | 140.0 | 38.0 | 80.0 | 0.571 |"), 1u) << t;
  // 2,000 + 100,000 + 2 × 5,000 + 6,000 + 110,000 + 140,000 = 368,000 steps of 1,000 grains; 199 s.
  EXPECT_EQ(count("| all rows | | 368000 | 368.0 | 100.0 | 199.0 | 0.541 |"), 1u) << t;
  EXPECT_NE(r.summary_markdown().find("Where the time goes"), std::string::npos);
}

}  // namespace
}  // namespace hilldem
