// The checkpoint container (io/checkpoint.hpp) and the engine-state sections (io/state_io.hpp):
// round trips, and every way a file can be damaged gives an InputError that names the file, never a
// crash or another exception.
#include <gtest/gtest.h>

#include <vector>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "hilldem/core/error.hpp"
#include "hilldem/io/checkpoint.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/state_io.hpp"

namespace {

namespace fs = std::filesystem;
using namespace hilldem;

// A small but complete state: the 27-grain assembly after 50 cycles (hill and linear contacts, facets).
Simulation assembly_state() {
  Scenario sc = load_scenario_file(std::string(HILLDEM_SOURCE_DIR) + "/examples/assembly_27.toml");
  sc.sim.update_forces();
  sc.sim.cycle(50);
  return std::move(sc.sim);
}

std::string checkpoint_bytes(const Simulation& sim) {
  CheckpointWriter w;
  write_simulation(w, sim);
  w.section("test.extra").str("a driver's own section");
  return w.bytes();
}

// The InputError message of f(), or "" if it did not throw one. Any other exception fails the test.
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return "other";
  } catch (...) {
    ADD_FAILURE() << "expected InputError, got a non-standard exception";
    return "other";
  }
  return "";
}

TEST(Crc32, MatchesTheStandardCheckValue) {
  const std::string s = "123456789";
  EXPECT_EQ(crc32(s.data(), s.size()), 0xCBF43926u);
  EXPECT_EQ(crc32(s.data() + 4, 5, crc32(s.data(), 4)), 0xCBF43926u);  // incremental
}

// The table-driven CRC (8 bytes a step) against the bit-by-bit definition, at every length and
// alignment up to 100 bytes and split anywhere.
TEST(Crc32, EqualsTheBitwiseDefinitionAtAnyLengthAndSplit) {
  auto bitwise = [](const unsigned char* p, std::size_t n) {
    std::uint32_t c = 0xFFFFFFFFu;
    for (std::size_t i = 0; i < n; ++i) {
      c ^= p[i];
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    }
    return ~c;
  };
  std::vector<unsigned char> data(128);
  std::uint32_t x = 12345;
  for (unsigned char& b : data) b = static_cast<unsigned char>((x = x * 1103515245u + 12345u) >> 24);
  for (std::size_t start = 0; start < 8; ++start)
    for (std::size_t n = 0; n + start <= 100; ++n) {
      const unsigned char* p = data.data() + start;
      ASSERT_EQ(crc32(p, n), bitwise(p, n)) << "start " << start << ", length " << n;
      const std::size_t cut = n / 3;
      ASSERT_EQ(crc32(p + cut, n - cut, crc32(p, cut)), bitwise(p, n));
    }
}

TEST(Checkpoint, SectionsRoundTrip) {
  CheckpointWriter w;
  SectionWriter& a = w.section("alpha", 3);
  a.u8(7);
  a.u32(0xDEADBEEF);
  a.i64(-42);
  a.f64(-0.0);
  a.boolean(true);
  a.vec3({1.5, -2.5, 1e300});
  a.str("text with \0 inside");
  a.column(std::vector<double>{1.0, 2.0, 3.0});
  w.section("beta").str("");
  const CheckpointReader r = CheckpointReader::from_bytes(w.bytes(), "mem");
  EXPECT_EQ(r.names(), (std::vector<std::string>{"alpha", "beta"}));
  EXPECT_TRUE(r.has("beta"));
  EXPECT_FALSE(r.has("gamma"));
  SectionReader s = r.section("alpha", 3);
  EXPECT_EQ(s.version(), 3u);
  EXPECT_EQ(s.u8(), 7);
  EXPECT_EQ(s.u32(), 0xDEADBEEFu);
  EXPECT_EQ(s.i64(), -42);
  const double z = s.f64();
  EXPECT_TRUE(z == 0.0 && std::signbit(z));
  EXPECT_TRUE(s.boolean());
  EXPECT_EQ(s.vec3(), (Vec3{1.5, -2.5, 1e300}));
  EXPECT_EQ(s.str(), std::string("text with "));
  std::vector<double> col;
  s.column(col, "col");
  EXPECT_EQ(col, (std::vector<double>{1.0, 2.0, 3.0}));
  s.finish();
  EXPECT_NE(input_error([&] { r.section("alpha", 2); }).find("version 3"), std::string::npos);
  EXPECT_NE(input_error([&] { r.section("gamma"); }).find("no section 'gamma'"), std::string::npos);
  SectionReader b = r.section("beta");
  EXPECT_EQ(b.str(), "");
  EXPECT_NE(input_error([&] { b.u8(); }).find("truncated"), std::string::npos);
}

