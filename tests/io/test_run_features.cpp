// What a run shows and how it stops: progress (io/progress.hpp), scenario-level servos ([[servo]],
// set_servo, servo.* quantities) and blow-up detection.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <unistd.h>

#include "hilldem/core/error.hpp"
#include "hilldem/io/progress.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/state_io.hpp"

namespace {

namespace fs = std::filesystem;
using namespace hilldem;

fs::path scratch(const std::string& name) {
  std::error_code ec;
  const fs::path base = fs::is_directory("/dev/shm", ec) ? fs::path("/dev/shm") : fs::temp_directory_path();
  const fs::path p = base / ("hilldem_features_" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  return p;
}

struct Cleanup : ::testing::Environment {
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(scratch(""), ec);
  }
};
const auto* const cleanup = ::testing::AddGlobalTestEnvironment(new Cleanup);

// ---- progress ----

struct FakeClock {
  double now = 100.0;
  Progress::Clock fn() {
    return [this] { return now; };
  }
};

Simulation two_balls() {
  Scenario sc = load_scenario(R"(
[[material]]
name = "g"
density = 2650
young_mod = 29e9
pois_ratio = 0.15
[[ball]]
id = 1
position = [0, 0, 0]
radius = 5e-3
material = "g"
fix = ["all"]
[[ball]]
id = 2
position = [0, 0, 9.9e-3]
radius = 5e-3
material = "g"
[[contact_model]]
between = "ball-ball"
model = "hill"
[[stage]]
type = "cycle"
steps = 1
)", "two.toml");
  sc.sim.update_forces();
  return std::move(sc.sim);
}

TEST(Progress, PlainLinesCarryStepsTimeStageProgressRatioAndEta) {
  Simulation sim = two_balls();
  FakeClock clock;
  std::ostringstream out;
  Progress p(out, ProgressMode::Auto, /*is_terminal=*/false, 10.0, clock.fn());
  p.begin_stage({2, 5, "cycle", "press", 1000, 0.0, 0}, 0);
  sim.steps = 400;
  sim.time = 2.5e-3;
  clock.now += 5.0;
  p.tick(sim, 400);
  EXPECT_EQ(out.str(), "") << "a line before the interval";
  clock.now += 5.0;  // 10 s for 400 steps: 40 steps/s, 600 left: 15 s
  p.tick(sim, 400);
  const std::string line = out.str();
  EXPECT_NE(line.find("[2/5] cycle 'press'"), std::string::npos) << line;
  EXPECT_NE(line.find("step 400"), std::string::npos) << line;
  EXPECT_NE(line.find("t = 2.5000e-03 s"), std::string::npos) << line;
  EXPECT_NE(line.find("stage 40.0% (400/1,000 steps)"), std::string::npos) << line;
  EXPECT_NE(line.find("ratio "), std::string::npos) << line;
  EXPECT_NE(line.find("40 steps/s"), std::string::npos) << line;
  EXPECT_NE(line.find("ETA 0:00:15"), std::string::npos) << line;
  EXPECT_EQ(line.back(), '\n');
  EXPECT_EQ(line.find('\r'), std::string::npos);
}

TEST(Progress, OnATerminalOneLineIsRewrittenInPlace) {
  Simulation sim = two_balls();
  FakeClock clock;
  std::ostringstream out;
  Progress p(out, ProgressMode::Auto, /*is_terminal=*/true, 10.0, clock.fn());
  p.begin_stage({1, 1, "cycle", "c", 100, 0.0, 0}, 0);
  for (int k = 1; k <= 4; ++k) {
    clock.now += 1.0;
    p.tick(sim, 20 * k);
  }
  const std::string s = out.str();
  EXPECT_EQ(std::count(s.begin(), s.end(), '\r'), 4);
  EXPECT_EQ(s.find('\n'), std::string::npos);
  p.clear();
  EXPECT_EQ(out.str().back(), '\r');  // the line is blanked before other output
}

TEST(Progress, SolveStagesEstimateFromTheRatioTrend) {
  Simulation sim = two_balls();
  FakeClock clock;
  std::ostringstream out;
  Progress p(out, ProgressMode::Lines, false, 1.0, clock.fn());
  p.begin_stage({1, 1, "solve", "s", -1, 1e-6, 1'000'000}, 0);
  clock.now += 1.0;
  p.tick(sim, 100, 1e-2);  // first sample
  clock.now += 1.0;
  p.tick(sim, 200, 1e-3);  // one decade per second; three left
  const std::string s = out.str();
  EXPECT_NE(s.find("ratio 1.000e-03 -> 1.0e-06"), std::string::npos) << s;
  EXPECT_NE(s.find("stage ~25%"), std::string::npos) << s;
  EXPECT_NE(s.find("ETA 0:00:03"), std::string::npos) << s;
}

TEST(Progress, OffPrintsNothingAndDurationsFormat) {
  Simulation sim = two_balls();
  std::ostringstream out;
  Progress p(out, ProgressMode::Off, true, 0.0);
  p.begin_stage({1, 1, "cycle", "c", 10, 0.0, 0}, 0);
  p.tick(sim, 5);
  EXPECT_EQ(out.str(), "");
  EXPECT_EQ(format_duration(3725), "1:02:05");
  EXPECT_EQ(format_duration(90061), "1:1:01:01");
  EXPECT_EQ(format_duration(-1), "?");
}

TEST(Progress, RunScenarioReportsUnlessQuiet) {
  const std::string file = std::string(HILLDEM_SOURCE_DIR) + "/examples/assembly_27.toml";
  for (bool quiet : {false, true}) {
    Scenario sc = load_scenario_file(file);
    std::ostringstream log, progress;
    RunOptions o;
    o.quiet = quiet;
    o.write_files = false;
    o.progress = ProgressMode::Lines;
    o.progress_interval = 1e-9;  // every tick
    o.progress_stream = &progress;
    run_scenario(sc, o, log);
    if (quiet) {
      EXPECT_EQ(progress.str(), "");
      EXPECT_EQ(log.str(), "");
    } else {
      EXPECT_NE(progress.str().find("[1/3] solve 'settle under gravity'"), std::string::npos);
      EXPECT_NE(progress.str().find("ETA"), std::string::npos);
      EXPECT_NE(log.str().find("equilibrium after"), std::string::npos);
    }
  }
}

// ---- servos ----

const char* kServoBox = R"(
[simulation]
timestep = "auto"
local_damping = 0.7
gravity = [0, 0, -9.81]
[[material]]
name = "granite"
density = 2650
young_mod = 29e9
pois_ratio = 0.15
[[ball_grid]]
first_id = 1
origin = [-10e-3, -10e-3, 5e-3]
counts = [3, 3, 3]
spacing = 10e-3
radius = 5e-3
material = "granite"
[[wall]]
name = "box"
type = "box"
min = [-16e-3, -16e-3, 0.0]
max = [16e-3, 16e-3, 31e-3]
[[servo]]
name = "lid"
wall = "box.zmax"
outward = [0, 0, 1]
target_stress = 2e4
max_speed = 0.05
area = "auto"
[[contact_model]]
between = "ball-ball"
model = "hill"
fric_coef = 0.4
damp_con = 0.07
[[contact_model]]
between = "ball-wall"
model = "linear"
emod = 29e6
fric = 0.4
[[history]]
name = "target"
quantity = "servo.target_stress"
servo = "lid"
[[stage]]
type = "cycle"
steps = 4000
[[stage]]
type = "probe"
label = "first"
quantity = "servo.stress"
servo = "lid"
[[stage]]
type = "set_servo"
servo = "lid"
target_stress = 4e4
[[stage]]
type = "cycle"
steps = 4000
[[stage]]
type = "probe"
label = "second"
quantity = "servo.stress"
servo = "lid"
[[stage]]
type = "probe"
label = "speed"
quantity = "servo.speed"
servo = "lid"
)";

