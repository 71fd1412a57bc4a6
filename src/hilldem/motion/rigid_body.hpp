// The law of motion of clumps (issue 32, spec §4 "Clumps need Euler's equations"): rigid bodies of
// any inertia, in their principal frame.
//
// Translation is the ball's (motion/ball_step.hpp, the same arithmetic): central difference with
// velocities at half steps, PFC local damping per global component, gravity, fixity per component.
//
// Rotation integrates the angular momentum L as a leapfrog: the kick L ← L + (M + M_d) Δt in the
// global frame (M_d the local damping on each global component of M, with the sign of ω at t − Δt/2),
// then the drift, the torque-free rotation over Δt, by the symmetric splitting of the free rigid body
// into rotations about the principal axes, each exact,
//   R3(Δt/2) R2(Δt/2) R1(Δt) R2(Δt/2) R3(Δt/2)   (body turns about axis k by L_k/I_k τ)
// — Dullweber, Leimkuhler & McLachlan, J. Chem. Phys. 107, 5840 (1997); in quaternions the NO_SQUISH
// scheme of Miller et al., J. Chem. Phys. 116, 8649 (2002), which LAMMPS's fix rigid uses. Why it:
// explicit, second order, time-reversible and symplectic, so the kinetic energy of a free body has a
// bounded O((ω Δt)²) error instead of a drift, and each sub-step turns the body about an axis it
// keeps L_k about, so the global L is unchanged by the drift up to rounding (Euler's gyroscopic term
// is in the sub-rotations, no iteration). A body whose three principal moments are equal (a sphere:
// one pebble) has no gyroscopic term; it takes the ball's formula ω ← ω + (M + M_d)/I Δt bit for bit,
// and its orientation turns by exp(ω Δt).
//
// Fixity (FixityMask, as for balls: velocity bits 0-2, spin bits 3-5 in global components): a fixed
// component keeps its value (the imposed velocity or spin). All three spins fixed: the body turns by
// exp(ω Δt). Some fixed: the fixed global components of ω are imposed on the angular momentum at the
// start of the drift (ω = R I⁻¹ Rᵀ L at the orientation at t), so they hold at t + Δt/2 to O(Δt).
#pragma once

#include <vector>

#include "hilldem/bodies/clump_state.hpp"

namespace hilldem {

struct RigidMotionSettings {
  Vec3 gravity;                // g [m/s²]
  double local_damping = 0.0;  // α [-], [0, 1)
};

// Clump i from t to t + Δt [s] with force [N] (all but gravity) and torque [N m] about its centre of
// mass, both global, at t.
void step_clump(ClumpState& s, std::size_t i, const Vec3& force, const Vec3& torque, const RigidMotionSettings& m,
                double dt);
// Every clump; force and torque one per clump.
void advance_clumps(ClumpState& s, const std::vector<Vec3>& force, const std::vector<Vec3>& torque,
                    const RigidMotionSettings& m, double dt);

}  // namespace hilldem
