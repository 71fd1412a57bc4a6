// Issue #4 features: periodic boundaries, packing import with replication, thread-count
// independence (bitwise), neighbour-list rebuilds that do not change results, density scaling.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <fstream>

#include "hilldem/contact/cell_grid.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/engine/thread_budget.hpp"
#include "hilldem/io/packing_import.hpp"
#include "sim_builders.hpp"

namespace hilldem {
namespace {

using namespace hilldem::testing;

// Brute-force periodic pair search: every pair (i<j) with its nearest image.
std::vector<std::pair<std::uint32_t, std::uint32_t>> periodic_brute(const std::vector<Vec3>& x, const std::vector<double>& r,
                                                                   double reach, const PeriodicBox& box) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  for (std::uint32_t i = 0; i < x.size(); ++i)
    for (std::uint32_t j = i + 1; j < x.size(); ++j) {
      const Vec3 xj = x[j] + image_shift(nearest_image(x[i], x[j], box), box);
      const double lim = r[i] + r[j] + reach;
      if (norm2(xj - x[i]) <= lim * lim) out.emplace_back(i, j);
    }
  return out;
}

TEST(Periodic, CellGridMatchesBruteForceWithImages) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0), rad(1e-3, 2e-3);
  PeriodicBox box;
  box.periodic[0] = box.periodic[1] = true;
  box.lo = {0, 0, 0};
  box.hi = {0.03, 0.025, 0.02};
  std::vector<Vec3> x;
  std::vector<double> r;
  for (int i = 0; i < 1500; ++i) {
    x.push_back({u(rng) * 0.03, u(rng) * 0.025, u(rng) * 0.02});
    r.push_back(rad(rng));
  }
  const auto found = find_pair_candidates(x, r, 0.3e-3, box);
  const auto expected = periodic_brute(x, r, 0.3e-3, box);
  ASSERT_EQ(found.size(), expected.size());
  std::size_t across = 0;
  for (std::size_t k = 0; k < found.size(); ++k) {
    EXPECT_EQ(found[k].i, expected[k].first);
    EXPECT_EQ(found[k].j, expected[k].second);
    EXPECT_EQ(found[k].image, nearest_image(x[found[k].i], x[found[k].j], box));
    across += found[k].image != kNoImage;
  }
  EXPECT_GT(across, 20u);  // pairs across the periodic faces were found
}

TEST(Periodic, TooSmallBoxIsRefused) {
  PeriodicBox box;
  box.periodic[0] = true;
  box.hi = {0.01, 1, 1};
  EXPECT_THROW(find_pair_candidates({{0.001, 0, 0}, {0.005, 0, 0}}, {2e-3, 2e-3}, 0.0, box), InputError);
}

// Two balls touching across the periodic face x = 0 / x = L push each other apart and the contact
// carries the same force as the same pair inside the box.
TEST(Periodic, ContactAcrossTheBoundary) {
  const double L = 0.1, r = 5e-3, overlap = 2e-5;
  auto run = [&](bool across) {
    Simulation sim;
    const double x1 = across ? r - overlap / 2 : 0.05;
    const double x2 = across ? L - r + overlap / 2 : 0.05 + 2 * r - overlap;
    sim.balls.add(granite(1, {x1, 0.05, 0.05}, r));
    sim.balls.add(granite(2, {x2, 0.05, 0.05}, r));
    sim.table.rules.push_back(hill_rule(0.4, 0.0));
    sim.settings.box.periodic[0] = sim.settings.box.periodic[1] = sim.settings.box.periodic[2] = true;
    sim.settings.box.hi = {L, L, L};
    sim.update_forces();
    const long c = sim.find_ball_ball(1, 2);
    EXPECT_GE(c, 0);
    return std::make_pair(sim.contacts.normal_force[c], sim.balls.contact_force[0].x);
  };
  const auto inside = run(false), across = run(true);
  EXPECT_GT(inside.first, 0.0);
  EXPECT_NEAR(across.first, inside.first, 1e-6 * inside.first);
  EXPECT_LT(inside.second, 0.0);  // ball 1 pushed towards -x ...
  EXPECT_GT(across.second, 0.0);  // ... and across the boundary, towards +x (its neighbour is the image at x < 0)
}

