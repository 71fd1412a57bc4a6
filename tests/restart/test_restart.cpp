// Restart-then-continue gives bitwise the same final state as an uninterrupted run.
//
// The bed (tests/data/restart/wet_servo_box.toml) has wet and dry hill contacts, linear wall contacts,
// a servo-driven lid, solve / cycle / translate stages and checkpoints every 700 steps. Each test
// stops a run after some step as if the process had died there (RunOptions::halt_after_step: no
// stage-end outputs, no final checkpoint, the history file left as it was), resumes it from its
// newest checkpoint and compares with an uninterrupted run: the whole state (every ball column, every
// wall, every contact column, the clock and settings), the probes, the history CSV and the snapshot
// files, byte for byte.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>

#include "hilldem/core/error.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/state_io.hpp"

namespace {

namespace fs = std::filesystem;
using namespace hilldem;

const std::string kBed = std::string(HILLDEM_SOURCE_DIR) + "/tests/data/restart/wet_servo_box.toml";

// Scratch folders in memory when possible (/dev/shm): checkpoints are fsync'ed, which costs a disk.
fs::path scratch_root() {
  std::error_code ec;
  const fs::path base = fs::is_directory("/dev/shm", ec) ? fs::path("/dev/shm") : fs::temp_directory_path();
  return base / ("hilldem_restart_" + std::to_string(::getpid()));
}

fs::path scratch(const std::string& name) {
  const fs::path p = scratch_root() / name;
  fs::remove_all(p);
  return p;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Every regular file under dir (relative path -> bytes), checkpoints excluded (their file names
// depend on where runs stopped).
std::map<std::string, std::string> outputs(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const std::string rel = fs::relative(e.path(), dir).string();
    if (rel.rfind("checkpoints", 0) == 0) continue;
    files[rel] = slurp(e.path());
  }
  return files;
}

RunOptions quiet_options(const fs::path& dir, std::int64_t halt = -1) {
  RunOptions o;
  o.quiet = true;
  o.output_dir = dir.string();
  o.halt_after_step = halt;
  return o;
}

struct Finished {
  Scenario sc;
  RunResult result;
};

Finished run_whole(const fs::path& dir) {
  Finished f{load_scenario_file(kBed), {}};
  std::ostringstream log;
  f.result = run_scenario(f.sc, quiet_options(dir), log);
  return f;
}

// The uninterrupted reference, computed once.
const Finished& reference() {
  static const Finished f = run_whole(scratch("reference"));
  return f;
}
const fs::path& reference_dir() {
  static const fs::path d = [] {
    reference();
    return scratch_root() / "reference";
  }();
  return d;
}

void expect_same_as_reference(const Scenario& sc, const RunResult& res, const fs::path& dir) {
  const Finished& ref = reference();
  EXPECT_EQ(state_difference(ref.sc.sim, sc.sim), "") << "the final states differ";
  EXPECT_EQ(state_digest(ref.sc.sim), state_digest(sc.sim));
  ASSERT_EQ(res.probes.size(), ref.result.probes.size());
  for (std::size_t k = 0; k < res.probes.size(); ++k) {
    EXPECT_EQ(res.probes[k].label, ref.result.probes[k].label);
    EXPECT_EQ(res.probes[k].value, ref.result.probes[k].value) << res.probes[k].label;  // bitwise
  }
  const auto a = outputs(reference_dir()), b = outputs(dir);
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, bytes] : a) {
    ASSERT_TRUE(b.count(name)) << name << " is missing after the restart";
    EXPECT_TRUE(b.at(name) == bytes) << name << " differs after the restart";
  }
}

