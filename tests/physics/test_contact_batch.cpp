// The batched hill and linear laws (engine/contact_batch.hpp) against the row-by-row laws (force_row,
// which takes every row while each contact's shear displacement is tracked): the same contacts,
// forces and motion to rounding, dry and wet, with creation, deletion and rupture.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <random>
#include <tuple>

#include "hilldem/core/error.hpp"
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
  sim.settings.track_shear_displacement = !batched;  // (every row through force_row)
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

// Contact parameters changed in the middle of a run: μ, γ_h and ψ of every other contact (as a
// set_contacts stage does, then refresh_mappings()), make_wet again with another suction, and the
// rule's μ edited so that contacts created from then on differ from the sets made for it. The
// batched law reads parameter sets (Simulation::refresh_param_sets), not the rows' parameters: it
// follows every change at the same step as the row-by-row law.
TEST(HillBatch, ContactParametersChangedMidRun) {
  auto run = [](bool batched, bool change) {
    Simulation sim = wet_box(batched);
    sim.cycle(100);
    if (change) {
      for (std::size_t c = 0; c < sim.contacts.size(); c += 2)
        if (sim.contacts.exists[c] && sim.contacts.model[c] == ModelKind::Hill)
          sim.contacts.hill_params[c] = HillParams{0.05, 0.5, 80e3};  // μ, γ_h, ψ [Pa]
      sim.refresh_mappings();
    }
    sim.cycle(100);
    if (change) sim.make_wet(5e3, 0.2e-3);
    sim.cycle(100);
    if (change) sim.table.rules.at(0).hill.fric_coef = 0.9;  // new contacts only (create_contact)
    sim.cycle(200);
    return outcome(sim);
  };
  const Outcome batch = run(true, true), rows = run(false, true), same = run(true, false);
  EXPECT_GT(batch.batched, 100);
  EXPECT_EQ(batch.contacts, rows.contacts);
  EXPECT_EQ(batch.wet, rows.wet);
  EXPECT_EQ(batch.ruptured, rows.ruptured);
  EXPECT_LT(worst_position_gap(batch, rows), 1e-12);
  EXPECT_GT(worst_position_gap(batch, same), 1e-9);  // the changes did change the motion
}

// A periodic box (x, y, z; no walls) of 400 fast grains, shifted so that the boundaries cut the
// cloud: contacts across the boundaries (periodic images in the gather) and positions wrapped at
// rebuilds.
Simulation periodic_cloud() {
  Simulation sim = random_box(400, 8, /*walls=*/false);
  sim.settings.box.periodic[0] = sim.settings.box.periodic[1] = sim.settings.box.periodic[2] = true;
  sim.settings.box.hi = {0.04, 0.04, 0.04};
  for (std::size_t i = 0; i < sim.balls.size(); ++i) {
    sim.balls.velocity[i] *= 10.0;                    // [m/s]
    sim.balls.position[i] += Vec3{0.02, 0.013, 0.0};  // [m] the x and y boundaries now cut the cloud
  }
  return sim;
}

