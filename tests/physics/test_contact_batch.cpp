// The batched hill and linear laws (engine/contact_batch.hpp) against the row-by-row laws (force_row):
// the same contacts, forces and motion to rounding, dry and wet, with creation, deletion and rupture.
#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include "sim_builders.hpp"

namespace hilldem {
namespace {

using namespace hilldem::testing;

struct Outcome {
  std::vector<Vec3> position, spin;
  std::size_t contacts = 0, wet = 0, ruptured = 0;
  std::int64_t batched = 0;
};

Outcome outcome(const Simulation& sim) {
  Outcome o{sim.balls.position, sim.balls.spin, sim.contact_count(), 0, 0, sim.batched_rows()};
  for (std::size_t c = 0; c < sim.contacts.size(); ++c)
    if (sim.contacts.exists[c]) {
      o.wet += sim.contacts.moisture[c] == Moisture::Wet;
      o.ruptured += sim.contacts.moisture[c] == Moisture::Ruptured;
    }
  return o;
}

// Largest distance [m] between the positions of two runs.
double worst_position_gap(const Outcome& x, const Outcome& y) {
  double worst = 0.0;
  for (std::size_t i = 0; i < x.position.size(); ++i) worst = std::max(worst, norm(x.position[i] - y.position[i]));
  return worst;
}

// A box of 600 grains thrown about (0.5 m/s, 50 rad/s), wetted within 0.5 mm (suction 20 kPa), under
// gravity with the automatic time step (Eqs. 19-21 through the batch): contacts form, slip, separate
// and their bridges rupture.
Simulation wet_box(bool batched) {
  Simulation sim = random_box(600, 21);
  sim.use_batched_kernel = batched;
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.auto_timestep = true;
  sim.make_wet(20e3, 0.5e-3);
  return sim;
}

TEST(HillBatch, SameMotionAsTheRowByRowLawWetAndDry) {
  auto run = [](bool batched) {
    Simulation sim = wet_box(batched);
    sim.cycle(300);
    return outcome(sim);
  };
  const Outcome batch = run(true), rows = run(false);
  EXPECT_GT(batch.batched, 100);  // the batch did carry most contacts
  EXPECT_EQ(rows.batched, 0);
  EXPECT_EQ(batch.contacts, rows.contacts);
  EXPECT_EQ(batch.wet, rows.wet);
  EXPECT_EQ(batch.ruptured, rows.ruptured);
  EXPECT_GT(batch.wet, 0u);
  EXPECT_LT(worst_position_gap(batch, rows), 1e-12);  // radii 2-3 mm: rounding only
}

// Properties changed in the middle of a run, then refresh_mappings(): the batched law takes the new
// E and ν from the same moment as the row-by-row law (its per-ball terms are cached between passes).
TEST(HillBatch, PropertiesChangedAndRefreshedMidRun) {
  auto run = [](bool batched) {
    Simulation sim = wet_box(batched);
    sim.cycle(150);
    for (std::size_t i = 0; i < sim.balls.size(); ++i) {
      sim.balls.young_mod[i] *= i % 2 ? 0.25 : 3.0;  // [Pa] much softer and much stiffer grains
      sim.balls.pois_ratio[i] = 0.3;
    }
    sim.refresh_mappings();
    sim.cycle(150);
    return outcome(sim);
  };
  const Outcome batch = run(true), rows = run(false);
  EXPECT_GT(batch.batched, 100);
  EXPECT_EQ(batch.contacts, rows.contacts);
  EXPECT_LT(worst_position_gap(batch, rows), 1e-12);
}

// A periodic box (x, y, z; no walls) of 400 fast wet grains, shifted so that the boundaries cut the
// cloud: contacts across the boundaries (periodic images in the gather) and positions wrapped at
// rebuilds; the same motion either way.
TEST(HillBatch, SameMotionInAPeriodicBox) {
  auto run = [](bool batched) {
    Simulation sim = random_box(400, 8, /*walls=*/false);
    sim.settings.box.periodic[0] = sim.settings.box.periodic[1] = sim.settings.box.periodic[2] = true;
    sim.settings.box.hi = {0.04, 0.04, 0.04};
    for (std::size_t i = 0; i < sim.balls.size(); ++i) {
      sim.balls.velocity[i] *= 10.0;  // [m/s]
      sim.balls.position[i] += Vec3{0.02, 0.013, 0.0};  // [m] the x and y boundaries now cut the cloud
    }
    sim.use_batched_kernel = batched;
    sim.make_wet(20e3, 0.5e-3);  // (its rebuild wraps the positions into the box)
    std::size_t across = 0;
    for (std::size_t c = 0; c < sim.contacts.size(); ++c) across += sim.contacts.exists[c] && sim.contacts.image[c] != kNoImage;
    sim.cycle(400);
    return std::make_tuple(outcome(sim), sim.rebuilds(), across);
  };
  const auto [batch, batch_rebuilds, across] = run(true);
  const auto [rows, rows_rebuilds, rows_across] = run(false);
  EXPECT_GT(across, 20u);  // wet contacts across the boundaries, through the batch with their image
  EXPECT_EQ(across, rows_across);
  EXPECT_GT(batch.batched, 50);
  EXPECT_GT(batch_rebuilds, 2);  // rebuilt (and wrapped) on the way
  EXPECT_EQ(batch_rebuilds, rows_rebuilds);
  EXPECT_EQ(batch.contacts, rows.contacts);
  EXPECT_LT(worst_position_gap(batch, rows), 1e-12);
}

// Two wet grains pulled apart: the bridge holds, then ruptures at 2 s_cr (Eq. 12), at the same step
// either way; the contact is then deleted (inactive beyond proximity).
TEST(HillBatch, RuptureAtTheSameStep) {
  auto run = [](bool batched) {
    Simulation sim = granite_row({0.2e-3});
    sim.use_batched_kernel = batched;
    sim.make_wet(20e3, 0.5e-3);
    sim.balls.velocity[1] = {10.0, 0, 0};  // [m/s] apart: enough to break a 1.6 N bridge
    std::int64_t broke_at = -1;
    for (std::int64_t k = 1; k <= 6000 && broke_at < 0; ++k) {
      sim.cycle(1);
      if (sim.contact_count() == 0) broke_at = k;
    }
    return std::make_pair(broke_at, outcome(sim));
  };
  const auto batch = run(true), rows = run(false);
  ASSERT_GT(batch.first, 0);
  EXPECT_EQ(batch.first, rows.first);
  EXPECT_LT(worst_position_gap(batch.second, rows.second), 1e-15);
}

// The linear law between grains, as in the packing phase of material genesis (E* 100 MPa, κ* 1.5,
// μ 0.3), the grains thrown down onto the floor by a strong gravity (2000 m/s²) with local damping.
Simulation falling_linear_box() {
  Simulation sim = random_box(600, 5);
  ModelRule& grains = sim.table.rules.at(0);
  grains.model = ModelKind::Linear;
  grains.linear = {100e6, 1.5, 0.3};
  sim.settings.gravity = {0, 0, -2000.0};
  sim.settings.local_damping = 0.7;
  sim.settings.timestep = 2e-6;  // [s] half the critical step of the walls
  return sim;
}

// The same motion through the batch as row by row.
TEST(LinearBatch, SameMotionAsTheRowByRowLaw) {
  auto run = [](bool batched) {
    Simulation sim = falling_linear_box();
    sim.use_batched_kernel = batched;
    sim.cycle(4000);
    return outcome(sim);
  };
  const Outcome batch = run(true), rows = run(false);
  EXPECT_GT(batch.batched, 150);
  EXPECT_EQ(rows.batched, 0);
  EXPECT_GT(batch.contacts, 200u);
  EXPECT_EQ(batch.contacts, rows.contacts);
  EXPECT_LT(worst_position_gap(batch, rows), 1e-12) << worst_position_gap(batch, rows);
}

// The block size of the force pass is a tuning knob: blocks of 7, 32, 128 or all 600 balls group the
// contacts into different batches, and the laws pad every batch to whole vectors, so each contact is
// computed by the same vector code whichever lane it lands in. Bit for bit the same motion, hill (wet,
// automatic time step) and linear.
TEST(ContactBatch, ResultsDoNotDependOnTheBlockSize) {
  auto hill = [](std::size_t block) {
    Simulation sim = wet_box(true);
    sim.balls_per_block = block;
    sim.cycle(200);
    return outcome(sim);
  };
  auto linear = [](std::size_t block) {
    Simulation sim = falling_linear_box();
    sim.balls_per_block = block;
    sim.cycle(4000);
    return outcome(sim);
  };
  const Outcome hill_ref = hill(128), linear_ref = linear(128);
  EXPECT_GT(hill_ref.batched, 100);
  EXPECT_GT(linear_ref.batched, 150);
  for (std::size_t block : {7u, 32u, 600u}) {
    const Outcome h = hill(block), l = linear(block);
    EXPECT_EQ(h.position, hill_ref.position) << "hill, blocks of " << block;
    EXPECT_EQ(h.spin, hill_ref.spin) << "hill, blocks of " << block;
    EXPECT_EQ(l.position, linear_ref.position) << "linear, blocks of " << block;
    EXPECT_EQ(l.spin, linear_ref.spin) << "linear, blocks of " << block;
  }
}

}  // namespace
}  // namespace hilldem