TEST(Restart, TheBedHasWetAndDryHillContactsAndAServo) {
  const Finished& ref = reference();
  const Simulation& sim = ref.sc.sim;
  int wet = 0, dry_hill = 0, wall = 0;
  for (std::size_t c = 0; c < sim.contacts.size(); ++c) {
    if (!sim.contacts.exists[c]) continue;
    if (sim.contacts.model[c] == ModelKind::Linear) ++wall;
    else if (sim.contacts.moisture[c] == Moisture::Wet) ++wet;
    else ++dry_hill;
  }
  EXPECT_GT(wet, 10);
  EXPECT_GT(dry_hill, 0);
  EXPECT_GT(wall, 0);
  ASSERT_EQ(ref.sc.servos.size(), 1u);
  // The servo held the lid near its 5 kPa target while it was on (history column lid_stress).
  EXPECT_GT(ref.result.find("stress")->value, 1e3);
  EXPECT_GE(ref.sc.sim.steps, 5000);
}

TEST(Restart, TwoUninterruptedRunsAreBitwiseIdentical) {
  const fs::path dir = scratch("again");
  const Finished again = run_whole(dir);
  expect_same_as_reference(again.sc, again.result, dir);
}

// Halt after `step`, resume from the newest checkpoint, finish; then compare.
void halt_and_resume(std::int64_t step) {
  const fs::path dir = scratch("halt_" + std::to_string(step));
  {
    Scenario sc = load_scenario_file(kBed);
    std::ostringstream log;
    const RunResult r = run_scenario(sc, quiet_options(dir, step), log);
    ASSERT_TRUE(r.halted) << "the run ended before step " << step;
    ASSERT_EQ(sc.sim.steps, step);
  }
  Scenario resumed;
  std::ostringstream log;
  const RunResult r = resume_scenario(dir.string(), resumed, quiet_options(""), log);
  EXPECT_FALSE(r.halted);
  expect_same_as_reference(resumed, r, dir);
}

TEST(Restart, MidSolveBeforeAnyPeriodicCheckpoint) { halt_and_resume(300); }  // from the checkpoint at the start
TEST(Restart, MidCycleStage) { halt_and_resume(1750); }
TEST(Restart, JustAfterAPeriodicCheckpoint) { halt_and_resume(2100); }
TEST(Restart, MidTranslateStage) { halt_and_resume(5150); }
TEST(Restart, MidFinalSolve) { halt_and_resume(5500); }

TEST(Restart, ResumedTwiceInARow) {
  const fs::path dir = scratch("twice");
  {
    Scenario sc = load_scenario_file(kBed);
    std::ostringstream log;
    ASSERT_TRUE(run_scenario(sc, quiet_options(dir, 1300), log).halted);
  }
  {
    Scenario sc;
    std::ostringstream log;
    ASSERT_TRUE(resume_scenario(dir.string(), sc, quiet_options("", 4300), log).halted);
  }
  Scenario sc;
  std::ostringstream log;
  const RunResult r = resume_scenario(dir.string(), sc, quiet_options(""), log);
  expect_same_as_reference(sc, r, dir);
}

TEST(Restart, ResumingAFinishedRunChangesNothing) {
  const fs::path dir = scratch("finished");
  Finished f = run_whole(dir);
  Scenario sc;
  std::ostringstream log;
  const RunResult r = resume_scenario(dir.string(), sc, quiet_options(""), log);
  EXPECT_TRUE(r.already_complete);
  expect_same_as_reference(sc, r, dir);
}

TEST(Restart, EveryCheckpointRestoresTheStateItSaved) {
  // read_simulation checks the restored state's digest against the saved one; a checkpoint restored
  // without preparing to cycle must give the same bytes as one prepared.
  const fs::path dir = scratch("digests");
  run_whole(dir);
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir / "checkpoints")) {
    const CheckpointReader r = CheckpointReader::from_file(e.path().string());
    Simulation raw, ready;
    read_simulation(r, raw, false);
    read_simulation(r, ready, true);
    EXPECT_EQ(state_difference(raw, ready), "") << e.path();
    ++n;
  }
  EXPECT_EQ(n, 3);  // keep = 3
}

