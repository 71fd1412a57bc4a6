// Where each contact model enters the engine: its mapping, its law on one row, whether its existing
// ball-ball contacts go through a batch, and what its wall rows add to a wall's normal stiffness.
//
// Adding a model (docs/architecture.md): its law in models/ (one template over the lane type), one
// case in each switch of model_dispatch.cpp and batch_of (every switch over ModelKind is exhaustive,
// -Werror=switch, so a model without its case does not compile), and its tests.
#pragma once

#include <cstddef>

#include "hilldem/bodies/ball_store.hpp"
#include "hilldem/contact/contact_store.hpp"
#include "hilldem/core/vec3.hpp"
#include "hilldem/engine/row_results.hpp"
#include "hilldem/models/contact_kinematics.hpp"
#include "hilldem/models/model_table.hpp"

namespace hilldem {

// Row c's mapping from its parameters and its bodies' properties (hill: spec §2.4, real masses;
// linear and rrlinear: the springs).
void compute_mapping(const BallStore& balls, ContactStore& store, std::size_t c);

// What a row's law reads besides its columns.
struct RowLawInput {
  ContactKinematics kin;  // n̂_c, g_c, the relative velocity at x_c, Δt
  Vec3 carried;           // the shear force of the last step carried into the contact plane [N]
  double mean_spin = 0.0; // ½(ω1 + ω2)·n̂ [rad/s] (§1.3: the twist that rotates the plane)
  Vec3 relative_spin;     // ω2 − ω1 [rad/s]
  double r1 = 0.0;        // radius of ball 1 [m]
  double r2 = 0.0;        // radius of ball 2 [m], 0 for a wall
  bool wall_row = false;
  bool want_stiffness = false;  // k̂_n + k̂_s and k̂_s for the time step (spec §4)
};

// Row c's law (its model's, models/): out's shear, moisture, force, normal_force, moisture_force,
// trial_shear, active, moment, k_tran and k_shear. The row's parameters and mapping from its columns.
void run_row_law(const ContactStore& contacts, std::size_t c, const RowLawInput& in, RowOutcome& out);

// The batches of the force pass (engine/contact_batch.hpp): a model's existing ball-ball contacts go
// through one, or row by row (None).
enum class BatchKind { Hill, Linear, None };
constexpr BatchKind batch_of(ModelKind model) {
  switch (model) {
    case ModelKind::Hill: return BatchKind::Hill;
    case ModelKind::Linear: return BatchKind::Linear;
    case ModelKind::RrLinear: return BatchKind::None;  // (its moment: row by row)
  }
  return BatchKind::None;
}

// What the time-step estimate queries of row c before its law has run on its present state (after
// make_wet, make_dry or new properties; spec §4: every active contact): whether the model counts it as
// active at gap g [m] in its present state, and k̂_n + k̂_s and k̂_s [N/m] (hill: Eqs. 19-21).
struct TimestepStiffness {
  bool active = false;
  double k_tran = 0.0;
  double k_shear = 0.0;
};
TimestepStiffness timestep_stiffness(const ContactStore& contacts, std::size_t c, double gap);

// What an active wall row adds to its wall's normal stiffness [N/m] (the servos' gain).
double wall_normal_stiffness(const ContactStore& contacts, std::size_t c);

}  // namespace hilldem
