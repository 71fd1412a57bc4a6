// The domain decomposition (parallel/domain.hpp) against the whole run, under mpirun with any number
// of ranks (tests/mpi/tests.cmake runs 1 to 4): balls sliding on a floor across the ranks'
// sub-domains and the periodic boundary, with frequent rebuilds (a small skin), migrating with their
// rows; the gathered state must be bitwise the whole run's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "hilldem/io/state_io.hpp"
#include "hilldem/parallel/domain.hpp"
#include "hilldem/parallel/mpi_world.hpp"

namespace hilldem {
namespace {

// Two rows of 8 balls (radius 5 mm) along x, periodic in x (0.2 m), on a floor and against a side
// wall (y = 5 mm), gravity tilted towards the wall so that the rows press on the floor, on each other
// and on the wall; the balls slide along +x at 4 m/s on the floor, the rows spinning about z in
// opposite senses, so that they slide on each other and on the wall too, with shear forces at the
// friction limit (linear, μ 0.3).
Simulation sliding_balls() {
  Simulation sim;
  const double r = 0.005;
  std::int64_t id = 1;
  for (int row = 0; row < 2; ++row)
    for (int k = 0; k < 8; ++k) {
      BallInit b;
      b.id = id++;
      b.radius = r;
      b.density = 2650.0;
      b.young_mod = 1e8;
      b.pois_ratio = 0.2;
      // (nearly at rest on the floor and each other: overlaps of the order of m g / k_n ≈ 2e-8 m)
      b.position = {0.025 * k, 0.005 + r - 2e-8 + row * (2 * r - 1e-8), r - 2e-8};
      b.velocity = {4.0, 0.0, 0.0};
      b.spin = {0.0, 0.0, row ? -100.0 : 100.0 + 10.0 * k};
      sim.balls.add(b);
    }
  sim.settings.box.periodic[0] = true;
  sim.settings.box.lo = {0, 0, 0};
  sim.settings.box.hi = {0.2, 0.04, 0.04};
  sim.settings.gravity = {0, -5.0, -9.81};
  sim.settings.local_damping = 0.3;
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 1e-5;
  sim.settings.skin = 1e-3;  // [m] a rebuild every dozen steps
  sim.settings.proximity = 2e-4;
  ModelRule grains;
  grains.name = "grains";
  grains.kind = ContactKind::BallBall;
  grains.model = ModelKind::Linear;
  grains.linear = {1e8, 1.5, 0.3};
  sim.table.rules.push_back(grains);
  ModelRule walls = grains;
  walls.name = "walls";
  walls.kind = ContactKind::BallWall;
  sim.table.rules.push_back(walls);
  Wall floor;
  floor.name = "floor";
  floor.shape = WallShape::Plane;
  floor.point = {0, 0, 0};
  floor.normal = {0, 0, 1};
  sim.walls.add(floor);
  Wall side = floor;
  side.name = "side";
  side.point = {0, 0.005, 0};
  side.normal = {0, 1, 0};
  sim.walls.add(side);
  return sim;
}

// The existing row of `kind` with the largest shear force in `sim` (−1: none).
long largest_shear(const Simulation& sim, ContactKind kind) {
  long best = -1;
  for (std::size_t c = 0; c < sim.contacts.size(); ++c)
    if (sim.contacts.exists[c] && sim.contacts.key[c].kind == kind &&
        (best < 0 || norm(sim.contacts.shear_state[c]) > norm(sim.contacts.shear_state[best])))
      best = static_cast<long>(c);
  return best;
}

std::set<std::uint32_t> owned_globals(const parallel::Domain& d, const Simulation& sim) {
  std::set<std::uint32_t> s;
  for (std::size_t i = 0; i < sim.balls.size(); ++i)
    if (d.owns(i)) s.insert(d.global_index(i));
  return s;
}

TEST(Domain, BallsSlidingAcrossRanksKeepTheirShearForceBitwise) {
  const MPI_Comm comm = parallel::world();
  ASSERT_NE(comm, MPI_COMM_NULL) << "run under mpirun";
  constexpr int kSteps = 1500;  // 6 cm at 4 m/s: across the sub-domains of 2 to 4 ranks
  Simulation whole = sliding_balls();
  whole.cycle(kSteps);

  Simulation part = sliding_balls();
  parallel::Domain domain(comm, part);
  const std::set<std::uint32_t> before = owned_globals(domain, part);
  part.cycle(kSteps);
  const std::set<std::uint32_t> after = owned_globals(domain, part);
  int moved = before != after ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &moved, 1, MPI_INT, MPI_LOR, comm);
  EXPECT_GT(domain.bytes().rebuilds, 20);  // (the rows travelled with their balls many times)
  if (domain.size() > 1) EXPECT_EQ(moved, 1) << "no ball changed its rank";