TEST(Restart, TheMoistureTestResumesFromAStageEnd) {
  // The memo's moisture test (make_wet, solve, translate, rupture, re-wetting) halted mid-translate.
  const std::string file = std::string(HILLDEM_SOURCE_DIR) + "/examples/moisture_test.toml";
  const fs::path ref_dir = scratch("moisture_ref"), dir = scratch("moisture");
  Scenario ref = load_scenario_file(file);
  std::ostringstream log;
  const RunResult whole = run_scenario(ref, quiet_options(ref_dir), log);
  {
    Scenario sc = load_scenario_file(file);
    ASSERT_TRUE(run_scenario(sc, quiet_options(dir, 6000), log).halted);
  }
  Scenario sc;
  const RunResult r = resume_scenario(dir.string(), sc, quiet_options(""), log);
  EXPECT_EQ(state_difference(ref.sim, sc.sim), "");
  ASSERT_EQ(r.probes.size(), whole.probes.size());
  for (std::size_t k = 0; k < r.probes.size(); ++k) EXPECT_EQ(r.probes[k].value, whole.probes[k].value);
  EXPECT_TRUE(slurp(ref_dir / "history.csv") == slurp(dir / "history.csv"));
}

TEST(Restart, PeriodicBoxResumesBitwise) {
  // Grains thrown across the periodic boundaries of tests/data/restart/periodic_bed.toml: the engine
  // wraps positions at each neighbour-list rebuild, so the resumed run must rebuild at the same steps
  // (the checkpoint's sim.cycle section).
  const std::string file = std::string(HILLDEM_SOURCE_DIR) + "/tests/data/restart/periodic_bed.toml";
  const fs::path ref_dir = scratch("periodic_ref"), dir = scratch("periodic");
  Scenario ref = load_scenario_file(file);
  std::ostringstream log;
  run_scenario(ref, quiet_options(ref_dir), log);
  ASSERT_GT(ref.sim.rebuilds(), 3);  // the list was rebuilt (and positions wrapped) several times
  bool wrapped = false;              // some grain crossed x = box_max and was wrapped
  for (const Vec3& x : ref.sim.balls.position) wrapped |= x.x < 2.2e-3 - 1e-4;
  EXPECT_TRUE(wrapped);
  for (std::int64_t halt : {1300, 2050}) {
    SCOPED_TRACE(halt);
    fs::remove_all(dir);
    {
      Scenario sc = load_scenario_file(file);
      ASSERT_TRUE(run_scenario(sc, quiet_options(dir, halt), log).halted);
    }
    Scenario sc;
    resume_scenario(dir.string(), sc, quiet_options(""), log);
    EXPECT_EQ(state_difference(ref.sim, sc.sim), "");
    EXPECT_EQ(state_digest(ref.sim), state_digest(sc.sim));
    EXPECT_EQ(sc.sim.rebuilds(), ref.sim.rebuilds());
    EXPECT_TRUE(slurp(ref_dir / "history.csv") == slurp(dir / "history.csv"));
  }
}

TEST(Restart, RollingResistanceMomentsResumeBitwise) {
  // examples/rolling_resistance.toml (rrlinear: a stored rolling moment per contact) halted while the
  // ball still rolls, resumed from a checkpoint taken with a non-zero moment.
  const std::string file = std::string(HILLDEM_SOURCE_DIR) + "/examples/rolling_resistance.toml";
  const fs::path ref_dir = scratch("rolling_ref"), dir = scratch("rolling");
  Scenario ref = load_scenario_file(file);
  ref.checkpoints.every = 30000;
  std::ostringstream log;
  run_scenario(ref, quiet_options(ref_dir), log);
  {
    Scenario sc = load_scenario_file(file);
    sc.checkpoints.every = 30000;
    ASSERT_TRUE(run_scenario(sc, quiet_options(dir, 100000), log).halted);
    ASSERT_GT(norm(sc.sim.contacts.moment_state.at(0)), 0.0);  // the moment the checkpoint at 90,000 holds
  }
  Scenario sc;
  resume_scenario(dir.string(), sc, quiet_options(""), log);
  EXPECT_EQ(state_difference(ref.sim, sc.sim), "");
  EXPECT_EQ(state_digest(ref.sim), state_digest(sc.sim));
}

// Remove this process's scratch folders at exit.
struct Cleanup : ::testing::Environment {
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(scratch_root(), ec);
  }
};
const auto* const cleanup = ::testing::AddGlobalTestEnvironment(new Cleanup);

}  // namespace
