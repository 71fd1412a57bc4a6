#include "hilldem/engine/contact_mapping.hpp"

namespace hilldem {

void compute_mapping(const BallStore& balls, ContactStore& store, std::size_t c) {
  const ContactKey& k = store.key[c];
  // (Exhaustive: a model without a case here does not compile, -Werror=switch.)
  switch (store.model[c]) {
    case ModelKind::Linear:
    case ModelKind::RrLinear: {  // (the linear springs; R̄ of rrlinear is taken in the force pass)
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

void create_contact(const ModelTable& table, const BallStore& balls, HillParamSets& sets, ContactStore& contacts,
                    std::size_t c, const Vec3& normal) {
  // A new contact takes its properties from its assignment rule, as a row new to the neighbour list
  // does: what an earlier contact of the same pair was given (make_wet's suction, a set_contact
  // stage) is gone with it, and the result does not depend on when the list was rebuilt.
  const auto r = static_cast<std::size_t>(contacts.rule[c]);
  const ModelRule& rule = table.rules[r];
  if (contacts.model[c] == ModelKind::Hill) {
    contacts.hill_params[c] = rule.hill;
    sets.new_row(c, r, rule.hill);
  } else {
    contacts.linear_params[c] = rule.linear;
  }
  compute_mapping(balls, contacts, c);
  contacts.create(c, normal);
}

}  // namespace hilldem
