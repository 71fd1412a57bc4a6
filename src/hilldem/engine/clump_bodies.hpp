// ClumpBodies: the clumps of a simulation (docs/clumps.md) and their pebbles as balls.
//
// Why pebbles are balls: a pebble is a BallStore row like any ball (LIGGGHTS's multisphere and
// MercuryDPM do the same), so its contacts — with balls, pebbles of other clumps and walls, under any
// model — go through the one neighbour list, cell grid and force pass. What makes it a pebble:
//   * its clump's rigid motion sets its position, velocity and spin (place_pebbles: x_k = X + q p_k q*,
//     v_k = V + ω × (x_k − X), ω_k = ω), and its own fixity is kFixAll, so the balls' law of motion
//     changes nothing but what place_pebbles writes over;
//   * its contact force and moment are summed into its clump (sum_pebble_loads, in pebble order:
//     the same bits for any thread count) before the clump's law of motion (motion/rigid_body.hpp);
//   * its mass column is its clump's mass [kg] and its inertia column the clump's smallest principal
//     moment [kg m²], so that the contact mappings (spec §2.4: the dashpots' effective mass, the hill
//     model's mass terms) use the clump's mass, while its radius is the pebble's (the local radius of
//     the hill model: memo Table 2, footnote 8);
//   * the neighbour list has no rows between pebbles of one clump (clump_of_balls).
#pragma once

#include <cstdint>
#include <vector>

#include "hilldem/bodies/ball_store.hpp"
#include "hilldem/bodies/clump_pebbles.hpp"
#include "hilldem/bodies/clump_state.hpp"
#include "hilldem/bodies/clump_template.hpp"
#include "hilldem/motion/ball_step.hpp"
#include "hilldem/motion/rigid_body.hpp"

namespace hilldem {

// A clump to add: where and how it moves, and what its pebbles are as balls.
struct ClumpInit {
  std::int64_t first_ball_id = 0;  // its pebbles' ball ids: first_ball_id, +1, ...
  Vec3 position;                   // centre of mass [m]
  Quat orientation;                // the rotation of the template's frame (identity: as given)
  Vec3 velocity;                   // [m/s]
  Vec3 spin;                       // ω [rad/s], global
  FixityMask fixity = 0;
  std::uint64_t groups = 0;        // the clump's groups, carried by its pebbles (assignment rules)
  double young_mod = 0.0;          // E [Pa] and ν [-] of its pebbles' surfaces (hill model)
  double pois_ratio = 0.0;
};

struct ClumpBodies {
  ClumpState state;
  ClumpPebbles pebbles;
  std::vector<std::uint32_t> ball;  // pebble k's row in the BallStore
  std::vector<std::uint64_t> groups;  // per clump

  std::size_t size() const { return state.size(); }
  // Apply f(column) to every column (checkpoints, state comparison: one list, none forgotten): the
  // clumps' eight, their groups, then the pebbles' four. kColumnNames: their names, in this order.
  template <class F>
  void for_each_column(F&& f) {
    for_each_clump_column(f);
    f(pebbles.clump); f(pebbles.body_position); f(pebbles.radius); f(ball);
  }
  // The columns with one entry per clump (the first nine: what a clump is, without its pebbles).
  template <class F>
  void for_each_clump_column(F&& f) {
    f(state.position); f(state.velocity); f(state.orientation); f(state.spin); f(state.body_momentum);
    f(state.mass); f(state.principal_inertia); f(state.fixity); f(groups);
  }
  static constexpr const char* kColumnNames[] = {"position", "velocity", "orientation", "spin", "body_momentum",
                                                 "mass", "principal_inertia", "fixity", "groups", "pebble_clump",
                                                 "pebble_body_position", "pebble_radius", "pebble_ball"};
  bool empty() const { return state.size() == 0; }

  // Add a clump from template t, its pebbles appended to balls (placed). Returns the clump's index.
  std::size_t add(BallStore& balls, const ClumpTemplate& t, const ClumpInit& c);
  // Per ball, its clump or kNoClump (n balls); empty when there are no clumps.
  std::vector<std::uint32_t> clump_of_balls(std::size_t n) const;
  // The pebbles' positions, velocities and spins [m, m/s, rad/s] in the balls' columns, from the clumps.
  void place_pebbles(BallStore& balls) const;
  // The same for pebble k.
  void place_pebble(BallStore& balls, std::size_t k) const;
  // The clumps' law of motion over Δt [s] with the loads at t on their pebbles: contact sums (the
  // force pass's, or the columns when null) plus the pebbles' applied loads, summed into force and
  // torque about each centre of mass (sum_pebble_loads), then step_clump; then place_pebbles.
  void advance(BallStore& balls, const motion::ContactSums* sums, const RigidMotionSettings& m, double dt);
  // The sums of the last advance (or loads()) [N], [N m], one per clump (all but gravity).
  std::vector<Vec3> force, torque;
  // force and torque from the loads now on the pebbles (as advance sums them).
  void loads(const BallStore& balls, const motion::ContactSums* sums);
  // The clumps' critical time step squared [s²] (spec §4 with a clump's mass and inertia): min over
  // clumps of m/Σ_k k_tran,k and I1/Σ_k [k_rot,k + k_tran,k |p_k| (|p_k| + 2 R_k)], from each pebble
  // k's sums (StiffnessSums: k_tran = Σ(k̂_n + k̂_s), k_rot = Σ k̂_s a², a the arm from its centre).
  // Why: turning the clump by θ about an axis e through its centre of mass moves a contact point
  // x_c = X + p_k + a n̂ by θ e × (x_c − X), resisted by at most k̂_n (e·(p_k × n̂))² + k̂_s |e × (x_c −
  // X)|² ≤ k̂_n |p_k|² + k̂_s (|p_k| + a)² ≤ k̂_s a² + (k̂_n + k̂_s)|p_k|(|p_k| + 2a), with a ≈ R_k. A
  // one-pebble clump (p = 0) has the ball's sums, bit for bit. +inf without stiffness.
  double critical_timestep2(const std::vector<double>& k_tran_of_pebble, const std::vector<double>& k_rot_of_pebble) const;
  // After balls.permute(order): each pebble's ball row follows its ball.
  void balls_permuted(const std::vector<std::uint32_t>& order);
  // Throws RunError unless every pebble's ball row exists, is a distinct ball and has its pebble's radius.
  void check(const BallStore& balls) const;
};

}  // namespace hilldem
