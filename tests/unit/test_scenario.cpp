// Scenario reader: every key is validated before anything runs. A refused input is an InputError
// whose message names the file, the key path, the allowed range and the value given.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "hilldem/core/error.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/scenario.hpp"
#include "hilldem/io/state_io.hpp"

namespace {

using hilldem::InputError;
using hilldem::load_scenario;
using hilldem::Scenario;

const std::string kFile = "case.toml";

// A small valid scenario; the tests below break one thing at a time with replace().
const std::string kBase = R"(title = "base"

[simulation]
timestep = 1e-6
local_damping = 0.7
gravity = [0.0, 0.0, -9.81]

[[material]]
name = "granite"
density = 2650
young_mod = 29e9
pois_ratio = 0.15

[[ball]]
id = 1
position = [0.0, 0.0, 0.0]
radius = 5e-3
material = "granite"
groups = ["bottom"]
fix = ["all"]

[[ball]]
id = 2
position = [0.0, 0.0, 9.99e-3]
radius = 5e-3
material = "granite"
groups = ["top"]

[[wall]]
name = "floor"
type = "plane"
point = [0.0, 0.0, -5e-3]
normal = [0.0, 0.0, 1.0]

[[contact_model]]
name = "grain-grain"
between = "ball-ball"
model = "hill"
fric_coef = 0.4
damp_con = 0.07

[[contact_model]]
name = "grain-floor"
between = "ball-wall"
model = "linear"
emod = 29e6

[[history]]
name = "top_z"
quantity = "ball.pos_z"
ball = 2

[[stage]]
name = "settle"
type = "cycle"
steps = 10

[[stage]]
type = "probe"
label = "F"
quantity = "contact.normal_force"
balls = [1, 2]
)";

// kBase with the first occurrence of `from` replaced by `to`.
std::string replace(const std::string& from, const std::string& to, std::string text = kBase) {
  const auto at = text.find(from);
  if (at == std::string::npos) {
    ADD_FAILURE() << "test bug: \"" << from << "\" is not in the scenario text";
    return text;
  }
  text.replace(at, from.size(), to);
  return text;
}

// Message of the InputError that loading `text` throws; a test failure (and "") when it loads, or
// throws anything else.
std::string input_error(const std::string& text, const std::string& file = kFile) {
  try {
    load_scenario(text, file);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected hilldem::InputError, got another exception: " << e.what();
    return "";
  } catch (...) {
    ADD_FAILURE() << "expected hilldem::InputError, got a non-standard exception";
    return "";
  }
  ADD_FAILURE() << "expected hilldem::InputError, but the scenario loaded";
  return "";
}

::testing::AssertionResult Mentions(const std::string& message, std::initializer_list<std::string> parts) {
  for (const std::string& p : parts)
    if (message.find(p) == std::string::npos)
      return ::testing::AssertionFailure() << "the message lacks \"" << p << "\"\n  message: " << message;
  return ::testing::AssertionSuccess();
}

// The number after the last "; got " in a message (the value given, at full precision).
double given_number(const std::string& message) {
  const auto at = message.rfind("; got ");
  if (at == std::string::npos) {
    ADD_FAILURE() << "no \"; got \" in: " << message;
    return 0.0;
  }
  return std::strtod(message.c_str() + at + 6, nullptr);
}

// ---------------------------------------------------------------------------------------------------
// Valid inputs

TEST(ScenarioLoad, EveryExampleLoads) {
  const std::filesystem::path dir = std::filesystem::path(HILLDEM_SOURCE_DIR) / "examples";
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".toml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 6u);
  for (const auto& f : files) {
    SCOPED_TRACE(f.string());
    Scenario sc;
    EXPECT_NO_THROW(sc = hilldem::load_scenario_file(f.string()));
    EXPECT_EQ(sc.file, f.string());
    EXPECT_FALSE(sc.title.empty());
    EXPECT_GT(sc.sim.balls.size(), 0u);
    EXPECT_FALSE(sc.stages.empty());
  }
}

