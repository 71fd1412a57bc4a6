// Triaxial test: the loop analysis on known paths, a miniature test with cycles through the engine,
// finalization, wetting and the saved packed specimen.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <numbers>

#include "hilldem/core/error.hpp"
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
  EXPECT_NE(r.loops_text().find("resilient modulus M_r (unload secant)"), std::string::npos);

  // Quasi-static: the platens carry the same force.
  EXPECT_LT(r.worst_platen_mismatch, 0.05);
  for (const TriaxialRow& row : r.history) EXPECT_LE(row.platen_mismatch, r.worst_platen_mismatch + 1e-15);
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
}

}  // namespace
}  // namespace hilldem
