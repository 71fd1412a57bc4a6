// StiffnessSums: per ball, the sums of its contacts' stiffnesses that the time-step estimate and
// density scaling read (spec §4): k_tran = Σ(k̂_n + k̂_s) [N/m], k_rot = Σ k̂_s |x_c − x|² [N m].
//
// Why here: the force pass adds each row's terms as it adds its force (in the forces' order, so the
// sums do not depend on the thread count); after a restore, or a change of the rows, the same sums
// are taken from the rows' columns in the same order, so that both ways give the same bits.
#pragma once

#include <cstddef>
#include <vector>

#include "hilldem/bodies/ball_store.hpp"
#include "hilldem/contact/contact_store.hpp"
#include "hilldem/core/vec3.hpp"
#include "hilldem/engine/neighbour_list.hpp"

namespace hilldem {

// A row's terms of a ball's sums: k_tran += k̂_n + k̂_s, k_rot += k̂_s |x_c − x|² with
// |x_c − x| = R + g/2 (the contact point is on the normal). One expression for the force pass and
// for the sums from the rows, so that both round alike.
HILLDEM_INLINE void add_stiffness(double k_tran_row, double k_shear, double radius, double gap, double& k_tran,
                                  double& k_rot) {
  const double arm = radius + 0.5 * gap;
  k_tran += k_tran_row;
  k_rot += k_shear * arm * arm;
}

// Row c's terms for a ball of the given radius [m], if the row is an active contact (its k_tran,
// k_shear and gap columns, written by the force pass when the sums are wanted).
inline void add_row_stiffness(const ContactStore& contacts, std::size_t c, double radius, double& k_tran,
                              double& k_rot) {
  if (!contacts.active[c]) return;
  add_stiffness(contacts.k_tran[c], contacts.k_shear[c], radius, contacts.gap[c], k_tran, k_rot);
}

class StiffnessSums {
 public:
  std::vector<double> tran, rot;  // per ball, summed by the last force pass [N/m], [N m]
  bool ready = false;             // tran and rot hold the last pass's sums

  // Zero for n balls, not ready (the rows changed).
  void reset(std::size_t n) {
    tran.assign(n, 0.0);
    rot.assign(n, 0.0);
    ready = false;
  }
  // Ball i's sums: the last pass's, or from the rows (the order of the force pass: the ball-ball
  // rows in descending row order, its own then those where it is piece 2; then its wall rows).
  void of_ball(std::size_t i, const BallStore& balls, const ContactStore& contacts, const NeighbourList& list,
               double& k_tran, double& k_rot) const;
  // Δt_crit = min over balls of √(m/k_tran), √(I/k_rot) [s] (spec §4), or +inf if no contact
  // reports a stiffness.
  double critical_timestep(const BallStore& balls, const ContactStore& contacts, const NeighbourList& list) const;
  // Density scaling: each ball's inertial mass and moment of inertia raised to k_tran τ² and
  // k_rot τ² where they are smaller, so that its own critical step is at least τ = Δt/f [s]
  // ([kg], [kg m²]; the gravity and weights keep the real mass).
  void scaled_masses(const BallStore& balls, const ContactStore& contacts, const NeighbourList& list, double tau,
                     std::vector<double>& mass, std::vector<double>& inertia) const;
};

}  // namespace hilldem