// Positions are wrapped into the box and the run stays identical to an equivalent one.
TEST(Periodic, BallsStayInTheBox) {
  Simulation sim = random_box(300, 21, /*walls=*/false);
  sim.settings.box.periodic[0] = sim.settings.box.periodic[1] = sim.settings.box.periodic[2] = true;
  sim.settings.box.hi = {0.04, 0.04, 0.04};
  for (std::size_t i = 0; i < sim.balls.size(); ++i) sim.balls.velocity[i] *= 50.0;  // fast: many crossings
  sim.cycle(2000);
  for (const Vec3& x : sim.balls.position)
    for (int d = 0; d < 3; ++d) {
      EXPECT_GE(x[d], -0.01);  // wrapped at rebuilds: never far outside
      EXPECT_LE(x[d], 0.05);
    }
}

TEST(PackingImport, LammpsDataWithReplication) {
  const std::string text = R"(LAMMPS data file via write_data

3 atoms
1 atom types

0 0.1 xlo xhi
0 0.2 ylo yhi
0 0.3 zlo zhi

Atoms # sphere

1 1 0.01 2650 0.01 0.02 0.03 0 0 0
2 1 0.012 2600 0.05 0.02 0.03 0 0 0
3 1 0.008 2650 0.09 0.15 0.005 0 0 0

Velocities

1 0 0 0 0 0 0
2 0 0 0 0 0 0
3 0 0 0 0 0 0
)";
  Packing p = parse_packing(text, "bed.data", PackingFormat::Lammps);
  ASSERT_EQ(p.balls.size(), 3u);
  EXPECT_DOUBLE_EQ(p.balls[1].radius, 0.006);
  EXPECT_DOUBLE_EQ(p.balls[1].density, 2600.0);
  EXPECT_DOUBLE_EQ(p.box_hi.y, 0.2);
  const int n[3] = {3, 2, 1};
  replicate(p, n);
  ASSERT_EQ(p.balls.size(), 18u);
  EXPECT_DOUBLE_EQ(p.box_hi.x, 0.3);
  EXPECT_DOUBLE_EQ(p.box_hi.y, 0.4);
  EXPECT_DOUBLE_EQ(p.balls[17].position.x, 0.09 + 0.2);
  EXPECT_DOUBLE_EQ(p.balls[17].position.y, 0.15 + 0.2);
}

TEST(PackingImport, XyzrAndErrors) {
  Packing p = parse_packing("# x y z r\n0 0 0 0.001\n0.01 0 0 0.002 # comment\n", "p.txt", PackingFormat::Xyzr);
  ASSERT_EQ(p.balls.size(), 2u);
  EXPECT_FALSE(p.has_box);
  EXPECT_THROW(parse_packing("0 0 0\n", "p.txt", PackingFormat::Xyzr), InputError);
  EXPECT_THROW(parse_packing("0 0 0 -1\n", "p.txt", PackingFormat::Xyzr), InputError);
  EXPECT_THROW(parse_packing("0 0 nan 1\n", "p.txt", PackingFormat::Xyzr), InputError);
  EXPECT_THROW(parse_packing("t\n\n2 atoms\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms # sphere\n\n1 1 0.01 2650 0 0 0\n",
                             "d.data", PackingFormat::Lammps),
               InputError);  // the header says 2 atoms, the section has 1
  const int n[3] = {2, 1, 1};
  EXPECT_THROW(replicate(p, n), InputError);  // no box
}

// 4,000 wet grains settling under gravity with local damping and the automatic time step: above the
// threshold below which the passes stay on one thread.
Simulation wet_box_4000() {
  Simulation sim = random_box(4000, 9, true, 0.1);
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.local_damping = 0.3;
  sim.settings.auto_timestep = true;
  sim.make_wet(20e3, 0.5e-3);
  return sim;
}

// Balls whose position or spin differ in any bit between two runs.
std::size_t differing_balls(const std::pair<std::vector<Vec3>, std::vector<Vec3>>& x,
                            const std::pair<std::vector<Vec3>, std::vector<Vec3>>& y) {
  std::size_t differ = 0;
  for (std::size_t i = 0; i < x.first.size(); ++i) differ += !(x.first[i] == y.first[i]) || !(x.second[i] == y.second[i]);
  return differ;
}

