// BallKin: what the force pass reads of one ball, in one record of two cache lines.
//
// Why: the pair loop reads the position, radius, velocity and spin of both balls of every row; in
// one record they are one memory stream per neighbourhood instead of one per column. Between force
// passes of one cycle() call the records are the balls' state (Simulation::advance_records moves
// them), and the BallStore's columns follow when someone may read them.
#pragma once

#include "hilldem/core/vec3.hpp"
#include "hilldem/models/hill.hpp"

namespace hilldem {

struct alignas(64) BallKin {
  Vec3 position;         // [m]
  double radius = 0.0;   // [m]
  Vec3 velocity;         // [m/s]
  Vec3 spin;             // [rad/s]
  HillBodyTerms terms;   // for the hill mappings
  double mass = 0.0;     // [kg] and [kg m²]: for the record motion (in the record's last 16 bytes,
  double inertia = 0.0;  // which the pair loop does not read)
};

}  // namespace hilldem