TEST(Servo, DrivesTheLidToEachTargetStress) {
  Scenario sc = load_scenario(kServoBox, "servo.toml");
  ASSERT_EQ(sc.servos.size(), 1u);
  EXPECT_EQ(sc.servos[0].walls.size(), 2u);  // the lid's two facets
  std::ostringstream log;
  RunOptions o;
  o.quiet = true;
  o.write_files = false;
  const RunResult r = run_scenario(sc, o, log);
  EXPECT_NEAR(r.find("first")->value, 2e4, 0.02 * 2e4);
  EXPECT_NEAR(r.find("second")->value, 4e4, 0.02 * 4e4);
  EXPECT_LT(std::abs(r.find("speed")->value), 1e-3);  // settled, not hunting
  EXPECT_EQ(sc.servos[0].servo.settings.target_stress, 4e4);
}

TEST(Servo, BadServoInputIsRefusedWithTheKey) {
  auto error = [](const std::string& servo_table, const std::string& extra = "") {
    std::string text = kServoBox;
    const auto a = text.find("[[servo]]");
    const auto b = text.find("[[contact_model]]");
    text = text.substr(0, a) + servo_table + "\n" + text.substr(b);
    const auto h = text.find("[[history]]");
    text = text.substr(0, h) + extra;  // drop histories and stages that name "lid"
    try {
      load_scenario(text, "bad_servo.toml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string ok = "[[servo]]\nname = \"lid\"\nwall = \"box.zmax\"\noutward = [0, 0, 1]\ntarget_stress = 1e4\narea = 1e-3\n";
  EXPECT_EQ(error(ok), "accepted");
  EXPECT_NE(error("[[servo]]\nname = \"lid\"\nwall = \"nope\"\noutward = [0,0,1]\ntarget_stress = 1\narea = 1\n").find("servo[1].wall"), std::string::npos);
  EXPECT_NE(error("[[servo]]\nname = \"lid\"\nwall = \"box.zmax\"\nmode = \"radial\"\ntarget_stress = 1\narea = 1\n").find("not one"), std::string::npos);
  EXPECT_NE(error("[[servo]]\nname = \"lid\"\nwall = \"box.zmax\"\noutward = [0,0,0]\ntarget_stress = 1\narea = 1\n").find("zero vector"), std::string::npos);
  EXPECT_NE(error("[[servo]]\nname = \"lid\"\nwall = \"box.zmax\"\noutward = [0,0,1]\ntarget_stress = 1\narea = -1\n").find("servo[1].area"), std::string::npos);
  EXPECT_NE(error("[[servo]]\nname = \"lid\"\nwall = \"box.zmax\"\noutward = [0,0,1]\ntarget_stress = 1\narea = 1\ngain_factor = 2\n").find("(0, 1]"), std::string::npos);
  EXPECT_NE(error(ok + ok).find("defined twice"), std::string::npos);
  EXPECT_NE(error(ok + "[[servo]]\nname = \"b\"\nwall = \"box\"\noutward = [0,0,1]\ntarget_stress = 1\narea = 1\n").find("already driven"), std::string::npos);
  EXPECT_NE(error(ok, "[[stage]]\ntype = \"set_servo\"\nservo = \"lid\"\n").find("at least one of"), std::string::npos);
  EXPECT_NE(error(ok, "[[stage]]\ntype = \"set_servo\"\nservo = \"x\"\nenabled = false\n").find("no [[servo]] named"), std::string::npos);
  EXPECT_NE(error(ok, "[[history]]\nname = \"h\"\nquantity = \"servo.force\"\nservo = \"lid\"\n").find("unknown quantity"), std::string::npos);
  EXPECT_NE(error(ok, "[[history]]\nname = \"h\"\nquantity = \"servo.stress\"\n").find("history[1].servo"), std::string::npos);
}

// ---- blow-up detection ----

// A ball squeezed between two fixed ones with a time step far above the critical one: it rattles
// between them with growing amplitude until it jumps most of its radius in one step, into one of them.
const char* kUnstable = R"(
[simulation]
timestep = 1.5e-5
[output]
history_every = 1
[[material]]
name = "g"
density = 2650
young_mod = 29e9
pois_ratio = 0.15
[[ball]]
id = 1
position = [0, 0, 0]
radius = 5e-3
material = "g"
fix = ["all"]
[[ball]]
id = 7
position = [0, 0, 9.9e-3]
radius = 5e-3
material = "g"
[[ball]]
id = 9
position = [0, 0, 19.7e-3]
radius = 5e-3
material = "g"
fix = ["all"]
[[contact_model]]
between = "ball-ball"
model = "hill"
[[history]]
name = "z"
quantity = "ball.pos_z"
ball = 7
[[stage]]
name = "explode"
type = "cycle"
steps = 1000
)";

TEST(Blowup, StopsTheRunWithTheStepTheBallItsContactsAndAStateToInspect) {
  const fs::path dir = scratch("blowup");
  Scenario sc = load_scenario(kUnstable, "unstable.toml");
  RunOptions o;
  o.quiet = true;
  o.output_dir = dir.string();
  std::ostringstream log;
  std::string message;
  try {
    run_scenario(sc, o, log);
    FAIL() << "the unstable run finished";
  } catch (const RunError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("blow-up at step "), std::string::npos) << message;
  EXPECT_NE(message.find("ball 7 moved"), std::string::npos) << message;
  EXPECT_NE(message.find("of its radius"), std::string::npos) << message;
  EXPECT_NE(message.find("its contacts:"), std::string::npos) << message;
  EXPECT_TRUE(message.find("ball 1 - ball 7") != std::string::npos || message.find("ball 7 - ball 9") != std::string::npos)
      << message;
  EXPECT_NE(message.find("[1/1] cycle 'explode'"), std::string::npos) << message;
  const fs::path state = dir / ("blowup-step-" + std::to_string(sc.sim.steps) + ".hdc");
  ASSERT_TRUE(fs::exists(state)) << message;
  EXPECT_NE(message.find(state.string()), std::string::npos);
  // It can be inspected, it is not a restart point, and it holds the state at the blow-up.
  const std::string info = describe_checkpoint(state.string(), 7);
  EXPECT_NE(info.find("kind: blow-up"), std::string::npos) << info;
  EXPECT_NE(info.find("ball 7:"), std::string::npos) << info;
  EXPECT_TRUE(info.find("ball 1 - ball 7") != std::string::npos || info.find("ball 7 - ball 9") != std::string::npos) << info;
  Simulation saved;
  read_simulation(CheckpointReader::from_file(state.string()), saved, false);
  EXPECT_EQ(state_difference(saved, sc.sim), "");
  Scenario resumed;
  EXPECT_THROW(resume_scenario(state.string(), resumed, o, log), InputError);
  // Stopped within a few steps of the first jump, long before the 1000 steps.
  EXPECT_LT(sc.sim.steps, 50);
}

TEST(Blowup, ThresholdIsAParameterAndZeroTurnsTheMoveCheckOff) {
  // A free ball thrown at 10 m/s with a 1 ms step moves 10 mm per step: twice its radius.
  const std::string fast = R"(
[simulation]
timestep = 1e-3
blowup_fraction = BF
[[material]]
name = "g"
density = 2650
[[ball]]
id = 3
position = [0, 0, 0]
radius = 5e-3
material = "g"
velocity = [10, 0, 0]
[[stage]]
type = "cycle"
steps = 5
)";
  auto run = [&](const std::string& bf) {
    std::string text = fast;
    text.replace(text.find("BF"), 2, bf);
    Scenario sc = load_scenario(text, "fast.toml");
    RunOptions o;
    o.quiet = true;
    o.write_files = false;
    std::ostringstream log;
    try {
      run_scenario(sc, o, log);
    } catch (const RunError& e) {
      return std::string(e.what());
    }
    return std::string("finished");
  };
  EXPECT_NE(run("0.5").find("ball 3 moved 0.01 m in one step (2 of its radius"), std::string::npos);
  EXPECT_NE(run("0.5").find("no state file written"), std::string::npos);
  EXPECT_EQ(run("2.5"), "finished");
  EXPECT_EQ(run("0"), "finished");
}

}  // namespace