TEST(ScenarioLoad, Assembly27HasItsGrainsAndBox) {
  const Scenario sc =
      hilldem::load_scenario_file(std::string(HILLDEM_SOURCE_DIR) + "/examples/assembly_27.toml");
  EXPECT_EQ(sc.sim.balls.size(), 27u);
  EXPECT_EQ(sc.sim.walls.size(), 12u);  // a box is 12 facets
  EXPECT_EQ(sc.sim.table.rules.size(), 2u);
  EXPECT_TRUE(sc.sim.settings.auto_timestep);
  EXPECT_DOUBLE_EQ(sc.sim.settings.local_damping, 0.7);
}

TEST(ScenarioLoad, BaseScenarioLoadsWithItsValues) {
  const Scenario sc = load_scenario(kBase, kFile);
  EXPECT_EQ(sc.title, "base");
  EXPECT_EQ(sc.sim.balls.size(), 2u);
  EXPECT_EQ(sc.sim.walls.size(), 1u);
  ASSERT_EQ(sc.sim.table.rules.size(), 2u);
  EXPECT_DOUBLE_EQ(sc.sim.table.rules[0].hill.damp_con, 0.07);
  EXPECT_FALSE(sc.sim.settings.auto_timestep);
  EXPECT_DOUBLE_EQ(sc.sim.settings.timestep, 1e-6);
  ASSERT_EQ(sc.stages.size(), 2u);
  EXPECT_EQ(sc.stages[0].steps, 10);
  EXPECT_EQ(sc.histories.size(), 1u);
}

TEST(ScenarioLoad, RangeEndsThatAreInsideAreAccepted) {
  EXPECT_NO_THROW(load_scenario(replace("pois_ratio = 0.15", "pois_ratio = 0.5"), kFile));
  EXPECT_NO_THROW(load_scenario(replace("pois_ratio = 0.15", "pois_ratio = -0.99"), kFile));
  EXPECT_NO_THROW(load_scenario(replace("damp_con = 0.07", "damp_con = 0.0"), kFile));
  EXPECT_NO_THROW(load_scenario(replace("damp_con = 0.07", "damp_con = 0.999"), kFile));
  EXPECT_NO_THROW(load_scenario(replace("local_damping = 0.7", "local_damping = 0"), kFile));
  EXPECT_NO_THROW(load_scenario(replace("steps = 10", "steps = 1"), kFile));
}

// ---------------------------------------------------------------------------------------------------
// Unknown keys

TEST(ScenarioUnknownKey, TopLevel) {
  const std::string m = input_error("colour = \"red\"\n" + kBase);
  EXPECT_TRUE(Mentions(m, {kFile, "key 'colour'", "(line 1)", "unknown key", "allowed here:", "material", "stage"}));
}

