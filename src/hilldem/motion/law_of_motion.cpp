#include "hilldem/motion/law_of_motion.hpp"

#include "hilldem/motion/ball_step.hpp"

namespace hilldem {

void advance_balls(BallStore& balls, const MotionSettings& s, double dt, const double* inertial_mass,
                   const double* inertial_inertia, const motion::ContactSums* contact_sums) {
  using namespace motion;
  const double alpha = s.local_damping;
  const std::size_t n = balls.size();
  const V4 gravity = load(s.gravity);
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (std::size_t i = 0; i < n; ++i) {
    V4 x = load(balls.position[i]), v = load(balls.velocity[i]), w = load(balls.spin[i]);
    const V4 f = contact_sums ? contact_sums[i].force : load(balls.contact_force[i]);
    const V4 m = contact_sums ? contact_sums[i].moment : load(balls.contact_moment[i]);
    step_ball(balls, i, gravity, alpha, dt, balls.mass[i], balls.inertia[i], inertial_mass, inertial_inertia, f, m, x,
              v, w);
    store(balls.velocity[i], v);
    store(balls.spin[i], w);
    store(balls.position[i], x);
  }
}

}  // namespace hilldem
