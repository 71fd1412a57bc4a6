// Servo-controlled triaxial test (docs/spec/lab-tests.md §4) on a finalized specimen: the lateral
// wall holds the confinement σ_c through the radial servo; the platens move toward each other, each
// at ½ ε̇ H₀ (strain control), with load-unload cycles at given axial strains and a final monotonic
// load. Records stresses, strains, porosity and coordination; computes, per cycle, the resilient
// modulus (a least-squares fit over the middle of the unload branch, with its standard error; the
// two-point unload secant beside it), the reload fit and secant, and the loop hysteresis.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "hilldem/labtests/genesis.hpp"
#include "hilldem/labtests/line_fit.hpp"

namespace hilldem {

struct TriaxialSettings {
  double confinement = 150e3;                   // σ_c [Pa]
  std::vector<double> cycle_strains{2e-4, 5e-4};  // ε_a at which each unloading starts [-], increasing
  double unload_fraction = 0.1;                 // unload until q ≤ this × q at the reversal [-] [ours]
  double final_strain = 0.01;                   // monotonic loading after the cycles, to this ε_a [-] [ours]
  double strain_rate = 0.02;                    // ε̇ during the cycles [1/s]
  double final_strain_rate = 0.1;               // ε̇ after the last cycle [1/s]
  double servo_gain = 0.5;                      // α_s of the radial servo [-]
  double wall_speed_limit = 1.0;                // radial servo speed cap [m/s]
  double cycle_record_strain = 0.0;             // history row every this much ε_a in the cycles [-]; 0: 1/100 of the first cycle strain
  int final_records = 500;                      // history rows of the final loading
  // Density scaling (docs/performance.md): 0 = off (automatic Δt, real masses); F ≥ 1: a fixed
  // Δt = F × the automatic Δt at the start of the test, each grain's inertia raised as that Δt needs.
  // F times fewer steps at the same strain rate; the grains respond as under an F times faster load.
  double density_scaling = 0.0;                 // F [-], 0 or [1, 50]
  std::int64_t max_steps = 100'000'000;
};
// Throws InputError naming the first bad value (before any work).
void validate(const TriaxialSettings& t);

enum class TriaxialPhase : std::uint8_t { Load, Unload, Reload, Final };
const char* to_string(TriaxialPhase p);

// The part of a branch the moduli are fitted over: the points whose q lies in the middle of the
// branch's deviator range, kFitTrim × (q_A − q_B) away from either end (unload: q_B .. q_A; reload:
// q_B .. q_C). That leaves out the ringing right after each reversal and the turn at the branch's end.
inline constexpr double kFitTrim = 0.1;  // [-]

// One load-unload-reload loop: A = reversal (start of unloading), B = end of unloading, C = the reload
// path back at ε_A.
struct LoopResult {
  int cycle = 0;                      // 1, 2, ...
  double target_strain = 0.0;         // ε_a at which unloading was asked to start [-]
  double eps_a = 0.0, q_a = 0.0;      // A [-], [Pa]
  double eps_b = 0.0, q_b = 0.0;      // B
  double q_c = 0.0;                   // C: q on reloading at ε_A [Pa]
  bool closed = false;                // the reload reached ε_A
  // M_r, the resilient modulus: slope dq/dε_a of the least-squares line through the unload points in
  // the fitted part (kFitTrim), with its standard error (line_fit.hpp) [Pa]. unload.valid is false
  // when that part has fewer than 3 points.
  LineFit unload;
  LineFit reload;                     // the same over the reload branch, up to ε_A [Pa]
  double unload_secant = 0.0;         // (q_A − q_B)/(ε_A − ε_B) [Pa]: the two-point secant
  double reload_secant = 0.0;         // (q_C − q_B)/(ε_A − ε_B) [Pa]
  double loop_area = 0.0;             // ∮ q dε_a over A→B→C [J/m³ = Pa]: energy dissipated per unit volume
  double damping_ratio = 0.0;         // loop_area / (4π W_s), W_s = (q_A − q_B)(ε_A − ε_B)/8 [-]
};

// Builds the loops from the q–ε_a path, point by point (the driver feeds every cycle of the engine).
class LoopTracker {
 public:
  void add(TriaxialPhase phase, int cycle, double strain, double q);
  // The loops so far (an unclosed last loop is included, with closed = false).
  std::vector<LoopResult> loops() const;

 private:
  void close_current();
  std::vector<LoopResult> done_;
  LoopResult cur_;
  bool open_ = false;
  bool have_prev_ = false;
  TriaxialPhase prev_phase_ = TriaxialPhase::Load;
  double prev_strain_ = 0.0, prev_q_ = 0.0;
  std::vector<double> unload_e_, unload_q_, reload_e_, reload_q_;  // the current loop's branches
};

// The fit over the part of a branch (ε, q in path order) whose q lies in [lo, hi].
LineFit fit_branch(const std::vector<double>& strain, const std::vector<double>& q, double lo, double hi);

struct TriaxialRow {
  std::int64_t step = 0;
  double time = 0.0;           // [s] since the test started
  TriaxialPhase phase = TriaxialPhase::Load;
  int cycle = 0;
  double eps_a = 0.0, eps_r = 0.0, eps_v = 0.0;   // compression positive [-]
  double sigma_a = 0.0, sigma_r = 0.0, q = 0.0;   // [Pa]
  double sigma_top = 0.0, sigma_bottom = 0.0;     // [Pa]
  double porosity = 0.0, coordination = 0.0;      // [-]
  double platen_mismatch = 0.0;                   // |σ_top − σ_bottom| / σ_a [-]
};

struct TriaxialResult {
  std::vector<TriaxialRow> history;
  std::vector<LoopResult> loops;
  double height0 = 0.0, radius0 = 0.0;            // [m] at the start
  double peak_q = 0.0, peak_strain = 0.0;         // [Pa], [-]
  double peak_radial_strain = 0.0, peak_volumetric_strain = 0.0;  // ε_r, ε_v at the peak [-] (compression positive)
  double worst_confinement_error = 0.0;           // max |σ_r − σ_c| / σ_c over every cycle [-]
  double worst_confinement_strain = 0.0;          // ε_a where it happened
  double worst_platen_mismatch = 0.0;             // max |σ_top − σ_bottom| / σ_a over every cycle [-]
  double worst_mismatch_strain = 0.0;
  std::int64_t steps = 0;
  double seconds = 0.0;
  std::string history_csv() const;
  std::string loops_text() const;                 // one labelled line per loop
};

// A fitted modulus as printed: "243.1 +- 2.3" [MPa] (slope +- standard error), or "n/a (2 points in
// the fitted part)".
std::string fit_text(const LineFit& f);

TriaxialResult run_triaxial(Specimen& s, const TriaxialSettings& t, std::ostream* log);

}  // namespace hilldem