  const Simulation gathered = domain.gather();
  part.domain = nullptr;
  if (domain.rank() != 0) return;
  EXPECT_EQ(state_difference(gathered, whole), "");
  EXPECT_EQ(state_digest(gathered), state_digest(whole));
  // The contacts sliding hardest, ball-ball and ball-wall: a shear force, with the whole run's bits.
  for (ContactKind kind : {ContactKind::BallBall, ContactKind::BallWall}) {
    const long c = largest_shear(whole, kind);
    ASSERT_GE(c, 0);
    EXPECT_GT(norm(whole.contacts.shear_state[c]), 1e-4);  // [N]
    const long g = gathered.contacts.find(whole.contacts.key[c]);
    ASSERT_GE(g, 0);
    EXPECT_EQ(gathered.contacts.shear_state[g].x, whole.contacts.shear_state[c].x);
    EXPECT_EQ(gathered.contacts.shear_state[g].y, whole.contacts.shear_state[c].y);
    EXPECT_EQ(gathered.contacts.shear_state[g].z, whole.contacts.shear_state[c].z);
  }
  EXPECT_EQ(whole.rebuilds(), part.rebuilds());
}

// A bed of 8 × 8 × 3 balls (radius 5 mm) on a floor, periodic in x and y, pressed by a top plate
// whose servo (a controller on every rank) moves it from its normal force: v_z = −0.1 m/(N s) ×
// (5 N − F_n), within ±0.2 m/s (it reaches the bed, 2 mm below, and presses on it). The plate's force sum steers the run, so a rank whose sum counted
// its ghosts' rows (or added the rows in another order) would move it differently.
Simulation servo_bed() {
  Simulation sim;
  const double r = 0.005, pitch = 0.0105;
  std::int64_t id = 1;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) {
        BallInit b;
        b.id = id++;
        b.radius = r * (1.0 - 0.01 * ((i + 3 * j + 5 * k) % 7));  // (unequal: not a symmetric lattice)
        b.density = 2650.0;
        b.young_mod = 1e8;
        b.pois_ratio = 0.2;
        b.position = {pitch * (i + 0.5) + 1e-4 * (k % 2), pitch * (j + 0.5) + 1e-4 * ((i + k) % 3), r + pitch * k};
        sim.balls.add(b);
      }
  sim.settings.box.periodic[0] = sim.settings.box.periodic[1] = true;
  sim.settings.box.lo = {0, 0, 0};
  sim.settings.box.hi = {8 * pitch, 8 * pitch, 0.1};
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.local_damping = 0.5;
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 1e-5;
  sim.settings.skin = 1e-3;
  sim.settings.proximity = 2e-4;
  ModelRule grains;
  grains.name = "grains";
  grains.kind = ContactKind::BallBall;
  grains.model = ModelKind::Linear;
  grains.linear = {1e8, 1.5, 0.3};
  sim.table.rules.push_back(grains);
  ModelRule walls = grains;
  walls.name = "walls";
  walls.kind = ContactKind::BallWall;
  sim.table.rules.push_back(walls);
  Wall floor;
  floor.name = "floor";
  floor.shape = WallShape::Plane;
  floor.point = {0, 0, 0};
  floor.normal = {0, 0, 1};
  sim.walls.add(floor);
  Wall top = floor;
  top.name = "top";
  top.point = {0, 0, 2 * pitch + 2 * r + 2e-3};
  top.normal = {0, 0, -1};
  sim.walls.add(top);
  sim.controllers.push_back([](Simulation& s, double) {
    Wall& w = s.walls.walls[1];
    w.velocity.z = std::clamp(-0.1 * (5.0 - w.normal_force), -0.2, 0.2);
  });
  return sim;
}

TEST(Domain, ServoOnAWallSumOverRanksGivesTheWholeRunBitwise) {
  const MPI_Comm comm = parallel::world();
  ASSERT_NE(comm, MPI_COMM_NULL) << "run under mpirun";
  constexpr int kSteps = 2000;
  Simulation whole = servo_bed();
  Simulation part = servo_bed();
  parallel::Domain domain(comm, part);
  // Step by step: every rank's plate sums are the whole run's, bits and all.
  int differ = 0;
  std::size_t most_contacts = 0;
  double most_force = 0.0;  // [N]
  for (int k = 0; k < kSteps; ++k) {
    whole.cycle(1);
    part.cycle(1);
    most_contacts = std::max(most_contacts, whole.walls.walls[1].active_contacts);
    most_force = std::max(most_force, whole.walls.walls[1].normal_force);
    for (std::size_t w = 0; w < 2; ++w) {
      const Wall &a = whole.walls.walls[w], &b = part.walls.walls[w];
      differ += a.force.x != b.force.x || a.force.y != b.force.y || a.force.z != b.force.z ||
                a.moment.x != b.moment.x || a.moment.y != b.moment.y || a.moment.z != b.moment.z ||
                a.normal_force != b.normal_force || a.normal_stiffness != b.normal_stiffness ||
                a.active_contacts != b.active_contacts || a.point.z != b.point.z;
    }
  }
  EXPECT_EQ(differ, 0) << "steps at which a rank's wall sums or plate position were not the whole run's";
  EXPECT_GT(most_contacts, 10u);  // (the plate is on the bed)
  EXPECT_GT(most_force, 1.0);     // [N]
  const Simulation gathered = domain.gather();
  part.domain = nullptr;
  if (domain.rank() != 0) return;
  EXPECT_EQ(state_difference(gathered, whole), "");
  EXPECT_EQ(state_digest(gathered), state_digest(whole));
}

}  // namespace
}  // namespace hilldem
