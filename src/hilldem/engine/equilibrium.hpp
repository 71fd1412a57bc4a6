// How far an assembly is from static equilibrium: PFC's mechanical ratio-average.
#pragma once

#include "hilldem/bodies/ball_store.hpp"
#include "hilldem/contact/contact_store.hpp"
#include "hilldem/core/vec3.hpp"
#include "hilldem/engine/clump_bodies.hpp"

namespace hilldem {

// The mean over free balls (not fully velocity-fixed) of the unbalanced-force magnitude, fixed
// components left out, over the mean over the same balls of the applied-force magnitude: the sum of
// the |F_c| of their active contacts and their weight m|g| [-] (spec lab-tests §3.4). 0 without
// free balls; 1 if nothing is applied but something is unbalanced. Clumps count as bodies: the
// unbalanced force of one is the sum over its pebbles (contact and applied forces) plus its weight,
// its applied force the sum of its pebbles' |F_c| plus its weight; pebbles (fixed balls) do not count
// on their own.
double mean_unbalanced_ratio(const BallStore& balls, const ContactStore& contacts, const Vec3& gravity,
                             const ClumpBodies* clumps = nullptr);

}  // namespace hilldem
