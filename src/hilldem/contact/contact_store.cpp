#include "hilldem/contact/contact_store.hpp"

#include <algorithm>

namespace hilldem {

void ContactStore::append_new(const ContactKey& k, ImageCode img, int rule_index, ModelKind m,
                              const LinearParams& lp, const HillParams& hp, const Vec3& n) {
  key.push_back(k);
  image.push_back(img);
  exists.push_back(0);
  rule.push_back(static_cast<std::int16_t>(rule_index));
  model.push_back(m);
  linear_params.push_back(lp);
  hill_params.push_back(hp);
  linear_map.emplace_back();
  hill_map.emplace_back();
  shear_state.emplace_back();
  shear_disp.emplace_back();
  normal.push_back(n);
  moisture.push_back(Moisture::Dry);  // new contacts start dry (spec §2.5)
  moment_state.emplace_back();
  gap.push_back(0.0);
  force.emplace_back();
  normal_force.push_back(0.0);
  moisture_force.push_back(0.0);
  trial_shear.push_back(0.0);
  active.push_back(0);
  k_tran.push_back(0.0);
  k_shear.push_back(0.0);
}

std::size_t ContactStore::count_existing() const {
  std::size_t n = 0;
  for (std::uint8_t e : exists) n += e;
  return n;
}

long ContactStore::find(const ContactKey& k) const {
  const auto it = std::lower_bound(key.begin(), key.end(), k);
  return (it != key.end() && *it == k) ? static_cast<long>(it - key.begin()) : -1;
}

}  // namespace hilldem
