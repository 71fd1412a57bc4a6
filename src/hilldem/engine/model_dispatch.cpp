#include "hilldem/engine/model_dispatch.hpp"

#include "hilldem/models/hill.hpp"
#include "hilldem/models/linear.hpp"
#include "hilldem/models/rrlinear.hpp"

namespace hilldem {

void compute_mapping(const BallStore& balls, ContactStore& store, std::size_t c) {
  const ContactKey& k = store.key[c];
  switch (store.model[c]) {
    case ModelKind::Linear:
    case ModelKind::RrLinear: {  // (the linear springs; R̄ of rrlinear is taken by run_row_law)
      const double r2 = k.kind == ContactKind::BallBall ? balls.radius[k.b] : 0.0;
      store.linear_map[c] = linear_mapping(store.linear_params[c], balls.radius[k.a], r2);
      break;
    }
    case ModelKind::Hill: {
      const std::size_t a = k.a, b = k.b;  // hill contacts are ball-ball only (checked by the table)
      store.hill_map[c] = hill_mapping(store.hill_params[c],
                                       HillBodies{balls.radius[a], balls.radius[b], balls.young_mod[a],
                                                  balls.young_mod[b], balls.pois_ratio[a], balls.pois_ratio[b],
                                                  balls.mass[a], balls.mass[b]});
      break;
    }
  }
}

void run_row_law(const ContactStore& contacts, std::size_t c, const RowLawInput& in, RowOutcome& out) {
  StiffnessEstimate stiff;
  switch (contacts.model[c]) {
    case ModelKind::Hill: {
      const HillResult r =
          hill_force(contacts.hill_params[c], contacts.hill_map[c], in.kin, HillState{in.carried, out.moisture});
      out.shear = r.state.shear_hm;
      out.moisture = r.state.moisture;
      out.force = r.force, out.normal_force = r.surface_normal, out.moisture_force = r.moisture_force;
      out.trial_shear = r.trial_shear, out.active = r.active;
      if (out.active && in.want_stiffness)
        stiff = hill_timestep_stiffness(contacts.hill_params[c], contacts.hill_map[c], in.kin.gap);
      break;
    }
    case ModelKind::Linear: {
      const LinearResult r =
          linear_force(contacts.linear_params[c], contacts.linear_map[c], in.kin, LinearState{in.carried});
      out.shear = r.state.shear_force;
      out.force = r.force, out.normal_force = r.normal_force, out.trial_shear = r.trial_shear, out.active = r.active;
      if (out.active) stiff = {contacts.linear_map[c].kn, contacts.linear_map[c].ks};
      break;
    }
    case ModelKind::RrLinear: {
      const Vec3 moment = carry_into_plane(contacts.moment_state[c], contacts.normal[c], in.kin.normal, in.mean_spin,
                                           in.kin.dt);
      const RrLinearResult r =
          rrlinear_force(contacts.linear_params[c], contacts.linear_map[c], in.kin, RrLinearState{in.carried, moment},
                         in.relative_spin, rrlinear_radius(in.r1, in.r2));
      out.shear = r.linear.state.shear_force;
      out.force = r.linear.force, out.normal_force = r.linear.normal_force, out.trial_shear = r.linear.trial_shear;
      out.active = r.linear.active;
      out.moment = r.moment;
      out.wall_row = in.wall_row;
      if (out.active) stiff = {contacts.linear_map[c].kn, contacts.linear_map[c].ks};
      break;
    }
  }
  out.k_tran = stiff.kn + stiff.ks;
  out.k_shear = stiff.ks;
}

TimestepStiffness timestep_stiffness(const ContactStore& contacts, std::size_t c, double gap) {
  switch (contacts.model[c]) {
    case ModelKind::Hill: {
      if (!hill_active(contacts.moisture[c], gap)) return {};
      const StiffnessEstimate k = hill_timestep_stiffness(contacts.hill_params[c], contacts.hill_map[c], gap);
      return {true, k.kn + k.ks, k.ks};
    }
    case ModelKind::Linear:
    case ModelKind::RrLinear: {
      if (!(gap < 0.0)) return {};
      const LinearMapping& m = contacts.linear_map[c];
      return {true, m.kn + m.ks, m.ks};
    }
  }
  return {};
}

double wall_normal_stiffness(const ContactStore& contacts, std::size_t c) {
  switch (contacts.model[c]) {
    case ModelKind::Hill: return contacts.k_tran[c];
    case ModelKind::Linear:
    case ModelKind::RrLinear: return contacts.linear_map[c].kn;
  }
  return 0.0;
}

}  // namespace hilldem