// Positions and spins of wet_box_4000() after `steps` cycles on `threads` OpenMP threads (the count
// is put back to the number of cores afterwards).
std::pair<std::vector<Vec3>, std::vector<Vec3>> wet_box_after(int threads, int steps) {
  omp_set_num_threads(threads);
  Simulation sim = wet_box_4000();
  sim.cycle(steps);
  omp_set_num_threads(omp_get_num_procs());
  return {sim.balls.position, sim.balls.spin};
}

// Bitwise identical positions after N steps for 1 and 2 threads (issue #4 acceptance).
TEST(Threads, OneAndTwoThreadsGiveBitwiseIdenticalResults) {
  const auto one = wet_box_after(1, 150), two = wet_box_after(2, 150);
  ASSERT_EQ(one.first.size(), two.first.size());
  EXPECT_EQ(differing_balls(one, two), 0u);
}

// Two threads sharing the work unequally (as the force pass does when one core runs slower,
// the threads' measured speeds): each thread's range of balls changes, the bits do not.
TEST(Threads, UnequalSharesOfTheWorkGiveTheSameBits) {
  auto run = [](std::vector<double> shares) {
    omp_set_num_threads(shares.empty() ? 1 : static_cast<int>(shares.size()));
    Simulation sim = wet_box_4000();
    sim.thread_shares = shares;
    sim.cycle(60);
    omp_set_num_threads(omp_get_num_procs());
    return std::make_pair(sim.balls.position, sim.balls.spin);
  };
  const auto one = run({});
  EXPECT_EQ(differing_balls(one, run({0.15, 0.85})), 0u);
  EXPECT_EQ(differing_balls(one, run({0.85, 0.15})), 0u);
}

// Three threads: the force pass cuts the balls into three ranges of equal work (not of equal numbers
// of balls, and not at block boundaries of the one-thread run) and shares the wall rows out three
// ways; still the same bits as one thread.
TEST(Threads, ThreeThreadsGiveTheSameBitsAsOne) {
  const auto one = wet_box_after(1, 60), three = wet_box_after(3, 60);
  ASSERT_EQ(one.first.size(), three.first.size());
  EXPECT_EQ(differing_balls(one, three), 0u);
}

// Ball-ball contacts of both models in one bed: every second ball is "hard", and pairs of hard balls
// get the linear model, all others the hill model; contacts exist from 3 mm apart, so most balls
// have rows of both models. The force pass runs a batch before a row of the other model joins the
// sums (force_block), so each ball's sums keep their order: 1, 2 and 3 threads and any block size
// give the same bits in the contact forces and moments on the balls themselves. (Without that rule
// the sums of 8 balls differ between blocks of 1 and of 128.)
std::pair<std::vector<Vec3>, std::vector<Vec3>> mixed_box_forces(int threads, int steps, std::size_t block) {
  omp_set_num_threads(threads);
  Simulation sim = random_box(4000, 21, true, 0.1);
  const std::uint64_t hard = sim.groups.bit("hard");
  for (std::size_t i = 0; i < sim.balls.size(); i += 2) sim.balls.groups[i] |= hard;
  ModelRule linear;
  linear.name = "hard-hard";
  linear.kind = ContactKind::BallBall;
  linear.groups1 = linear.groups2 = hard;
  linear.model = ModelKind::Linear;
  linear.linear = {100e6, 1.5, 0.3};
  sim.table.rules.insert(sim.table.rules.begin(), linear);
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.local_damping = 0.3;
  sim.settings.auto_timestep = true;
  sim.settings.proximity = 3e-3;
  sim.balls_per_block = block;
  sim.make_wet(20e3, 3e-3);
  sim.cycle(steps);
  std::size_t hill = 0, lin = 0;
  for (std::size_t c = 0; c < sim.contacts.size(); ++c)
    if (sim.contacts.exists[c] && sim.contacts.key[c].kind == ContactKind::BallBall)
      (sim.contacts.model[c] == ModelKind::Hill ? hill : lin) += 1;
  EXPECT_GT(hill, 3000u);
  EXPECT_GT(lin, 1000u);
  omp_set_num_threads(omp_get_num_procs());
  return {sim.balls.contact_force, sim.balls.contact_moment};
}

