// ContactStore: every contact as structure-of-arrays, sorted by its key (ball a, kind, piece b), so
// that history survives re-detection by a linear merge and every sum over contacts has a fixed order
// (determinism regardless of thread count).
#pragma once

#include <cstdint>
#include <vector>

#include "hilldem/contact/contact_kinematics.hpp"
#include "hilldem/models/hill.hpp"
#include "hilldem/models/linear.hpp"
#include "hilldem/models/model_table.hpp"

namespace hilldem {

struct ContactKey {
  std::uint32_t a = 0;  // ball index (piece 1)
  ContactKind kind = ContactKind::BallBall;
  std::uint32_t b = 0;  // ball index (> a) or wall index (piece 2)
  friend auto operator<=>(const ContactKey&, const ContactKey&) = default;
};

class ContactStore {
 public:
  std::size_t size() const { return key.size(); }

  // Identity and model
  std::vector<ContactKey> key;
  std::vector<std::int16_t> rule;      // index into ModelTable::rules
  std::vector<ModelKind> model;
  std::vector<LinearParams> linear_params;  // meaningful when model == Linear
  std::vector<HillParams> hill_params;      // meaningful when model == Hill
  std::vector<LinearMapping> linear_map;
  std::vector<HillMapping> hill_map;

  // History carried between steps
  std::vector<Vec3> shear_state;    // linear: F_s; hill: F^h_s [N], in the plane of `normal`
  std::vector<Vec3> shear_disp;     // accumulated relative shear displacement Σ Δδ_s [m], same plane
  std::vector<Vec3> normal;         // n̂_c of the last step
  std::vector<Moisture> moisture;   // hill M

  // Results of the last force-displacement pass
  std::vector<double> gap;             // g_c [m]
  std::vector<Vec3> point;             // x_c [m]
  std::vector<Vec3> force;             // F_c on piece 2 [N]
  std::vector<double> normal_force;    // F_n (linear) or F^s_n (hill) [N], compression positive
  std::vector<double> moisture_force;  // F^m [N] ≤ 0
  std::vector<Vec3> shear_force;       // F_s [N]
  std::vector<double> trial_shear;     // |F*_s| [N]
  std::vector<std::uint8_t> active;

  // Apply f(column_of_this, column_of_other) to every column: one list, so that copying, clearing and
  // reserving can never forget a column.
  template <class Self, class Other, class F>
  static void zip_columns(Self& self, Other& other, F&& f) {
    f(self.key, other.key); f(self.rule, other.rule); f(self.model, other.model);
    f(self.linear_params, other.linear_params); f(self.hill_params, other.hill_params);
    f(self.linear_map, other.linear_map); f(self.hill_map, other.hill_map);
    f(self.shear_state, other.shear_state); f(self.shear_disp, other.shear_disp);
    f(self.normal, other.normal); f(self.moisture, other.moisture);
    f(self.gap, other.gap); f(self.point, other.point); f(self.force, other.force);
    f(self.normal_force, other.normal_force); f(self.moisture_force, other.moisture_force);
    f(self.shear_force, other.shear_force); f(self.trial_shear, other.trial_shear);
    f(self.active, other.active);
  }

  // Append row i of `from`, history included.
  void append_row(const ContactStore& from, std::size_t i) {
    zip_columns(*this, from, [i](auto& dst, const auto& src) { dst.push_back(src[i]); });
  }
  // Append a fresh contact with default history (dry, no shear force).
  void append_new(const ContactKey& k, int rule_index, ModelKind m, const LinearParams& lp,
                  const HillParams& hp, const Vec3& n);
  void clear() {
    zip_columns(*this, *this, [](auto& dst, auto&) { dst.clear(); });
  }
  // Index of the contact with key k, or -1 (binary search: keys are sorted).
  long find(const ContactKey& k) const;
};

}  // namespace hilldem