TEST(Checkpoint, ReadsAreBoundsCheckedAndCountsCannotAllocateHugely) {
  CheckpointWriter w;
  SectionWriter& s = w.section("s");
  s.u64(UINT64_MAX);  // a corrupt count
  s.u8(2);            // a corrupt boolean
  const CheckpointReader r = CheckpointReader::from_bytes(w.bytes(), "mem");
  SectionReader a = r.section("s");
  EXPECT_NE(input_error([&] { a.count(8); }).find("does not fit"), std::string::npos);
  SectionReader b = r.section("s");
  EXPECT_NE(input_error([&] { b.str(); }).find("truncated"), std::string::npos);
  SectionReader c = r.section("s");
  std::vector<Vec3> v;
  EXPECT_NE(input_error([&] { c.column(v, "v"); }).find("column 'v'"), std::string::npos);
  SectionReader d = r.section("s");
  d.u64();
  EXPECT_NE(input_error([&] { d.boolean(); }).find("boolean"), std::string::npos);
  SectionReader e = r.section("s");
  e.u64();
  EXPECT_NE(input_error([&] { e.finish(); }).find("unexpected bytes"), std::string::npos);
}

TEST(Checkpoint, WriterRefusesDuplicateSectionNames) {
  CheckpointWriter w;
  w.section("x");
  EXPECT_THROW(w.section("x"), RunError);
  EXPECT_THROW(w.section(""), RunError);
}

TEST(Checkpoint, EngineStateRoundTripsBitwise) {
  const Simulation sim = assembly_state();
  const CheckpointReader r = CheckpointReader::from_bytes(checkpoint_bytes(sim), "mem");
  Simulation back;
  read_simulation(r, back, true);
  EXPECT_EQ(state_difference(sim, back), "");
  // Only the contacts and the wall rows are saved; the restore makes the other neighbour rows again,
  // row for row those of the last rebuild (and cycling on is still bitwise, below).
  std::size_t saved = 0;
  for (std::size_t c = 0; c < sim.contacts.size(); ++c)
    saved += sim.contacts.exists[c] || sim.contacts.key[c].kind == ContactKind::BallWall;
  ASSERT_LT(saved, sim.contacts.size());
  Simulation as_saved;
  read_simulation(r, as_saved, false);
  EXPECT_EQ(as_saved.contacts.size(), saved);
  ASSERT_EQ(back.contacts.size(), sim.contacts.size());
  for (std::size_t c = 0; c < sim.contacts.size(); ++c) EXPECT_TRUE(back.contacts.key[c] == sim.contacts.key[c]) << c;
  // Cycling on from the restored state is cycling on from the original.
  Simulation original = sim;
  original.cycle(200);
  back.cycle(200);
  EXPECT_EQ(state_difference(original, back), "");
  // Restored into a simulation that has run on: it moves with the restored contact forces, not with
  // the sums its own last force pass left.
  Simulation used = sim;
  used.cycle(100);
  read_simulation(r, used, true);
  used.cycle(200);
  EXPECT_EQ(state_difference(original, used), "");
  // A driver's section rides along and is skipped by read_simulation.
  EXPECT_EQ(r.section("test.extra").str(), "a driver's own section");
}