TEST(Threads, MixedModelsGiveTheSameBitsForAnyThreadsAndBlocks) {
  const auto one = mixed_box_forces(1, 20, Simulation::kDefaultBallsPerBlock);
  const auto two = mixed_box_forces(2, 20, Simulation::kDefaultBallsPerBlock);
  const auto three = mixed_box_forces(3, 20, 1);
  ASSERT_EQ(one.first.size(), two.first.size());
  EXPECT_EQ(differing_balls(one, two), 0u);
  EXPECT_EQ(differing_balls(one, three), 0u);
}

// The contacts' reported columns (gap, F_c, F_n, F^m, |F*_s|, active) are written on the last cycle of a
// cycle() call and on every cycle while an observer is registered, and skipped by the batched
// ball-ball contacts in between (Simulation::cycle). With a fixed time step (no stiffness sums read
// them), a run with no observer must end with the same columns and the same bits as one with an
// observer, and the observer must see each cycle's own results.
TEST(ContactResults, WrittenOnTheLastCycleAndForObservers) {
  auto make = [] {
    Simulation sim = random_box(800, 21);
    sim.settings.gravity = {0, 0, -9.81};
    sim.settings.auto_timestep = false;
    sim.settings.timestep = 1e-6;
    sim.make_wet(20e3, 0.3e-3);  // some bridges: F^m reported
    return sim;
  };
  // Σ F_n + Σ F^m + Σ |F*_s| + Σ gap + Σ |F_c| over active contacts: one number per cycle for the observer.
  auto summary = [](const Simulation& s) {
    double sum = 0.0;
    for (std::size_t c = 0; c < s.contacts.size(); ++c)
      if (s.contacts.active[c])
        sum += s.contacts.normal_force[c] + s.contacts.moisture_force[c] + s.contacts.trial_shear[c] + s.contacts.gap[c] +
               norm(s.contacts.force[c]);
    return sum;
  };
  constexpr int kSteps = 120;
  Simulation quiet = make(), watched = make(), single = make();
  std::vector<double> seen;
  watched.observers.push_back([&](const Simulation& s) { seen.push_back(summary(s)); });
  quiet.cycle(kSteps);
  watched.cycle(kSteps);
  ASSERT_GT(quiet.batched_rows(), 100);  // the batched path ran
  EXPECT_EQ(quiet.balls.position, watched.balls.position);
  EXPECT_EQ(quiet.balls.spin, watched.balls.spin);
  EXPECT_EQ(quiet.contacts.gap, watched.contacts.gap);
  EXPECT_EQ(quiet.contacts.force, watched.contacts.force);
  EXPECT_EQ(quiet.contacts.normal_force, watched.contacts.normal_force);
  EXPECT_EQ(quiet.contacts.moisture_force, watched.contacts.moisture_force);
  EXPECT_EQ(quiet.contacts.trial_shear, watched.contacts.trial_shear);
  EXPECT_EQ(quiet.contacts.active, watched.contacts.active);
  // One cycle per call: every cycle is a last one, so its results are its own.
  ASSERT_EQ(seen.size(), static_cast<std::size_t>(kSteps));
  std::size_t wet = 0, differ = 0;
  for (int k = 0; k < kSteps; ++k) {
    single.cycle(1);
    differ += !(summary(single) == seen[k]);
  }
  for (std::size_t c = 0; c < single.contacts.size(); ++c) wet += single.contacts.moisture_force[c] < 0.0;
  EXPECT_GT(wet, 0u);
  EXPECT_EQ(differ, 0u);
}

// A thread count that changes from step to step (engine/thread_budget.hpp, as a study's cases share
// the cores) gives the same bits as one thread throughout.
TEST(ThreadBudget, ACountThatChangesWhileItRunsGivesTheSameResults) {
  struct Alternating : ThreadBudget {
    mutable int calls = 0;
    int threads() const override { return 1 + (calls++ / 7) % 2; }  // 7 steps on 1 thread, 7 on 2, ...
  };
  auto run = [](const ThreadBudget* budget) {
    omp_set_num_threads(1);
    set_thread_budget(budget);
    Simulation sim = wet_box_4000();
    sim.cycle(100);
    set_thread_budget(nullptr);
    return std::make_pair(sim.balls.position, sim.balls.spin);
  };
  const Alternating alternating;
  const auto one = run(nullptr), changing = run(&alternating);
  EXPECT_GE(alternating.calls, 100);  // asked before every step
  omp_set_num_threads(omp_get_num_procs());
  ASSERT_EQ(one.first.size(), changing.first.size());
  EXPECT_EQ(differing_balls(one, changing), 0u);
}