// Wet, the same motion with the batched and the row-by-row laws.
TEST(HillBatch, SameMotionInAPeriodicBox) {
  auto run = [](bool batched) {
    Simulation sim = periodic_cloud();
    sim.settings.track_shear_displacement = !batched;  // (every row through force_row)
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

void expect_same_bits(const Outcome& a, const Outcome& b) {
  EXPECT_GT(a.batched, 50);
  EXPECT_EQ(a.contacts, b.contacts);
  ASSERT_EQ(a.position.size(), b.position.size());
  for (std::size_t i = 0; i < a.position.size(); ++i) {
    EXPECT_EQ(a.position[i].x, b.position[i].x) << i;
    EXPECT_EQ(a.position[i].y, b.position[i].y) << i;
    EXPECT_EQ(a.position[i].z, b.position[i].z) << i;
    EXPECT_EQ(a.spin[i].x, b.spin[i].x) << i;
  }
}

// Every step watched (an observer: the live rows through the row columns) or not (through their
// records): the same lanes with the same inputs in the same order, so the same bits, dry and wet.
// The run is cut into cycle() calls of 37 steps
// (the last step of each, looked at, goes through the columns), and make_wet between them reads and
// changes the columns, so the records' history (n̂_c, F^h_s, M) must be back in the columns after
// every call: they are compared bit for bit at the end.
TEST(HillBatch, LiveRecordsOrColumnsGiveTheSameBits) {
  for (const double proximity : {0.0, 1e-3}) {
    auto run = [proximity](bool records) {
      Simulation sim = periodic_cloud();
      sim.settings.proximity = proximity;
      if (!records) sim.observers.push_back([](const Simulation&) {});
      for (int k = 0; k < 8; ++k) sim.cycle(37);
      sim.make_wet(20e3, 0.5e-3);
      for (int k = 0; k < 4; ++k) sim.cycle(37);
      for (std::size_t i = 0; i < sim.balls.size(); ++i)  // kicks [m/s] that pull bridges apart
        sim.balls.velocity[i] += Vec3{4.0 * static_cast<double>(i % 7) - 12.0, 3.0 * static_cast<double>(i % 5) - 6.0, 0};
      for (int k = 0; k < 16; ++k) sim.cycle(37);
      return sim;
    };
    const Simulation on = run(true), off = run(false);
    EXPECT_GT(on.live_record_passes(), 200);
    EXPECT_EQ(off.live_record_passes(), 0);
    const Outcome a = outcome(on), b = outcome(off);
    expect_same_bits(a, b);
    EXPECT_GT(a.wet, 20u);
    EXPECT_EQ(a.wet, b.wet);
    EXPECT_EQ(a.ruptured, b.ruptured);
    ASSERT_EQ(on.contacts.size(), off.contacts.size());
    for (std::size_t c = 0; c < on.contacts.size(); ++c) {
      EXPECT_EQ(on.contacts.exists[c], off.contacts.exists[c]) << c;
      EXPECT_EQ(on.contacts.moisture[c], off.contacts.moisture[c]) << c;
      for (const auto& [x, y] : {std::pair{on.contacts.normal[c], off.contacts.normal[c]},
                                 std::pair{on.contacts.shear_state[c], off.contacts.shear_state[c]}}) {
        EXPECT_EQ(x.x, y.x) << c;
        EXPECT_EQ(x.y, y.y) << c;
        EXPECT_EQ(x.z, y.z) << c;
      }
    }
  }
}

// Two wet grains pulled apart: the bridge holds, then ruptures at 2 s_cr (Eq. 12), at the same step
// either way; the contact is then deleted (inactive beyond proximity).
TEST(HillBatch, RuptureAtTheSameStep) {
  auto run = [](bool batched) {
    Simulation sim = granite_row({0.2e-3});
    sim.settings.track_shear_displacement = !batched;  // (every row through force_row)
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

// A bridge that ruptures inside a cycle() call, on a step nobody looks at, while its contact stays
// (within the proximity), so that the rupture (M = 1) is written into the live record; the grain
// then bounces off a wall and meets the other again. The same step of rupture and the same bits with
// and without the records. (A stale M = 2 would rupture again at once wherever the gap is beyond the
// bridge's reach, so only a bridge that closed again before the records were written back could
// tell; the records are written back whenever the live list is made again, every few µm of travel.)
// Without the records: every step watched by an observer.
TEST(HillBatch, RuptureInALiveRecordReachesTheColumns) {
  auto run = [](bool records) {
    Simulation sim = granite_row({0.2e-3});  // radii 5 mm, centres 10.2 mm apart
    if (!records) sim.observers.push_back([](const Simulation&) {});
    sim.settings.proximity = 20e-3;  // [m] the contact outlives its bridge
    sim.table.rules.push_back(linear_wall_rule(500e6, 0.0));
    Wall w;
    w.name = "stop";
    w.shape = WallShape::Plane;
    w.point = {30e-3, 0, 0};
    w.normal = {-1, 0, 0};
    sim.walls.add(w);
    sim.make_wet(20e3, 0.5e-3);
    sim.balls.velocity[1] = {10.0, 0, 0};  // [m/s] apart, towards the wall
    std::int64_t broke_at = -1;
    for (std::int64_t k = 1; k <= 200; ++k) {
      sim.cycle(25);
      if (broke_at < 0 && sim.contacts.moisture[0] == Moisture::Ruptured) broke_at = k;
    }
    return std::make_tuple(broke_at, outcome(sim), sim.live_record_passes());
  };
  const auto [on_broke, on, on_passes] = run(true);
  const auto [off_broke, off, off_passes] = run(false);
  ASSERT_GT(on_broke, 0);
  EXPECT_EQ(on_broke, off_broke);
  EXPECT_GT(on_passes, 4000);
  EXPECT_EQ(off_passes, 0);
  EXPECT_EQ(on.ruptured, 1u);
  EXPECT_LT(on.position[0].x, -5e-3);  // the grains met again: the returning one knocked the other away
  EXPECT_EQ(on.position[1].x, off.position[1].x);
  EXPECT_EQ(on.position[0].x, off.position[0].x);
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
    sim.settings.track_shear_displacement = !batched;  // (every row through force_row)
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

// Linear ball-ball rows are live rows too: through their records, their flags and history stay in the
// columns (only hill rows keep theirs in the record). The same bits with and without the records
// (every step watched by an observer).
TEST(LinearBatch, LiveRecordsGiveTheSameBits) {
  auto run = [](bool records) {
    Simulation sim = falling_linear_box();
    if (!records) sim.observers.push_back([](const Simulation&) {});
    for (int k = 0; k < 10; ++k) sim.cycle(400);
    return sim;
  };
  const Simulation on = run(true), off = run(false);
  EXPECT_GT(on.live_record_passes(), 3000);
  expect_same_bits(outcome(on), outcome(off));
  EXPECT_GT(outcome(on).contacts, 200u);
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

// Ball-wall rows through the linear batch (Simulation::wall_block) against force_row: a layer of
// 36 grains (apart from each other) on a floor that rises and spins about the vertical, inside a
// cylinder that contracts and turns about its axis, under a tilted facet that comes down and slides
// sideways, every grain with its own velocity and spin. The same motion to rounding, and the same
// wall force sums.
TEST(WallBatch, SameMotionAsTheRowByRowLawWithMovingWalls) {
  const double r = 2.5e-3, pitch = 5.2e-3;  // [m]
  auto run = [&](bool batched) {
    Simulation sim;
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> vel(-0.01, 0.01), spin(-5.0, 5.0);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) {
        const Vec3 x{(i - 2.5) * pitch, (j - 2.5) * pitch, r - 1e-6};  // 1 µm into the floor
        sim.balls.add(granite(6 * i + j + 1, x, r, {vel(rng), vel(rng), vel(rng)}));
        sim.balls.spin.back() = {spin(rng), spin(rng), spin(rng)};
      }
    sim.table.rules.push_back(hill_rule(0.4, 0.07));
    sim.table.rules.push_back(linear_wall_rule(50e3, 0.3));  // soft walls: the grains stay on them
    Wall floor;
    floor.name = "floor";
    floor.velocity = {0, 0, 0.01};  // [m/s]
    floor.spin = {0, 0, 2.0};       // [rad/s] about the origin
    sim.walls.add(floor);
    Wall cylinder;
    cylinder.name = "cylinder";
    cylinder.shape = WallShape::Cylinder;
    cylinder.radius = std::sqrt(2.0) * 2.5 * pitch + r - 1e-6;  // [m] 1 µm into the corner grains
    cylinder.radial_velocity = -0.01;  // [m/s]
    cylinder.spin = {0, 0, -3.0};      // [rad/s]
    sim.walls.add(cylinder);
    Wall roof;
    roof.name = "roof";
    roof.shape = WallShape::Facet;
    // [m] rising 0.2 mm over 30 mm in x and in y, and ≈ 1 µm into the top of the corner grain
    // (-13, -13) mm (the plane's height there is h0 + 0.2 mm × 14/30)
    const double h0 = 2 * r - 2e-6 - 0.2e-3 * 14.0 / 30.0;
    roof.vertex[0] = {-0.02, -0.02, h0};
    roof.vertex[1] = {0.01, -0.02, h0 + 0.2e-3};
    roof.vertex[2] = {-0.02, 0.01, h0 + 0.2e-3};
    roof.velocity = {0.005, 0, -0.01};  // [m/s]
    sim.walls.add(roof);
    sim.settings.track_shear_displacement = !batched;  // (every row through force_row)
    sim.settings.gravity = {0, 0, -9.81};
    sim.settings.auto_timestep = false;
    sim.settings.timestep = 1e-6;  // [s]
    sim.cycle(2000);
    std::vector<std::size_t> wall_contacts(3, 0);
    for (std::size_t c = 0; c < sim.contacts.size(); ++c)
      if (sim.contacts.exists[c] && sim.contacts.key[c].kind == ContactKind::BallWall)
        ++wall_contacts[sim.contacts.key[c].b];
    std::vector<Vec3> wall_force;
    for (const Wall& w : sim.walls.walls) wall_force.push_back(w.force);
    return std::make_tuple(outcome(sim), wall_contacts, wall_force);
  };
  const auto [batch, batch_walls, batch_force] = run(true);
  const auto [rows, rows_walls, rows_force] = run(false);
  EXPECT_EQ(batch_walls, rows_walls);
  EXPECT_EQ(batch_walls[0], 36u);  // every grain still on the floor
  EXPECT_GE(batch_walls[1], 4u);   // the corner grains against the cylinder
  EXPECT_GE(batch_walls[2], 1u);   // under the roof
  EXPECT_GE(batch.batched, 36 + 4 + 1);
  EXPECT_EQ(rows.batched, 0);
  EXPECT_LT(worst_position_gap(batch, rows), 1e-15) << worst_position_gap(batch, rows);
  for (std::size_t w = 0; w < batch_force.size(); ++w) {
    EXPECT_GT(norm(rows_force[w]), 0.0) << "wall " << w;
    EXPECT_LT(norm(batch_force[w] - rows_force[w]), 1e-9 * norm(rows_force[w])) << "wall " << w;
  }
}

// One ball pressed into the corner of a floor and a cylinder (no ball-ball rows): both of its wall
// contacts go through the batch, and give the row-by-row law's forces to rounding.
TEST(WallBatch, WallContactsGoThroughTheBatch) {
  auto run = [](bool batched) {
    Simulation sim;
    sim.balls.add(granite(1, {0.0149, 0, 5e-3 - 1e-6}, 5e-3, {0.01, 0.02, -0.03}));  // 1 µm into the floor
    sim.balls.spin[0] = {3, -2, 5};  // [rad/s]
    sim.table.rules.push_back(linear_wall_rule(500e6, 0.4));
    Wall floor;
    floor.name = "floor";
    sim.walls.add(floor);
    Wall cylinder;
    cylinder.name = "cylinder";
    cylinder.shape = WallShape::Cylinder;
    cylinder.radius = 0.0149 + 5e-3 - 1e-6;  // [m] 1 µm into the cylinder
    sim.walls.add(cylinder);
    sim.settings.track_shear_displacement = !batched;  // (every row through force_row)
    sim.settings.auto_timestep = false;
    sim.settings.timestep = 1e-6;
    sim.cycle(5);
    return std::make_pair(sim.batched_rows(), sim.balls.contact_force[0]);
  };
  const auto [batch_rows, batch_force] = run(true);
  const auto [row_rows, row_force] = run(false);
  EXPECT_EQ(batch_rows, 2);
  EXPECT_EQ(row_rows, 0);
  EXPECT_GT(norm(row_force), 1.0);  // [N] pressed into both walls
  EXPECT_LT(norm(batch_force - row_force), 1e-12 * norm(row_force));
}

// The scatter's rare lanes (Simulation::force_block: not kQuick): a batched contact pulled apart
// beyond the proximity distance is deleted and gives neither ball anything, in the same step as the
// row-by-row law; and a non-finite force stops the run, naming the pair, on either path.
TEST(HillBatch, ContactPulledApartIsDeletedInTheBatch) {
  auto run = [](bool batched) {
    Simulation sim = granite_row({-1e-6});  // 1 µm overlap
    sim.settings.track_shear_displacement = !batched;  // (every row through force_row)
    sim.balls.velocity[1] = {0.6, 0, 0};  // [m/s] away from ball 1: 0.6 µm a step
    int step = 0;
    std::int64_t batched_at_deletion = -1;
    while (step < 50) {
      sim.cycle(1);
      ++step;
      if (sim.contact_count() == 0) {
        batched_at_deletion = sim.batched_rows();
        break;
      }
    }
    return std::make_tuple(step, batched_at_deletion, sim.balls.contact_force[0], sim.balls.contact_moment[1],
                           sim.balls.position[1]);
  };
  const auto [batch_step, batch_rows, batch_force, batch_moment, batch_x] = run(true);
  const auto [row_step, row_rows, row_force, row_moment, row_x] = run(false);
  EXPECT_GT(batch_step, 1);  // the contact lived on for a step or more: deleted from the batch
  EXPECT_LT(batch_step, 50);
  EXPECT_EQ(batch_step, row_step);
  EXPECT_EQ(batch_rows, 1);
  EXPECT_EQ(row_rows, 0);
  EXPECT_EQ(batch_force, Vec3{});
  EXPECT_EQ(batch_moment, Vec3{});
  EXPECT_EQ(row_force, Vec3{});
  EXPECT_LT(norm(batch_x - row_x), 1e-15);
}

TEST(HillBatch, NonFiniteForceStopsTheRunNamingThePair) {
  for (const bool batched : {true, false}) {
    Simulation sim = granite_row({-1e-6});
    sim.settings.track_shear_displacement = !batched;  // (every row through force_row)
    sim.cycle(1);  // the contact exists from here: the next step takes it through the batch
    ASSERT_EQ(sim.contact_count(), 1u);
    sim.balls.spin[1] = {0, 0, std::numeric_limits<double>::infinity()};
    try {
      sim.cycle(1);
      ADD_FAILURE() << "a non-finite contact force went unnoticed (batched " << batched << ")";
    } catch (const RunError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("non-finite contact force at step 2 between ball 1 and ball 2"), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace hilldem