TEST(Checkpoint, PeriodicBoxSavesOnlyContactsAndWallRowsAndRestoresTheSameList) {
  // Grains thrown across the boundaries of a box periodic in x and y: positions are wrapped into the
  // box at every rebuild, so the restore must not rebuild (x - L rounds differently from x). It makes
  // the last rebuild's rows again from its positions, and the next rebuild comes at the same step.
  Scenario sc = load_scenario_file(std::string(HILLDEM_SOURCE_DIR) + "/tests/data/restart/periodic_bed.toml");
  Simulation& sim = sc.sim;
  sim.update_forces();
  sim.cycle(1337);  // (some grains have crossed a boundary: checked below)
  ASSERT_GT(sim.rebuilds(), 3);
  bool crossed = false;
  for (const Vec3& x : sim.balls.position) crossed |= x.x < 2.2e-3 - 1e-4;
  ASSERT_TRUE(crossed);
  const CheckpointReader r = CheckpointReader::from_bytes(checkpoint_bytes(sim), "mem");
  std::size_t contacts = 0, wall_rows = 0;
  for (std::size_t c = 0; c < sim.contacts.size(); ++c) {
    contacts += sim.contacts.exists[c] != 0;
    wall_rows += sim.contacts.key[c].kind == ContactKind::BallWall && !sim.contacts.exists[c];
  }
  Simulation as_saved;
  read_simulation(r, as_saved, false);
  ASSERT_LT(contacts + wall_rows, sim.contacts.size());  // some ball-ball rows are not contacts
  EXPECT_EQ(as_saved.contacts.size(), contacts + wall_rows);
  Simulation back;
  read_simulation(r, back, true);
  ASSERT_EQ(back.contacts.size(), sim.contacts.size());
  for (std::size_t c = 0; c < sim.contacts.size(); ++c) {
    EXPECT_TRUE(back.contacts.key[c] == sim.contacts.key[c]) << c;
    EXPECT_EQ(back.contacts.image[c], sim.contacts.image[c]) << c;
    EXPECT_EQ(back.contacts.rule[c], sim.contacts.rule[c]) << c;
  }
  EXPECT_EQ(state_difference(sim, back), "");
  Simulation original = sim;
  original.cycle(1500);
  back.cycle(1500);
  EXPECT_GT(original.rebuilds(), sim.rebuilds());
  EXPECT_EQ(back.rebuilds(), original.rebuilds());
  EXPECT_EQ(state_difference(original, back), "");
  EXPECT_EQ(state_digest(original), state_digest(back));
}

TEST(Checkpoint, EveryTruncationIsRefusedWithAMessage) {
  const std::string bytes = checkpoint_bytes(assembly_state());
  ASSERT_GT(bytes.size(), 1000u);
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    const std::string m = input_error([&] { CheckpointReader::from_bytes(bytes.substr(0, n), "cut.hdc"); });
    ASSERT_EQ(m.rfind("cut.hdc: ", 0), 0u) << "length " << n << ": " << m;
  }
}

TEST(Checkpoint, EverySingleBitFlipIsRefused) {
  // Every byte of the header and trailer, and every 5th byte elsewhere (a different bit each time).
  const std::string bytes = checkpoint_bytes(assembly_state());
  for (std::size_t i = 0; i < bytes.size(); i += (i < 64 || i + 64 > bytes.size()) ? 1 : 5) {
    std::string bad = bytes;
    bad[i] = static_cast<char>(bad[i] ^ (1 << (i % 8)));
    const std::string m = input_error([&] {
      const CheckpointReader r = CheckpointReader::from_bytes(bad, "flip.hdc");
      Simulation sim;
      read_simulation(r, sim, false);
    });
    ASSERT_EQ(m.rfind("flip.hdc: ", 0), 0u) << "byte " << i << " flipped was accepted: " << m;
  }
}

TEST(Checkpoint, TrailingDataAndForeignFilesAreRefused) {
  const std::string bytes = checkpoint_bytes(assembly_state());
  EXPECT_NE(input_error([&] { CheckpointReader::from_bytes(bytes + "x", "f"); }).find("trailing data"), std::string::npos);
  EXPECT_NE(input_error([&] { CheckpointReader::from_bytes("", "f"); }).find("empty file"), std::string::npos);
  EXPECT_NE(input_error([&] { CheckpointReader::from_bytes("title = \"a scenario\"\n", "f"); }).find("not a hilldem checkpoint"),
            std::string::npos);
  EXPECT_NE(input_error([&] { CheckpointReader::from_file("/no/such/file.hdc"); }).find("cannot open"), std::string::npos);
  EXPECT_NE(input_error([&] { CheckpointReader::from_file(HILLDEM_SOURCE_DIR); }).find("is a folder"), std::string::npos);
}