// The skin is an optimisation only: a run with a large skin (few rebuilds) equals one that
// rebuilds every step, up to round-off in the order of nothing (same rows, same order).
TEST(NeighbourList, SkinDoesNotChangeResults) {
  auto run = [](double skin) {
    Simulation sim = random_box(500, 13);
    sim.settings.skin = skin;
    sim.settings.gravity = {0, 0, -9.81};
    sim.cycle(400);
    return std::make_pair(sim.balls.position, sim.rebuilds());
  };
  const auto small = run(1e-9), large = run(2e-3);
  EXPECT_GT(small.second, 5 * large.second);  // many more rebuilds
  double worst = 0.0;
  for (std::size_t i = 0; i < small.first.size(); ++i) worst = std::max(worst, norm(small.first[i] - large.first[i]));
  EXPECT_LT(worst, 1e-12);
}

}  // namespace
}  // namespace hilldem

namespace hilldem {
namespace {

using namespace hilldem::testing;

// A bimodal pile (radii 5 mm and 1.5 mm, 64 grains on a loose lattice) settling in a box of planes
// under gravity with local damping 0.7: the small grains limit the time step of a plain run.
Simulation bimodal_pile() {
  Simulation sim;
  std::int64_t id = 1;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const double r = (i + j + k) % 2 ? 5e-3 : 1.5e-3;
        sim.balls.add(granite(id++, {6e-3 + i * 10.5e-3, 6e-3 + j * 10.5e-3, 5.2e-3 + k * 10.5e-3}, r));
      }
  sim.table.rules.push_back(hill_rule(0.4, 0.0));
  sim.table.rules.push_back(linear_wall_rule(500e6, 0.4));
  for (int d = 0; d < 3; ++d)
    for (int upper = 0; upper < 2; ++upper) {
      Wall w;
      w.name = "plane" + std::to_string(2 * d + upper);
      w.shape = WallShape::Plane;
      w.point[d] = upper ? 0.0445 : 0.0;
      w.normal[d] = upper ? -1.0 : 1.0;
      sim.walls.add(w);
    }
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.local_damping = 0.7;
  return sim;
}

double total_weight(const Simulation& sim) {
  double w = 0.0;
  for (double m : sim.balls.mass) w += m * 9.81;
  return w;
}

// Density scaling: 6 × the automatic Δt is stable, equilibrium takes several times fewer steps,
// and the static result (floor force = weight) is unchanged. Measured here: 33,491 plain steps
// against 10,985 scaled (8 ×: 9,070; beyond about 10 × the gain is lost to oscillation).
TEST(DensityScaling, SameEquilibriumInFewerSteps) {
  Simulation plain = bimodal_pile();
  const std::int64_t plain_steps = plain.solve(1e-4, 400000);
  ASSERT_GT(plain_steps, 0);

  Simulation scaled = bimodal_pile();
  scaled.settings.auto_timestep = false;
  scaled.settings.timestep = 6 * plain.last_dt;
  scaled.settings.density_scaling = true;
  const std::int64_t scaled_steps = scaled.solve(1e-4, 400000);
  ASSERT_GT(scaled_steps, 0);
  EXPECT_LT(scaled_steps * 2, plain_steps) << "plain " << plain_steps << " scaled " << scaled_steps;
  const double weight = total_weight(plain);
  EXPECT_NEAR(-plain.walls.walls[4].force.z, weight, 1e-3 * weight);  // walls[4]: the floor (z = 0)
  EXPECT_NEAR(-scaled.walls.walls[4].force.z, weight, 1e-3 * weight);
}

// Without density scaling the same Δt is unstable: the grains are blown apart or the run stops.
TEST(DensityScaling, TheSameTimeStepWithoutScalingIsUnstable) {
  Simulation probe = bimodal_pile();
  probe.solve(1e-4, 400000);
  Simulation sim = bimodal_pile();
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 6 * probe.last_dt;
  double worst = 0.0;
  try {
    sim.cycle(20000);
    for (const Vec3& v : sim.balls.velocity) worst = std::max(worst, norm(v));
  } catch (const std::exception&) {
    worst = HUGE_VAL;
  }
  EXPECT_GT(worst, 1.0);  // m/s: nothing near rest
}

}  // namespace
}  // namespace hilldem
