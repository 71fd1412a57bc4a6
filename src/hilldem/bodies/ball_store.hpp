// BallStore: every ball's data as structure-of-arrays (one std::vector per property, as LAMMPS
// Atom and HOOMD ParticleData do). No physics here: the cycle reads and writes these arrays.
#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "hilldem/core/vec3.hpp"

namespace hilldem {

// Fixity of the six generalised velocity components (bit i: translation x,y,z then spin x,y,z).
// A fixed component keeps its prescribed velocity and ignores forces (spec §4).
using FixityMask = std::uint8_t;
inline constexpr FixityMask kFixVel = 0b000111;
inline constexpr FixityMask kFixSpin = 0b111000;
inline constexpr FixityMask kFixAll = 0b111111;

struct BallInit {
  std::int64_t id = 0;        // user id, unique
  Vec3 position;              // [m]
  double radius = 0.0;        // [m] > 0
  double density = 0.0;       // [kg/m^3] > 0
  double young_mod = 0.0;     // E [Pa], surface property used by the hill model (spec §2.2)
  double pois_ratio = 0.0;    // ν [-], in (-1, 0.5]
  Vec3 velocity;              // [m/s]
  Vec3 spin;                  // [rad/s]
  FixityMask fixity = 0;
  std::uint64_t groups = 0;   // bit set of group ids (GroupNames)
};

class BallStore {
 public:
  std::size_t size() const { return id.size(); }
  std::size_t add(const BallInit& b);  // returns the index
  // Index of the ball with user id, or -1.
  long find(std::int64_t user_id) const;

  // Identity and shape
  std::vector<std::int64_t> id;
  std::vector<double> radius;      // [m]
  std::vector<double> density;     // [kg/m^3]
  std::vector<double> mass;        // [kg]  (4/3)πR³ρ
  std::vector<double> inertia;     // [kg m^2] (2/5) m R²
  std::vector<double> young_mod;   // [Pa]
  std::vector<double> pois_ratio;  // [-]
  std::vector<std::uint64_t> groups;
  std::vector<FixityMask> fixity;

  // Kinematics (velocities live at half steps, spec §4)
  std::vector<Vec3> position;      // [m]
  std::vector<Vec3> velocity;      // [m/s]
  std::vector<Vec3> spin;          // [rad/s]

  // Sums built each cycle
  std::vector<Vec3> contact_force;   // [N] sum of contact forces on the ball
  std::vector<Vec3> contact_moment;  // [N m]
  std::vector<Vec3> applied_force;   // [N] user-applied, constant until changed
  std::vector<Vec3> applied_moment;  // [N m]

  // Recompute mass and inertia of ball i after its radius or density changed.
  void update_mass(std::size_t i);
  // Reorder every column: new index k holds the ball that was at order[k].
  void permute(const std::vector<std::uint32_t>& order);

  // Apply f(column) to every per-ball column (one list, so nothing is forgotten when copying,
  // permuting or checkpointing).
  template <class F>
  void for_each_column(F&& f) {
    f(id); f(radius); f(density); f(mass); f(inertia); f(young_mod); f(pois_ratio); f(groups); f(fixity);
    f(position); f(velocity); f(spin); f(contact_force); f(contact_moment); f(applied_force); f(applied_moment);
  }

 private:
  std::unordered_map<std::int64_t, std::uint32_t> index_of_;  // user id -> index
};

// Interned group names: a ball or wall belongs to a set of groups, stored as a 64-bit mask.
class GroupNames {
 public:
  // Bit for name, adding it if new; throws InputError past 64 names.
  std::uint64_t bit(const std::string& name);
  // Bit for name if known, else 0.
  std::uint64_t find(const std::string& name) const;
  std::string describe(std::uint64_t mask) const;  // "a,b" or "-"

 private:
  std::vector<std::string> names_;
};

// The names of bits 0, 1, 2, ... in order (checkpoints and snapshots list them), up to the first
// that does not read back as its own bit (an empty name, which describe shows as "-").
std::vector<std::string> group_names(const GroupNames& g);

// An order of the balls along a grid of cells one mean diameter wide (by z, then y, then x cell;
// stable), for memory locality: the permutation for BallStore::permute.
std::vector<std::uint32_t> spatial_order(const BallStore& balls);

}  // namespace hilldem
