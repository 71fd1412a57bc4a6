// What a Simulation is told (SimulationSettings), and the cycle's bookkeeping that a checkpoint
// carries (CycleState).
#pragma once

#include <cstdint>
#include <vector>

#include "hilldem/contact/cell_grid.hpp"
#include "hilldem/contact/contact_geometry.hpp"
#include "hilldem/core/vec3.hpp"

namespace hilldem {

struct SimulationSettings {
  Vec3 gravity;                  // [m/s²]
  double local_damping = 0.0;    // α [-], [0, 1)
  bool auto_timestep = true;     // Δt from the stiffness estimate (spec §4) or fixed
  double timestep = 1e-6;        // [s] fixed Δt (when auto_timestep is false)
  double timestep_safety = 0.8;  // f [-], Δt = f Δt_crit
  double timestep_max = 1e-4;    // [s] Δt used when no contact reports a stiffness yet
  double proximity = 0.0;        // [m] contacts are created for gaps ≤ proximity
  double skin = 0.0;             // [m] neighbour-list skin; 0 = 0.1 × mean ball diameter
  // Density scaling (as PFC): with a fixed Δt, each ball's inertial mass and inertia are raised to
  // what that Δt needs for stability, m' = max(m, k_tran (Δt/f)²), I' = max(I, k_rot (Δt/f)²).
  // Static equilibria are unchanged; dynamics are not physical. For quasi-static runs only.
  bool density_scaling = false;
  // Accumulate each contact's relative shear displacement (ContactStore::shear_disp). A reported
  // quantity that no law uses: off by default, on when a scenario records contact.shear_disp.
  bool track_shear_displacement = false;
  PeriodicBox box;               // periodic directions and their period [lo, hi) [m]
};


// The cycle's private bookkeeping, for checkpoints: with it a restored run rebuilds its neighbour
// list at the very steps the saved run would have (which matters with periodic boxes, where the
// rebuild wraps positions into the box).
struct CycleState {
  bool forces_ready = false;
  bool rebuild_needed = true;
  std::int64_t rebuilds = 0;
  std::uint64_t unassigned_pairs = 0;
  std::vector<Vec3> position_at_build;  // [m] ball positions at the last rebuild
  double wall_travel = 0.0;             // [m] bound on wall motion since then
  // Whether the contact rows are the whole neighbour list; false: only the contacts and the wall
  // rows (a checkpoint), and the ball-ball rows that are not contacts are made again from
  // position_at_build (NeighbourList::restore_rows).
  bool rows_complete = true;
};

}  // namespace hilldem
