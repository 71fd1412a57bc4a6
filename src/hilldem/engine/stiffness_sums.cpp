#include "hilldem/engine/stiffness_sums.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "hilldem/motion/law_of_motion.hpp"

namespace hilldem {

void StiffnessSums::of_ball(std::size_t i, const BallStore& balls, const ContactStore& contacts,
                            const NeighbourList& list, double& k_tran, double& k_rot) const {
  if (ready) {
    k_tran = tran[i];
    k_rot = rot[i];
    return;
  }
  k_tran = k_rot = 0.0;
  const std::vector<std::uint32_t>& first = list.first_rows();
  if (i + 1 >= first.size()) return;  // a ball added since the last rebuild: no contacts yet
  const double radius = balls.radius[i];
  for (std::size_t c = first[i + 1]; c-- > first[i];) add_row_stiffness(contacts, c, radius, k_tran, k_rot);
  for (std::uint32_t k = list.late_rows_start()[i + 1]; k-- > list.late_rows_start()[i];)
    add_row_stiffness(contacts, list.late_rows()[k], radius, k_tran, k_rot);
  for (std::uint32_t k = list.wall_rows_start()[i]; k < list.wall_rows_start()[i + 1]; ++k)
    add_row_stiffness(contacts, list.wall_rows()[k], radius, k_tran, k_rot);
}

double StiffnessSums::critical_timestep(const BallStore& balls, const ContactStore& contacts,
                                        const NeighbourList& list) const {
  // The minimum is taken over the squares m/k_tran, I/k_rot [s²] and rooted once: √ is monotonic and
  // correctly rounded, so √(min x) is bit for bit min √x, without two roots per ball.
  const std::size_t n = balls.size();
  double crit2 = std::numeric_limits<double>::infinity();
#pragma omp parallel for schedule(static) reduction(min : crit2) if (n > kParallelMin)
  for (std::size_t i = 0; i < n; ++i) {
    double k_tran, k_rot;
    of_ball(i, balls, contacts, list, k_tran, k_rot);
    if (k_tran > 0.0) crit2 = std::min(crit2, balls.mass[i] / k_tran);
    if (k_rot > 0.0) crit2 = std::min(crit2, balls.inertia[i] / k_rot);
  }
  return std::sqrt(crit2);
}

void StiffnessSums::scaled_masses(const BallStore& balls, const ContactStore& contacts, const NeighbourList& list,
                                  double tau, std::vector<double>& mass, std::vector<double>& inertia) const {
  const std::size_t n = balls.size();
  mass.resize(n);
  inertia.resize(n);
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (std::size_t i = 0; i < n; ++i) {
    double k_tran, k_rot;
    of_ball(i, balls, contacts, list, k_tran, k_rot);
    mass[i] = std::max(balls.mass[i], k_tran * tau * tau);
    inertia[i] = std::max(balls.inertia[i], k_rot * tau * tau);
  }
}

}  // namespace hilldem