// Contents that pass every checksum but are invalid are refused by the validation in read_simulation.
TEST(Checkpoint, InvalidContentsWithValidChecksumsAreRefused) {
  // Contacts only, so that every row mutated below is one that is saved.
  Simulation good = assembly_state();
  ContactStore rows;
  for (std::size_t c = 0; c < good.contacts.size(); ++c)
    if (good.contacts.exists[c]) rows.append_row(good.contacts, c);
  good.contacts = rows;
  ASSERT_GT(good.contacts.size(), 2u);
  auto refused = [&](const char* what, auto&& mutate, const std::string& expect) {
    Simulation sim = good;
    mutate(sim);
    const std::string m = input_error([&] {
      Simulation back;
      read_simulation(CheckpointReader::from_bytes(checkpoint_bytes(sim), "bad.hdc"), back, true);
    });
    EXPECT_NE(m.find(expect), std::string::npos) << what << ": " << m;
  };
  refused("ball index", [](Simulation& s) { s.contacts.key[0].a = 1000; }, "refers to ball index");
  refused("unsorted", [](Simulation& s) { std::swap(s.contacts.key[0], s.contacts.key[1]); }, "not strictly sorted");
  refused("rule", [](Simulation& s) { s.contacts.rule[0] = 99; }, "assignment rule");
  refused("model", [](Simulation& s) { s.contacts.model[0] = static_cast<ModelKind>(7); }, "unknown model");
  refused("moisture", [](Simulation& s) { s.contacts.moisture[0] = static_cast<Moisture>(9); }, "moisture state");
  refused("flag", [](Simulation& s) { s.contacts.exists[0] = 2; }, "neither 0 nor 1");
  refused("image", [](Simulation& s) { s.contacts.image[0] = 200; }, "image code");
  refused("column length", [](Simulation& s) { s.contacts.gap.pop_back(); }, "rows");
  refused("position", [](Simulation& s) { s.balls.position[3].x = NAN; }, "non-finite 'position'");
  refused("radius", [](Simulation& s) { s.balls.radius[3] = -1.0; }, "radius");
  refused("duplicate id", [](Simulation& s) { s.balls.id[3] = s.balls.id[4]; }, "appears twice");
  refused("fixity", [](Simulation& s) { s.balls.fixity[3] = 0xFF; }, "fixity");
  refused("groups", [](Simulation& s) { s.balls.groups[3] = std::uint64_t{1} << 40; }, "group that is not defined");
  refused("wall shape", [](Simulation& s) { s.walls.walls[0].shape = static_cast<WallShape>(5); }, "shape code");
  refused("wall axis", [](Simulation& s) { s.walls.walls[0].axis = 3; }, "axis");
  refused("wall name", [](Simulation& s) { s.walls.walls[1].name = s.walls.walls[0].name; }, "used twice");
  refused("damping", [](Simulation& s) { s.settings.local_damping = 1.0; }, "local_damping");
  refused("clock", [](Simulation& s) { s.steps = -1; }, "out of range");
  refused("ball force", [](Simulation& s) { s.balls.contact_force[2].y = NAN; }, "non-finite 'contact_force'");
  refused("ball velocity", [](Simulation& s) { s.balls.velocity[2].z = INFINITY; }, "non-finite 'velocity'");
  refused("contact force", [](Simulation& s) {
    for (std::size_t c = 0; c < s.contacts.size(); ++c)
      if (s.contacts.exists[c]) s.contacts.force[c].x = NAN;
  }, "non-finite 'force'");
  refused("wall velocity", [](Simulation& s) { s.walls.walls[3].velocity.x = NAN; }, "non-finite position, velocity or force");
}

TEST(Checkpoint, WritesAreAtomic) {
  const fs::path dir = fs::temp_directory_path() / ("hilldem_ckpt_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / "a.hdc").string();
  CheckpointWriter w1;
  w1.section("n").u64(1);
  w1.write_file(path);
  CheckpointWriter w2;
  w2.section("n").u64(2);
  w2.write_file(path);
  EXPECT_EQ(CheckpointReader::from_file(path).section("n").u64(), 2u);
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1) << "a temporary file was left behind";
  EXPECT_THROW(w1.write_file((dir / "no" / "such" / "dir.hdc").string()), RunError);
  fs::remove_all(dir);
}

}  // namespace
