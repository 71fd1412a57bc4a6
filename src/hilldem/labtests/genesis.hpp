// Material genesis (docs/spec/lab-tests.md §3): a seeded random cloud of grains at porosity n_c in
// the vessel, frictionless packing by boundary contraction under servo control to the material
// pressure P_m (each material with its own contact model, μ_CA = 0), static equilibrium,
// finalization through the assignment table (friction restored), and (optionally) wetting. Every phase reports what it did and the state it reached.
#pragma once

#include <cstdint>
#include <cstring>
#include <functional>
#include <iosfwd>
#include <string>
#include <type_traits>
#include <vector>

#include "hilldem/bodies/clump_template.hpp"
#include "hilldem/engine/simulation.hpp"
#include "hilldem/labtests/clump_mix.hpp"
#include "hilldem/labtests/gsd.hpp"
#include "hilldem/labtests/material.hpp"
#include "hilldem/labtests/measure_region.hpp"
#include "hilldem/labtests/vessel.hpp"

namespace hilldem {

class RunDecomposition;  // io/runner.hpp

// Servo-controlled equilibrium of the three vessel walls at one pressure. Converged when, at a check,
// all three hold (lab-tests.md §3.4): every wall within ε_P·P of P; the mean unbalanced-force ratio
// (Simulation::mean_unbalanced_ratio, per body) at most `ratio`; and the vessel porosity changed by at
// most porosity_change per 1,000 steps over the last porosity_window steps (PorosityHistory).
struct EquilibriumSettings {
  double pressure = 150e3;           // target wall pressure [Pa] (P_m)
  double pressure_tolerance = 1e-2;  // ε_P: every wall within ε_P·P of P [-]
  double ratio = 8e-3;               // static equilibrium: mean unbalanced-force ratio ≤ this [-]
  double porosity_change = 2e-5;     // |Δn| per 1,000 steps at most this [-] [ours]
  std::int64_t porosity_window = 5000;  // steps Δn is taken over [ours]
  double servo_gain = 0.5;           // α_s [-]
  double wall_speed_limit = 1.0;     // v_lim [m/s]
  std::int64_t check_every = 50;     // cycles between convergence checks
  std::int64_t max_steps = 4'000'000;
};

// The convergence criterion in words, for logs and summaries.
std::string criterion_text(const EquilibriumSettings& e);

// The vessel porosity along a servo equilibrium, sampled at its checks: how much it still changes.
class PorosityHistory {
 public:
  explicit PorosityHistory(std::int64_t window) : window_(window) {}
  void add(std::int64_t step, double porosity);
  // |n(now) − n(then)| × 1000 / (now − then) [-] per 1,000 steps, `then` the latest sample at least
  // `window` steps before the newest; false until the samples span the window.
  bool change_per_1000(double& out) const;
  // The history spans the window and the change is at most `tolerance` per 1,000 steps.
  bool converged(double tolerance) const;

