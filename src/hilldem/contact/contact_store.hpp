// ContactStore: the neighbour list and the contacts on it, as structure-of-arrays sorted by key
// (ball a, kind, piece b). Every pair within reach (proximity + skin) at the last rebuild has a row;
// `exists` says whether the row is a contact in PFC's sense (created by proximity, deleted when
// inactive beyond it). History survives rebuilds by a linear merge of sorted keys, and every sum over
// rows has a fixed order (determinism regardless of thread count).
#pragma once

#include <cstdint>
#include <vector>

#include "hilldem/contact/cell_grid.hpp"
#include "hilldem/models/contact_kinematics.hpp"
#include "hilldem/models/hill.hpp"
#include "hilldem/models/linear.hpp"
#include "hilldem/models/model_table.hpp"

namespace hilldem {

struct ContactKey {
  std::uint32_t a = 0;  // ball index (piece 1)
  ContactKind kind = ContactKind::BallBall;
  std::uint32_t b = 0;  // ball index (> a) or wall index (piece 2)
  friend bool operator==(const ContactKey&, const ContactKey&) = default;
  // Rows are ordered by kind first: all ball-ball rows form one block, then all ball-wall rows.
  friend auto operator<=>(const ContactKey& x, const ContactKey& y) {
    if (auto c = x.kind <=> y.kind; c != 0) return c;
    if (auto c = x.a <=> y.a; c != 0) return c;
    return x.b <=> y.b;
  }
};

class ContactStore {
 public:
  std::size_t size() const { return key.size(); }

  // Identity and model
  std::vector<ContactKey> key;
  std::vector<ImageCode> image;        // periodic image of piece 2 (ball-ball)
  std::vector<std::uint8_t> exists;    // a contact now (else only a neighbour pair)
  std::vector<std::int16_t> rule;      // index into ModelTable::rules
  std::vector<ModelKind> model;
  std::vector<LinearParams> linear_params;  // meaningful when model == Linear
  std::vector<HillParams> hill_params;      // meaningful when model == Hill
  std::vector<LinearMapping> linear_map;
  std::vector<HillMapping> hill_map;

  // History carried between steps
  std::vector<Vec3> shear_state;    // linear: F_s; hill: F^h_s [N], in the plane of `normal`
  std::vector<Vec3> shear_disp;     // accumulated relative shear displacement Σ Δδ_s [m], same plane; kept
                                    // only while SimulationSettings::track_shear_displacement is on
  std::vector<Vec3> normal;         // n̂_c of the last step
  std::vector<Moisture> moisture;   // hill M
  std::vector<Vec3> moment_state;   // rrlinear: M_r [N m] on piece 2, in the plane of `normal`

  // Results of the last force-displacement pass
  // Only what the cycle needs is stored (each column costs memory traffic on every step): the shear
  // force is derived from these (shear_force()), the moments from n̂_c × F_c in the force pass. gap,
  // force, normal_force, moisture_force, trial_shear and active of ball-ball rows are written for the
  // cycles someone may read them (Simulation::cycle: the last of a call, and every cycle while
  // observers or controllers are registered); the force pass sums the balls' forces without them.
  std::vector<double> gap;             // g_c [m]
  std::vector<Vec3> force;             // F_c = (F_n + F^m) n̂_c + F_s on piece 2 [N]
  std::vector<double> normal_force;    // F_n (linear) or F^s_n (hill) [N], compression positive
  std::vector<double> moisture_force;  // F^m [N] ≤ 0
  std::vector<double> trial_shear;     // |F*_s| [N]
  std::vector<std::uint8_t> active;
  std::vector<double> k_tran;          // k̂_n + k̂_s [N/m] for the time step (0 if inactive)
  std::vector<double> k_shear;         // k̂_s [N/m]

  // Apply f(column_of_this, column_of_other) to every column: one list, so that copying, clearing and
  // reserving can never forget a column.
  template <class Self, class Other, class F>
  static void zip_columns(Self& self, Other& other, F&& f) {
    f(self.key, other.key); f(self.image, other.image); f(self.exists, other.exists);
    f(self.rule, other.rule); f(self.model, other.model);
    f(self.linear_params, other.linear_params); f(self.hill_params, other.hill_params);
    f(self.linear_map, other.linear_map); f(self.hill_map, other.hill_map);
    f(self.shear_state, other.shear_state); f(self.shear_disp, other.shear_disp);
    f(self.normal, other.normal); f(self.moisture, other.moisture); f(self.moment_state, other.moment_state);
    f(self.gap, other.gap); f(self.force, other.force);
    f(self.normal_force, other.normal_force); f(self.moisture_force, other.moisture_force);
    f(self.trial_shear, other.trial_shear);
    f(self.active, other.active); f(self.k_tran, other.k_tran); f(self.k_shear, other.k_shear);
  }

  // Append row i of `from`, history included.
  void append_row(const ContactStore& from, std::size_t i) {
    zip_columns(*this, from, [i](auto& dst, const auto& src) { dst.push_back(src[i]); });
  }
  // Append a fresh neighbour pair (not a contact yet) with default history.
  void append_new(const ContactKey& k, ImageCode img, int rule_index, ModelKind m, const LinearParams& lp,
                  const HillParams& hp, const Vec3& n);
  // Make row i a fresh contact: dry, no shear force or displacement, normal n.
  void create(std::size_t i, const Vec3& n) {
    exists[i] = 1;
    shear_state[i] = shear_disp[i] = moment_state[i] = Vec3{};
    moisture[i] = Moisture::Dry;  // new contacts start dry (spec §2.5)
    normal[i] = n;
  }
  // Row i stops being a contact (its history is gone).
  void remove(std::size_t i) {
    exists[i] = 0;
    active[i] = 0;
    shear_state[i] = shear_disp[i] = moment_state[i] = force[i] = Vec3{};
    normal_force[i] = moisture_force[i] = trial_shear[i] = k_tran[i] = k_shear[i] = 0.0;
    moisture[i] = Moisture::Dry;
  }
  // F_s [N] of row i: F_c less its normal part (exact zero when the shear force is zero).
  Vec3 shear_force(std::size_t i) const { return force[i] - normal[i] * (normal_force[i] + moisture_force[i]); }
  std::size_t count_existing() const;
  void clear() {
    zip_columns(*this, *this, [](auto& dst, auto&) { dst.clear(); });
  }
  // Index of the contact with key k, or -1 (binary search: keys are sorted).
  long find(const ContactKey& k) const;
};

}  // namespace hilldem
