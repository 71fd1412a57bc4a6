// Contact life cycle details: a contact that re-forms on a row that outlived its previous contact
// takes its rule's properties again; a non-finite ball position stops the cycle at the neighbour
// check; the accumulated shear displacement is kept only when asked for.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "hilldem/core/error.hpp"
#include "sim_builders.hpp"

namespace hilldem {
namespace {

using namespace hilldem::testing;

// Two granite balls (R = 5 mm) 1 mm apart on the x axis, hill model without suction in the rule.
Simulation pair_apart() {
  Simulation sim = granite_row({1e-3});
  sim.settings.skin = 3e-3;  // the pair stays on the neighbour list throughout
  return sim;
}

TEST(ContactLifecycle, ReformedContactTakesTheRulePropertiesAgain) {
  Simulation sim = pair_apart();
  sim.make_wet(200e3, 2e-3);
  long c = sim.find_ball_ball(1, 2);
  ASSERT_GE(c, 0);
  ASSERT_DOUBLE_EQ(sim.contacts.hill_params[c].suction, 200e3);
  sim.make_dry();
  sim.cycle(1);  // dry and open: deleted, the row stays a neighbour pair
  ASSERT_LT(sim.find_ball_ball(1, 2), 0);
  ASSERT_EQ(sim.contacts.size(), 1u);
  const auto rebuilds = sim.rebuilds();
  // Drive ball 2 into ball 1: the contact forms again on the same row.
  sim.balls.velocity[1] = {-2.0, 0, 0};
  sim.balls.fixity[1] = kFixVel;
  for (int k = 0; k < 1000 && sim.find_ball_ball(1, 2) < 0; ++k) sim.cycle(1);
  c = sim.find_ball_ball(1, 2);
  ASSERT_GE(c, 0);
  EXPECT_EQ(sim.rebuilds(), rebuilds);  // no rebuild in between: the same row re-formed
  EXPECT_EQ(sim.contacts.hill_params[c].suction, 0.0);
  EXPECT_EQ(sim.contacts.moisture[c], Moisture::Dry);
}

TEST(ContactLifecycle, NonFinitePositionStopsTheCycle) {
  Simulation sim = pair_apart();
  sim.cycle(2);
  sim.balls.position[1].y = std::numeric_limits<double>::quiet_NaN();
  try {
    sim.cycle(1);
    FAIL() << "a NaN position went unnoticed";
  } catch (const RunError& e) {
    EXPECT_NE(std::string(e.what()).find("ball 2 has a non-finite position"), std::string::npos) << e.what();
  }
}

// The same before the first list is made, where no travel is measured: the neighbour list stops with
// the ball's name, not in the cell grid (a fuzzed checkpoint got there with a non-finite position,
// and the grid's cell count became a cast of NaN to an integer: fuzz/corpus/checkpoint/
// finding_nan_cell_count.hdc).
TEST(ContactLifecycle, NonFinitePositionStopsTheFirstNeighbourList) {
  for (const double bad : {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    Simulation sim = pair_apart();
    sim.balls.position[1].z = bad;
    try {
      sim.update_forces();  // the first list, and the forces, without a step
      FAIL() << "a position of " << bad << " went unnoticed";
    } catch (const RunError& e) {
      EXPECT_NE(std::string(e.what()).find("ball 2 has a non-finite position at step 0"), std::string::npos)
          << e.what();
    }
  }
}

// Two overlapping balls sliding past each other at 0.1 m/s for n steps.
Simulation sliding_pair(bool track) {
  Simulation sim = pair_apart();
  sim.balls.position[1].x = 2 * 5e-3 - 1e-5;
  sim.balls.velocity[1] = {0, 0.1, 0};
  sim.balls.fixity[0] = sim.balls.fixity[1] = kFixAll;
  sim.settings.track_shear_displacement = track;
  sim.cycle(100);
  return sim;
}

TEST(ContactLifecycle, ShearDisplacementOnlyWhenTracked) {
  const Simulation off = sliding_pair(false), on = sliding_pair(true);
  const long c_off = off.find_ball_ball(1, 2), c_on = on.find_ball_ball(1, 2);
  ASSERT_GE(c_off, 0);
  ASSERT_GE(c_on, 0);
  EXPECT_EQ(norm(off.contacts.shear_disp[c_off]), 0.0);
  // 100 steps of 1e-6 s at 0.1 m/s (the first step's force pass is the one at t = 0).
  EXPECT_NEAR(norm(on.contacts.shear_disp[c_on]), 0.1 * 100e-6, 0.1 * 1.5e-6);
  // Tracking changes nothing else.
  EXPECT_EQ(off.contacts.force[c_off], on.contacts.force[c_on]);
  EXPECT_EQ(off.contacts.shear_force(c_off), on.contacts.shear_force(c_on));
}

}  // namespace
}  // namespace hilldem