TEST(ScenarioUnknownKey, InsideBall) {
  const std::string m = input_error(replace("groups = [\"top\"]", "groups = [\"top\"]\nmass = 1.0"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'ball[2].mass'", "unknown key", "radius", "position"}));
}

TEST(ScenarioUnknownKey, InsideStage) {
  const std::string m = input_error(replace("steps = 10", "steps = 10\nmax_step = 5"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'stage[1].max_step'", "unknown key", "steps"}));
}

TEST(ScenarioUnknownKey, InsideSimulation) {
  const std::string m = input_error(replace("local_damping = 0.7", "local_damping = 0.7\ngravty = [0, 0, -1]"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'simulation.gravty'", "unknown key", "gravity", "local_damping"}));
}

TEST(ScenarioUnknownKey, KeyOfAnotherModel) {
  // emod belongs to the linear model: a hill rule refuses it.
  const std::string m = input_error(replace("damp_con = 0.07", "damp_con = 0.07\nemod = 1e9"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'contact_model[1].emod'", "unknown key"}));
}

// ---------------------------------------------------------------------------------------------------
// Wrong types

TEST(ScenarioWrongType, StringForANumber) {
  const std::string m = input_error(replace("density = 2650", "density = \"heavy\""));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'material[1].density'", "(line 10)", "must be a number", "[0.001, 1e+06]",
                           "[kg/m^3]", "heavy"}));
}

TEST(ScenarioWrongType, TwoElementPosition) {
  const std::string m =
      input_error(replace("position = [0.0, 0.0, 9.99e-3]", "position = [0.0, 0.0]"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'ball[2].position'", "an array of 3 numbers", "[-1e+06, 1e+06]", "[m]",
                           "0.0, 0.0 ]"}));
}

TEST(ScenarioWrongType, StepsGivenAsFloat) {
  const std::string m = input_error(replace("steps = 10", "steps = 10.0"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'stage[1].steps'", "must be an integer", "[1, 1000000000000]", "got 10.0"}));
}

TEST(ScenarioWrongType, NumberForAString) {
  const std::string m = input_error(replace("material = \"granite\"", "material = 3"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'ball[1].material'", "must be a string", "got 3"}));
}

TEST(ScenarioWrongType, TableForAnArrayOfTables) {
  const std::string m = input_error("[ball]\nid = 1\n");
  EXPECT_TRUE(Mentions(m, {kFile, "key 'ball'", "array of tables", "[[ball]]"}));
}

TEST(ScenarioWrongType, ArrayOfTablesForATable) {
  const std::string m = input_error("[[simulation]]\ntimestep = 1e-6\n");
  EXPECT_TRUE(Mentions(m, {kFile, "key 'simulation'", "must be a table"}));
}

// ---------------------------------------------------------------------------------------------------
// Values out of range

TEST(ScenarioRange, PoissonRatioAboveHalf) {
  const std::string m = input_error(replace("pois_ratio = 0.15", "pois_ratio = 0.6"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'material[1].pois_ratio'", "(line 12)", "(-1, 0.5]", "; got "}));
  EXPECT_DOUBLE_EQ(given_number(m), 0.6);
}

TEST(ScenarioRange, PoissonRatioMinusOne) {
  const std::string m = input_error(replace("pois_ratio = 0.15", "pois_ratio = -1"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'material[1].pois_ratio'", "(-1, 0.5]", "got -1"}));
}

TEST(ScenarioRange, PoissonRatioNaN) {
  const std::string m = input_error(replace("pois_ratio = 0.15", "pois_ratio = nan"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'material[1].pois_ratio'", "(-1, 0.5]", "got nan"}));
}

TEST(ScenarioRange, DampConOne) {
  const std::string m = input_error(replace("damp_con = 0.07", "damp_con = 1.0"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'contact_model[1].damp_con'", "[0, 1)", "got 1.0"}));
}

TEST(ScenarioRange, DampConNegative) {
  const std::string m = input_error(replace("damp_con = 0.07", "damp_con = -0.1"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'contact_model[1].damp_con'", "[0, 1)", "; got "}));
  EXPECT_DOUBLE_EQ(given_number(m), -0.1);
}

TEST(ScenarioRange, DampConInASetContactsStage) {
  const std::string m =
      input_error(kBase + "\n[[stage]]\ntype = \"set_contacts\"\nmodel = \"hill\"\ndamp_con = 1.5\n");
  EXPECT_TRUE(Mentions(m, {kFile, "key 'stage[3].damp_con'", "[0, 1)", "got 1.5"}));
}

TEST(ScenarioRange, LocalDampingOne) {
  const std::string m = input_error(replace("local_damping = 0.7", "local_damping = 1.0"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'simulation.local_damping'", "[0, 1)", "got 1.0"}));
}

TEST(ScenarioRange, LocalDampingInASetSimulationStage) {
  const std::string m = input_error(kBase + "\n[[stage]]\ntype = \"set_simulation\"\nlocal_damping = 1\n");
  EXPECT_TRUE(Mentions(m, {kFile, "key 'stage[3].local_damping'", "[0, 1)", "got 1"}));
}

TEST(ScenarioRange, NegativeRadius) {
  const std::string m = input_error(replace("radius = 5e-3", "radius = -5e-3"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'ball[1].radius'", "[1e-09, 1000]", "[m]", "; got "}));
  EXPECT_DOUBLE_EQ(given_number(m), -5e-3);
}

TEST(ScenarioRange, ZeroRadius) {
  const std::string m = input_error(replace("radius = 5e-3", "radius = 0"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'ball[1].radius'", "[1e-09, 1000]", "got 0"}));
}

TEST(ScenarioRange, InfiniteRadius) {
  const std::string m = input_error(replace("radius = 5e-3", "radius = inf"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'ball[1].radius'", "[1e-09, 1000]", "got inf"}));
}

TEST(ScenarioRange, StepsZero) {
  const std::string m = input_error(replace("steps = 10", "steps = 0"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'stage[1].steps'", "[1, 1000000000000]", "got 0"}));
}

TEST(ScenarioRange, NegativeBallId) {
  const std::string m = input_error(replace("id = 1", "id = -1"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'ball[1].id'", "[0, 9223372036854775807]", "got -1"}));
}

TEST(ScenarioRange, TimestepNotAuto) {
  const std::string m = input_error(replace("timestep = 1e-6", "timestep = \"fast\""));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'simulation.timestep'", "\"auto\"", "got \"fast\""}));
}

// ---------------------------------------------------------------------------------------------------
// References and consistency

TEST(ScenarioReference, MaterialThatDoesNotExist) {
  const std::string m =
      input_error(replace("material = \"granite\"\ngroups = [\"top\"]", "material = \"basalt\"\ngroups = [\"top\"]"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'ball[2].material'", "no [[material]] named \"basalt\"", "defined: granite"}));
}

TEST(ScenarioReference, DuplicateBallIds) {
  const std::string m = input_error(replace("id = 2", "id = 1"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'ball[2].id'", "ball id 1 is used twice"}));
}

TEST(ScenarioReference, HillModelOnABallWallRule) {
  const std::string m = input_error(replace("model = \"linear\"\nemod = 29e6", "model = \"hill\""));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'contact_model[2].model'", "ball-ball", "ball-wall"}));
}

TEST(ScenarioReference, UnknownStageType) {
  const std::string m = input_error(replace("type = \"cycle\"", "type = \"wait\""));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'stage[1].type'", "\"cycle\"", "\"solve\"", "\"probe\"", "got \"wait\""}));
}

TEST(ScenarioReference, UnknownQuantityInAHistory) {
  const std::string m = input_error(replace("quantity = \"ball.pos_z\"", "quantity = \"ball.temperature\""));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'history[1].quantity'", "unknown quantity \"ball.temperature\"", "ball.pos_z [m]"}));
}

TEST(ScenarioReference, UnknownQuantityInAProbe) {
  const std::string m =
      input_error(replace("quantity = \"contact.normal_force\"", "quantity = \"contact.pressure\""));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'stage[2].quantity'", "unknown quantity \"contact.pressure\"",
                           "contact.normal_force [N]"}));
}

TEST(ScenarioReference, ProbeRatioToALaterLabel) {
  const std::string m = input_error(replace("balls = [1, 2]\n", "balls = [1, 2]\nratio_to = \"G\"\n") +
                                    "\n[[stage]]\ntype = \"probe\"\nlabel = \"G\"\nquantity = \"sim.time\"\n");
  EXPECT_TRUE(Mentions(m, {kFile, "key 'stage[2].ratio_to'", "earlier probe label", "got \"G\""}));
}

TEST(ScenarioReference, ProbeRatioToItself) {
  const std::string m = input_error(replace("balls = [1, 2]\n", "balls = [1, 2]\nratio_to = \"F\"\n"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'stage[2].ratio_to'", "got \"F\""}));
}

TEST(ScenarioReference, ProbeOfABallThatDoesNotExist) {
  const std::string m = input_error(replace("balls = [1, 2]", "balls = [1, 7]"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'stage[2].balls'", "no ball or pebble with id 7"}));
}

TEST(ScenarioReference, RuleGroupThatDoesNotExist) {
  const std::string m = input_error(replace("between = \"ball-ball\"", "between = \"ball-ball\"\ngroups = [\"middle\"]"));
  EXPECT_TRUE(Mentions(m, {kFile, "key 'contact_model[1].groups'", "\"middle\""}));
}

// ---------------------------------------------------------------------------------------------------
// TOML syntax

TEST(ScenarioSyntax, ErrorNamesFileLineAndColumn) {
  const std::string text = replace("name = \"settle\"", "name = \"settle");
  const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(text.find("\"settle")), '\n');
  const std::string m = input_error(text, "broken.toml");
  EXPECT_TRUE(Mentions(m, {"broken.toml", "TOML syntax error", "at line " + std::to_string(line) + ", column "}));
}

TEST(ScenarioSyntax, TruncatedFile) {
  const std::string m = input_error(kBase.substr(0, kBase.find("9.99e-3]")), "half.toml");
  EXPECT_TRUE(Mentions(m, {"half.toml", "TOML syntax error", "line ", "column "}));
}

TEST(ScenarioSyntax, MissingFile) {
  const std::string path = std::string(HILLDEM_SOURCE_DIR) + "/tests/data/no_such_scenario.toml";
  try {
    hilldem::load_scenario_file(path);
    ADD_FAILURE() << "a missing file loaded";
  } catch (const InputError& e) {
    EXPECT_TRUE(Mentions(e.what(), {path, "cannot open"}));
  }
}

// ---------------------------------------------------------------------------------------------------
// Assignment table: the first rule whose kind and groups match, and contact_listing names it.

const std::string kGroups = R"(
[[material]]
name = "granite"
density = 2650
young_mod = 29e9
pois_ratio = 0.15

[[ball]]
id = 1
position = [0.0, 0.0, 0.0]
radius = 5e-3
material = "granite"
groups = ["bottom"]

[[ball]]
id = 2
position = [0.0, 0.0, 9.99e-3]
radius = 5e-3
material = "granite"
groups = ["top"]

[[ball]]
id = 3
position = [9.99e-3, 0.0, 9.99e-3]
radius = 5e-3
material = "granite"
groups = ["top"]

[[contact_model]]
name = "top-top"
between = "ball-ball"
groups = ["top", "top"]
model = "hill"
fric_coef = 0.3

[[contact_model]]
name = "bottom-top"
between = "ball-ball"
groups = ["bottom", "top"]
model = "linear"
emod = 1e8

[[contact_model]]
name = "anything"
between = "ball-ball"
model = "linear"
emod = 2e8
)";

TEST(ScenarioAssignment, FirstMatchingRuleByGroup) {
  Scenario sc = load_scenario(kGroups, "groups.toml");
  const auto& table = sc.sim.table;
  ASSERT_EQ(table.rules.size(), 3u);
  const std::uint64_t top = sc.sim.groups.find("top"), bottom = sc.sim.groups.find("bottom");
  ASSERT_NE(top, 0u);
  ASSERT_NE(bottom, 0u);
  using hilldem::ContactKind;
  EXPECT_EQ(table.match(ContactKind::BallBall, top, top), 0);
  EXPECT_EQ(table.match(ContactKind::BallBall, bottom, top), 1);
  EXPECT_EQ(table.match(ContactKind::BallBall, top, bottom), 1);  // either way round
  EXPECT_EQ(table.match(ContactKind::BallBall, bottom, bottom), 2);
  EXPECT_EQ(table.match(ContactKind::BallBall, 0, 0), 2);
  EXPECT_EQ(table.match(ContactKind::BallWall, top, 0), -1);  // no ball-wall rule

  sc.sim.update_forces();
  const long c12 = sc.sim.find_ball_ball(1, 2), c23 = sc.sim.find_ball_ball(2, 3);
  ASSERT_GE(c12, 0);
  ASSERT_GE(c23, 0);
  EXPECT_LT(sc.sim.find_ball_ball(1, 3), 0);  // too far apart
  EXPECT_EQ(sc.sim.contacts.rule[c12], 1);
  EXPECT_EQ(sc.sim.contacts.model[c12], hilldem::ModelKind::Linear);
  EXPECT_DOUBLE_EQ(sc.sim.contacts.linear_params[c12].emod, 1e8);
  EXPECT_EQ(sc.sim.contacts.rule[c23], 0);
  EXPECT_EQ(sc.sim.contacts.model[c23], hilldem::ModelKind::Hill);

  const std::string listing = hilldem::contact_listing(sc.sim);
  std::istringstream lines(listing);
  std::string line, l12, l23;
  while (std::getline(lines, line)) {
    if (line.find("ball 1 - ball 2") != std::string::npos) l12 = line;
    if (line.find("ball 2 - ball 3") != std::string::npos) l23 = line;
  }
  EXPECT_TRUE(Mentions(l12, {"linear", "rule 2 'bottom-top'", "bottom / top"})) << listing;
  EXPECT_TRUE(Mentions(l23, {"hill", "rule 1 'top-top'", "top / top"})) << listing;
  EXPECT_TRUE(Mentions(listing, {"2 contacts"}));
}

TEST(ScenarioAssignment, RuleOrderDecides) {
  // The catch-all rule first takes every ball-ball contact.
  const std::string first = R"(
[[contact_model]]
name = "anything"
between = "ball-ball"
model = "linear"
emod = 2e8
)";
  std::string text = kGroups;
  text.insert(text.find("[[contact_model]]"), first);
  Scenario sc = load_scenario(text, "groups.toml");
  sc.sim.update_forces();
  const long c12 = sc.sim.find_ball_ball(1, 2);
  ASSERT_GE(c12, 0);
  EXPECT_EQ(sc.sim.contacts.rule[c12], 0);
  EXPECT_TRUE(Mentions(hilldem::contact_listing(sc.sim), {"rule 1 'anything'"}));
}


// ---- the reader's plain data (read_scenario) and the builder (build_scenario, build_simulation) ----

TEST(ScenarioDescription, ReaderFillsPlainData) {
  const hilldem::ScenarioDescription d = hilldem::read_scenario(kBase, kFile);
  EXPECT_EQ(d.file, kFile);
  EXPECT_EQ(d.text, kBase);
  EXPECT_EQ(d.title, "base");
  ASSERT_EQ(d.sim.balls.size(), 2u);
  EXPECT_EQ(d.sim.balls[0].id, 1);
  EXPECT_EQ(d.sim.balls[0].fixity, hilldem::kFixAll);
  EXPECT_DOUBLE_EQ(d.sim.balls[0].density, 2650.0);
  EXPECT_DOUBLE_EQ(d.sim.balls[0].young_mod, 29e9);
  EXPECT_EQ(d.sim.balls[1].id, 2);
  EXPECT_DOUBLE_EQ(d.sim.balls[1].position.z, 9.99e-3);
  EXPECT_EQ(d.sim.balls[1].groups, d.sim.groups.find("top"));
  ASSERT_EQ(d.sim.walls.size(), 1u);
  EXPECT_EQ(d.sim.walls[0].name, "floor");
  ASSERT_EQ(d.sim.rules.size(), 2u);
  EXPECT_EQ(d.sim.rules[0].model, hilldem::ModelKind::Hill);
  EXPECT_DOUBLE_EQ(d.sim.rules[1].linear.emod, 29e6);
  EXPECT_FALSE(d.sim.settings.auto_timestep);
  EXPECT_DOUBLE_EQ(d.sim.settings.gravity.z, -9.81);
  EXPECT_EQ(d.sim.find_ball(2), 1);
  EXPECT_EQ(d.sim.find_ball(3), -1);
  EXPECT_EQ(d.sim.walls_named("floor"), std::vector<std::size_t>{0});
  EXPECT_TRUE(d.sim.walls_named("roof").empty());
  ASSERT_EQ(d.stages.size(), 2u);
  EXPECT_EQ(d.histories.size(), 1u);
}

TEST(ScenarioDescription, BuildGivesWhatLoadGives) {
  // load_scenario is read_scenario then build_scenario: the same state, bit for bit, before and
  // after cycling, for the base scenario and every example.
  std::vector<std::pair<std::string, std::string>> cases{{kFile, kBase}};
  const std::filesystem::path dir = std::filesystem::path(HILLDEM_SOURCE_DIR) / "examples";
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".toml") {
      std::ifstream in(e.path());
      std::stringstream text;
      text << in.rdbuf();
      cases.emplace_back(e.path().string(), text.str());
    }
  for (const auto& [file, text] : cases) {
    SCOPED_TRACE(file);
    Scenario loaded = load_scenario(text, file);
    Scenario built = hilldem::build_scenario(hilldem::read_scenario(text, file));
    EXPECT_EQ(hilldem::state_difference(loaded.sim, built.sim), "");
    EXPECT_EQ(built.sim.groups.describe(~std::uint64_t{0}), loaded.sim.groups.describe(~std::uint64_t{0}));
    ASSERT_EQ(built.sim.table.rules.size(), loaded.sim.table.rules.size());
    EXPECT_EQ(built.stages.size(), loaded.stages.size());
    EXPECT_EQ(built.histories.size(), loaded.histories.size());
    EXPECT_EQ(built.servos.size(), loaded.servos.size());
    EXPECT_EQ(built.text, text);
    if (loaded.sim.balls.size() > 2000) continue;  // the cycles below only for the small ones
    loaded.sim.cycle(3);
    built.sim.cycle(3);
    EXPECT_EQ(hilldem::state_digest(built.sim), hilldem::state_digest(loaded.sim));
  }
}

TEST(ScenarioDescription, BuildSimulationFromDataWrittenInCode) {
  // No TOML: two touching balls on a floor, one rule for each kind of contact.
  hilldem::SimulationDescription d;
  d.settings.gravity = {0.0, 0.0, -9.81};
  d.settings.auto_timestep = false;
  d.settings.timestep = 1e-6;
  const std::uint64_t grains = d.groups.bit("grains");
  for (int k = 0; k < 2; ++k) {
    hilldem::BallInit b;
    b.id = 10 + k;
    b.position = {0.0, 0.0, 1.99e-2 * k};
    b.radius = 1e-2;
    b.density = 2650.0;
    b.groups = grains;
    d.balls.push_back(b);
  }
  hilldem::Wall floor;
  floor.name = "floor";
  floor.point = {0.0, 0.0, -0.99e-2};
  d.walls.push_back(floor);
  hilldem::ModelRule bb;
  bb.name = "grains";
  bb.linear.emod = 1e8;
  bb.groups1 = grains;
  hilldem::ModelRule bw = bb;
  bw.name = "floor";
  bw.kind = hilldem::ContactKind::BallWall;
  d.rules = {bb, bw};

  hilldem::Simulation sim = hilldem::build_simulation(d);
  ASSERT_EQ(sim.balls.size(), 2u);
  EXPECT_EQ(sim.balls.find(11), 1);
  EXPECT_NEAR(sim.balls.mass[0], 4.0 / 3.0 * 3.141592653589793 * 1e-6 * 2650.0, 1e-15);
  EXPECT_EQ(sim.walls.find("floor"), 0);
  EXPECT_EQ(sim.groups.find("grains"), grains);
  ASSERT_EQ(sim.table.rules.size(), 2u);
  EXPECT_EQ(sim.time, 0.0);
  sim.update_forces();
  const long c = sim.find_ball_ball(10, 11);
  ASSERT_GE(c, 0);
  EXPECT_EQ(sim.contacts.rule[c], 0);
  EXPECT_GE(sim.find_ball_wall(10, 0), 0);
  sim.cycle(2);
  EXPECT_EQ(sim.steps, 2);
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Magnitudes that would make a run meaningless are refused when the file is read (issue 34 item 7):
// at run time they surfaced as a "non-finite position" blow-up (exit status 1) or a cell-grid error
// without file or key.

namespace {

TEST(ScenarioRanges, PositionBeyondAMillionMetresIsRefusedWithKeyAndRange) {
  const std::string m = input_error(replace("position = [0.0, 0.0, 9.99e-3]", "position = [1e300, 0.0, 9.99e-3]"));
  EXPECT_TRUE(Mentions(m, {kFile, "ball[2].position", "[-1e+06, 1e+06]", "[m]", "1e+300"}));
  // The bound itself is allowed.
  EXPECT_NO_THROW(load_scenario(replace("position = [0.0, 0.0, 9.99e-3]", "position = [1e6, 0.0, 9.99e-3]"), kFile));
}

TEST(ScenarioRanges, RadiusDensityAndGravityOutsideTheirRangesAreRefused) {
  EXPECT_TRUE(Mentions(input_error(replace("radius = 5e-3", "radius = 1e-300")), {"ball[1].radius", "[1e-09, 1000]", "[m]"}));
  EXPECT_TRUE(Mentions(input_error(replace("density = 2650", "density = 1e-300")),
                       {"material[1].density", "[0.001, 1e+06]", "[kg/m^3]", "1e-300"}));
  EXPECT_TRUE(Mentions(input_error(replace("gravity = [0.0, 0.0, -9.81]", "gravity = [0.0, 0.0, -1e300]")),
                       {"simulation.gravity", "[-10000, 10000]", "[m/s^2]"}));
  EXPECT_TRUE(Mentions(input_error(replace("point = [0.0, 0.0, -5e-3]", "point = [0.0, 0.0, -5e7]")), {"wall[1].point", "[m]"}));
}

TEST(ScenarioRanges, BallGridReachingPastTheBoundIsRefused) {
  const std::string grid = R"([[ball_grid]]
first_id = 100
origin = [0.0, 0.0, 0.1]
counts = [10, 1, 1]
spacing = 2e5
radius = 5e-3
material = "granite"

[[wall]])";
  EXPECT_TRUE(Mentions(input_error(replace("[[wall]]", grid)), {"ball_grid[1].spacing", "far corner", "[-1e+06, 1e+06]"}));
}

TEST(ScenarioRanges, PeriodicBoxTooSmallForTheCellGridIsRefusedNamingTheKey) {
  // 2 R_max + skin = 10 mm + 1 mm: a period must be at least 33 mm.
  const std::string box = "[simulation]\nperiodic = [\"x\"]\nbox_min = [-0.015, -1, -1]\nbox_max = [0.015, 1, 1]\n";
  const std::string m = input_error(replace("[simulation]\n", box));
  EXPECT_TRUE(Mentions(m, {kFile, "simulation.box_max", "0.03 m long in x", "3 interaction lengths", "0.033 m"}));
  EXPECT_NO_THROW(load_scenario(replace("[simulation]\n", "[simulation]\nperiodic = [\"x\"]\nbox_min = [-0.017, -1, -1]\nbox_max = [0.017, 1, 1]\n"), kFile));
}

TEST(ScenarioRanges, HistoryFileDotDotIsRefused) {
  for (const char* name : {"..", ".", ".hilldem.lock"}) {
    const std::string m = input_error(replace("[[history]]", std::string("[output]\nhistory_file = \"") + name + "\"\n\n[[history]]"));
    EXPECT_TRUE(Mentions(m, {kFile, "output.history_file", "plain file name"})) << name;
  }
}

}  // namespace