 private:
  std::int64_t window_;
  std::vector<std::pair<std::int64_t, double>> samples_;  // (step, porosity), steps increasing
};

struct PackingSettings {
  std::uint64_t seed = 10000;        // N_RS (Table 7)
  double cloud_porosity = 0.58;      // n_c (Table 7)
  double local_damping = 0.7;        // α (Table 7)
  int placement_tries = 20;          // cloud: best of this many random positions per grain [ours]
  double cloud_speed_limit = 1.0;    // cloud relaxation: grain speed cap [m/s] [ours]
  double cloud_overlap = 1e-3;       // relaxation ends when every overlap ≤ this × smallest diameter [ours]
  std::int64_t cloud_max_steps = 200'000;
  EquilibriumSettings equilibrium;   // P_m = 150 kPa, ε_P = 1e-2, ε_lim = 8e-3, v_lim = 1 m/s (Table 7)
  PackingContact contact;            // frictionless packing contacts: hill by default, or linear
  WallContact walls;
};

struct GenesisSpec {
  Grading grading = grading_c5b();
  double d_mult = 1.0;               // D_mult (Table 7)
  double vessel_radius = 0.085;      // [m] (170 mm diameter)
  double vessel_height = 0.240;      // [m]
  // The grains' density, E and ν from the cloud on (the hill packing contacts read E and ν); the
  // material's model and friction are not used here (packing.contact says how grains are packed).
  Class5Material grain;
  PackingSettings packing;
  // Grains as clumps (docs/clumps.md, "Specimens of clumps"): empty for balls, else named templates
  // (bodies/clump_shapes.hpp: sphere, elongated2, ...) with the solid volume fraction each takes
  // (check_clump_mix; one template: the list of one at 1). Each grain's template is drawn from the
  // seed on a stream of its own (assign_clump_templates), the grain is that template scaled so that
  // its size by clump_size is the size drawn from the grading, turned to a uniformly random
  // orientation drawn from the seed after its position.
  ClumpMix clump_mix;
  SizeMeasure clump_size = SizeMeasure::EqualVolumeDiameter;
  // Not physics: given to every Simulation made from this spec (Simulation::interrupt), and by
  // make_packed to a specimen it loads, so that a lab test stops between two cycles when it
  // answers true (the CLI: on SIGINT, SIGTERM, SIGHUP), throwing Interrupted.
  std::function<bool()> interrupt;
  // Not physics: the run over MPI ranks this process is one rank of (docs/mpi.md, "The lab tests over
  // ranks"), given to every Specimen made from this spec (Specimen::ranks); null: one process.
  RunDecomposition* ranks = nullptr;
};
// Throws InputError naming the first bad value.
void validate(const GenesisSpec& spec);

// What a specimen looks like now.
struct SpecimenState {
  std::size_t grains = 0;
  double porosity = 0.0;            // 1 − V_solid / (π R² H) [-]: the whole vessel
  // In a coaxial measurement cylinder one margin in from every wall [-] (measure_region.hpp). The
  // margin is D_max; where that leaves less than D_max in radius or 2 D_max in height (the half-size
  // vessels), it is D50, the grains' volume-median diameter; where even that leaves too little, the
  // interior is not measured: interior_margin is None and interior_porosity NaN (never printed as
  // such: interior_text() says "n/a" and why).
  double interior_porosity = 0.0;
  enum class Margin : std::uint8_t { DMax, D50, None } interior_margin = Margin::DMax;
  double interior_margin_length = 0.0;  // the margin [m] (0 when None)
  // 2 N_c / N_grains, N_c the touching contacts between two grains [-]. With clumps each touching
  // pebble-pebble (or pebble-ball) contact counts once, as PFC counts the contacts of a clump; two
  // clumps may touch at more than one.
  double coordination = 0.0;
  double mech_coordination = 0.0;   // Thornton's: grains with < 2 contacts left out [-]
  double radial_stress = 0.0;       // lateral wall [Pa]
  double bottom_stress = 0.0, top_stress = 0.0;  // platens [Pa]
  double radius = 0.0, height = 0.0;             // vessel [m]
  double ratio = 0.0;               // mean unbalanced-force ratio [-]
  std::size_t wet_contacts = 0;
  double timestep = 0.0;            // Δt of the last cycle [s]
};

struct PhaseReport {
  std::string name;          // "cloud", "packing", "finalize C5b_Hill", "wet"
  std::int64_t steps = 0;    // cycles
  double seconds = 0.0;      // wall-clock
  SpecimenState state;       // at the end
  // Servo equilibria: the vessel porosity's change per 1,000 steps at the end [-] (its convergence);
  // negative where not measured (the cloud relaxation).
  double porosity_change = -1.0;
  std::string line() const;  // one console line
};

struct Specimen {
  Simulation sim;
  Vessel vessel;
  std::string grading = "C5b";
  double d_mult = 1.0;
  std::uint64_t seed = 0;
  double pressure = 0.0;               // P_m it was packed to [Pa]
  std::string material = "packed";     // what the assignment table holds: "packed", "C5b_Hill", ...
  GrainModel packed_with = GrainModel::Linear;  // the grain-grain model of the packing contacts
  bool wet = false;
  std::vector<PhaseReport> phases;     // genesis history
  // Grains as clumps of these named templates at these solid volume fractions (empty for balls),
  // sized by clump_size; clump_kind: each clump's template, an index into clump_mix, in clump order.
  ClumpMix clump_mix;
  std::vector<std::uint32_t> clump_kind;
  SizeMeasure clump_size = SizeMeasure::EqualVolumeDiameter;
  // The grains' sizes [m]: a ball's diameter; a clump's size by clump_size (the equal-volume
  // diameter (6V/π)^(1/3), or the enclosing diameter 2 max_k(|p_k| + r_k)), clumps first in clump order.
  std::vector<double> diameters() const;
  // Over MPI ranks (docs/mpi.md, "The lab tests over ranks"): the run this process is one rank of, or
  // null (one process). While attached (attach_to_ranks) `sim` is this rank's part, and every
  // reading the drivers take of the balls or contacts is the whole run's, the same bits for any rank
  // count. A copy keeps the pointer and is not attached: attach it on its own.
  RunDecomposition* ranks = nullptr;
  // The whole run's grain count and solid volume [m³], taken when attached (radii do not change).
  std::size_t whole_grains = 0;
  double whole_solid = 0.0;
};

// Whether s.sim is one rank's part of a run over MPI ranks (attached), and rank 0 or no ranks (the
// process that writes files and logs).
bool decomposed(const Specimen& s);
bool is_root(const Specimen& s);
// Make s.sim, the whole run on every rank (the same bits everywhere), this rank's part of it: its
// balls and ghosts to `reach` [m] beyond their surfaces (make_wet's gap when the specimen is to be
// wetted). Nothing when s.ranks is null or s is attached already. InputError for a specimen of
// clumps (the drivers' readings over ranks are made for balls only).
void attach_to_ranks(Specimen& s, double reach);
// Let s go (it keeps this rank's part). Nothing when not attached.
void detach_from_ranks(Specimen& s);
// attach_to_ranks for a scope: detaches when it ends (an exception included), before s ends.
class RanksScope {
 public:
  RanksScope(Specimen& s, double reach) : s_(s) { attach_to_ranks(s, reach); }
  ~RanksScope() { detach_from_ranks(s_); }
  RanksScope(const RanksScope&) = delete;
  RanksScope& operator=(const RanksScope&) = delete;

