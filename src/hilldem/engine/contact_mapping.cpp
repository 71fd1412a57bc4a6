#include "hilldem/engine/contact_mapping.hpp"

#include "hilldem/engine/model_dispatch.hpp"

namespace hilldem {

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