 private:
  Specimen& s_;
};
// The whole specimen on every rank, detached (gathered with its cycle state to rank 0 and sent to
// every rank as checkpoint bytes: it continues as the whole run would); s is detached. Collective.
// Without ranks, a copy.
Specimen whole_run(Specimen& s);
// Rank 0's f(the whole specimen), on every rank: gathered to rank 0, f computed there, its bytes sent
// to every rank. T trivially copyable. Collective when decomposed; else f(s).
std::string on_whole_run_bytes(const Specimen& s, const std::function<std::string(const Specimen&)>& f);
template <class T, class F>
T on_whole_run(const Specimen& s, F&& f) {
  static_assert(std::is_trivially_copyable_v<T>);
  if (!decomposed(s)) return f(s);
  const std::string bytes = on_whole_run_bytes(s, [&](const Specimen& whole) {
    const T v = f(whole);
    return std::string(reinterpret_cast<const char*>(&v), sizeof v);
  });
  T out;
  std::memcpy(&out, bytes.data(), sizeof out);
  return out;
}
// The mean unbalanced-force ratio of the whole run [-] (Simulation::mean_unbalanced_ratio).
double whole_run_ratio(const Specimen& s);
// The whole run's count of the rows that satisfy pred(store, row): each row counted by the owner of
// its first ball, the counts summed over the ranks (integers: exact in any order).
std::size_t whole_run_rows(const Specimen& s, bool (*pred)(const ContactStore&, std::size_t));

// The grains: the clumps and the balls that are not pebbles.
std::size_t grain_count(const Simulation& sim);
// The grains' solid volume [m³]: 4/3 π r³ per ball that is not a pebble, the union volume m/ρ per
// clump (its pebbles' overlaps counted once: the template's, docs/clumps.md).
double solid_volume(const Simulation& sim);
// Each template's share of the clumps' union volume [-], in the order of s.clump_mix: the mix the
// genesis realised (its target is clump_mix's fractions, to within the largest grain's volume).
std::vector<double> clump_mix_fractions(const Specimen& s);
// "sizes = equal-volume diameter" or "sizes = enclosing diameter", for logs.
const char* to_string(SizeMeasure m);

// The specimen's state; `interior` false skips the measurement-cylinder porosity (set to the vessel's),
// for frequent records.
SpecimenState measure(const Specimen& s, bool interior = true);
// The porosity in region m [-]: 1 − Σ (each grain's volume inside m) / m's volume, a ball's by
// sphere_volume_inside, a clump's by clump_volume_inside (its pebbles' overlaps counted once).
double interior_porosity(const MeasurementCylinder& m, const Simulation& sim);
// The interior porosity as printed: "0.3072" with the D_max margin, "0.3301 (D50 margin)" with the
// smaller one, "n/a (vessel radius under D_max + D50 or height under 2 (D_max + D50))" when it cannot
// be measured. Never "nan".
std::string interior_text(const SpecimenState& s);
// The volume-median diameter D50 of a set of diameters [m] (0 for none).
double volume_median_diameter(std::vector<double> diameters);

// The cloud: grains sampled from the grading for porosity n_c in the vessel and placed at random
// (best of placement_tries positions, largest grains first; overlaps allowed), packing table
// installed, no gravity, local damping α.
Specimen make_cloud(const GenesisSpec& spec);
// Cycles with the walls at rest and grain speeds capped until the cloud's overlaps are gone, then
// sets every velocity to zero.
PhaseReport relax_cloud(Specimen& s, const PackingSettings& p, std::ostream* log);
// Servo-controlled walls to P ± ε_P·P and mean unbalanced-force ratio ≤ ε_lim; walls stopped at the
// end. Throws RunError after max_steps.
PhaseReport servo_equilibrium(Specimen& s, const EquilibriumSettings& e, const std::string& name, std::ostream* log);
// make_cloud + relax_cloud + servo_equilibrium: the packed (frictionless) specimen, packed with
// spec.packing.contact (the material's own model by default). With spec.ranks, the cloud (made
// whole on every rank, from the seed) is relaxed and packed decomposed, and the packed specimen is
// the whole run on every rank, detached (whole_run).
Specimen pack_specimen(const GenesisSpec& spec, std::ostream* log);

// Finalization: grain properties and the material's assignment table installed on every contact
// (friction μ restored), then servo equilibrium at e.pressure (P_m).
PhaseReport finalize(Specimen& s, const Class5Material& m, const WallContact& walls, const EquilibriumSettings& e,
                     std::ostream* log);
// Wet material (lab-tests.md §3.6): make_wet(ψ, g_m) on the finalized hill specimen, then servo
// equilibrium. Throws InputError for a linear material (no liquid bridges).
PhaseReport make_specimen_wet(Specimen& s, double suction, double gap, const EquilibriumSettings& e, std::ostream* log);

}  // namespace hilldem
