// The memo's Class 5 study (docs/spec/hill-model.md §5.3) as one driver: for each case (grading ×
// material, dry or wet) a packed specimen (made once per grading and material, each material packed
// with its own contact model; or loaded), finalization, optional wetting and a triaxial test; per case a CSV history, the realised grading and the genesis log; for
// the study a summary table and the memo's qualitative findings checked with numbers.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "hilldem/labtests/genesis.hpp"
#include "hilldem/labtests/triaxial.hpp"

namespace hilldem {

struct CaseSpec {
  std::string grading = "C5b";  // "C5n", "C5b" or a grading CSV file
  GrainModel model = GrainModel::Hill;
  bool wet = false;
  double confinement = 0.0;     // σ_c of this case [Pa]; 0: StudySettings::triaxial.confinement
  // "C5b_Hill", "C5b_Hill_wet", "<file stem>_Linear"; a case of a confinement sweep ends in its σ_c,
  // "C5b_Hill_100kPa".
  std::string name() const;
};

// Each case once per confinement [Pa] (a sweep; cases in confinement order, each case's order kept).
std::vector<CaseSpec> sweep_confinements(const std::vector<CaseSpec>& cases, const std::vector<double>& confinements);

// The memo's five cases: C5n/C5b × linear/hill, plus C5b hill wet.
std::vector<CaseSpec> memo_cases();

// The memo's vessel [m] (170 mm × 240 mm, Table 7) and AASHTO T 307's specimen for aggregate base
// (152 mm × 305 mm, H/D = 2).
inline constexpr double kMemoVesselRadius = 0.085, kMemoVesselHeight = 0.240;
inline constexpr double kT307VesselRadius = 0.076, kT307VesselHeight = 0.305;
// The default study (StudySettings{} and `hilldem triaxial` without --full or --scale): the memo's
// vessel scaled by kDefaultVesselScale, each grading's scaled up until it holds kDefaultMinGrains
// grains (C5b stays at 0.5: 1,688 grains; C5n gets 0.83: 498), so that a coarse grading is not a
// handful of grains across and the five cases run in minutes (docs/lab-tests.md, Defaults).
inline constexpr double kDefaultVesselScale = 0.5;
inline constexpr int kDefaultMinGrains = 500;
// The genesis defaults in the default study's vessel.
inline GenesisSpec default_study_genesis() {
  GenesisSpec g;
  g.vessel_radius = kDefaultVesselScale * kMemoVesselRadius;
  g.vessel_height = kDefaultVesselScale * kMemoVesselHeight;
  return g;
}

struct StudySettings {
  // Vessel, packing; its grading is replaced by each case's. Default: the default study's vessel.
  GenesisSpec genesis = default_study_genesis();
  // A grading whose expected grain count in genesis's vessel (at the cloud porosity) is below this
  // gets the same vessel shape scaled up until it holds that many (never scaled down); 0: every
  // grading in genesis's vessel. vessel_for says which vessel a grading gets.
  int min_grains = kDefaultMinGrains;
  Class5Material material;              // Table 7; `model` is replaced by each case's
  WallContact test_walls;               // grain-wall contacts after finalization
  EquilibriumSettings finalize;         // servo equilibrium after finalization and wetting (at P_m)
  double suction = 20e3;                // ψ of make_wet [Pa]
  double moisture_gap = 3e-3;           // g_m of make_wet [m]
  // Confinement σ_c: triaxial.confinement. When it differs from the packing pressure P_m, the
  // finalized (and wetted) specimen is first brought to σ_c on every wall by the same servo
  // equilibrium ("confine" phase), so that each test starts isotropic at σ_c.
  TriaxialSettings triaxial;
  // The shared linear packing: every material packed with the frictionless linear
  // packing contacts (genesis.packing.contact's E*, κ*), one packed specimen per grading, the hill
  // model installed only at finalization. A deviation from the memo (lab-tests.md §3.2), kept as an
  // option (`--pack-linear`). Default: each material packed with its own model.
  bool pack_linear = false;
  std::string output_dir = "out/triaxial";
  std::string specimen_file;            // start from this packed specimen instead of packing
  bool save_specimens = true;           // write <output>/specimens/<grading>_packed.csv
  // Cases (and packings) computed at once, each on its own thread with its own Simulation: every case
  // is computed alone from the same inputs, so the results do not depend on it. 0: the number of
  // cores. With more than one, each log line is prefixed with its case's name. Unless 1, the cores
  // are shared: a job runs on cores / running jobs OpenMP threads (at least the caller's count), so
  // that when fewer jobs than cores are left the running ones take the idle cores.
  int jobs = 1;
};
// Every check that can be made before work starts (throws InputError): settings ranges, gradings
// resolvable, wet only with hill, the specimen file readable.
void validate(const StudySettings& s, const std::vector<CaseSpec>& cases);

struct CaseResult {
  CaseSpec spec;
  double confinement = 0.0;             // σ_c of its test [Pa]
  GradingReport grading;
  GrainModel packed_with = GrainModel::Linear;  // grain-grain model of the packing it started from
  std::string clump_template;           // its grains' clump template or mix, clump_mix_text ("" for balls; docs/clumps.md)
  SpecimenState packed;                 // after packing (frictionless)
  SpecimenState initial;                // after finalization (and wetting): the test's start
  std::vector<PhaseReport> phases;      // genesis phases of this case (packing shared by the cases of a grading and packing model)
  TriaxialResult test;
  double seconds = 0.0;                 // finalization + wetting + test, wall clock [s]
  double packing_seconds = 0.0;         // the packing it started from (shared by the cases of a grading) [s]
  std::string dir;                      // output folder of the case
  std::string packing_file;             // the packed specimen it started from ("" if not saved)
};

struct StudyResult {
  std::vector<CaseResult> cases;
  std::string criterion;                // the servo equilibria's convergence criterion in words (criterion_text)
  double seconds = 0.0;                 // wall clock [s]
  double cpu_seconds = 0.0;             // process CPU time, all threads [s]
  std::string summary_csv() const;
  std::string summary_markdown() const;  // the table, the findings and time_markdown()
  // Where the time went: one row per packing (cloud relaxation, servo packing) and per phase of each
  // case (finalize, wet, confine, triaxial test) with its grains, steps, grain-steps (grains × steps:
  // a step's cost grows with the grains), share of all grain-steps and wall-clock seconds. With
  // several jobs at once the seconds of different rows overlap and include the waits for the cores.
  std::string time_markdown() const;
  std::vector<std::string> findings() const;  // the memo's qualitative claims, each with numbers and a verdict
};

// Physically impossible states and results, each with its reason (empty: none found). A state is
// impossible when a wall stress lies more than kStateTolerance × target from the target it was brought
// to (the servos stop within ε_P = 1 %); results are impossible when a loop reverses at q_A ≤ 0 or
// dissipates negative energy (loop area or damping ratio below 0), a fitted M_r is not positive, or
// the peak deviator under compression is not positive. run_study and make_packed throw RunError
// (exit status 1) with these reasons instead of writing a summary.
inline constexpr double kStateTolerance = 0.25;  // [-]
std::vector<std::string> impossible_state(const SpecimenState& st, double target);
std::vector<std::string> impossible_results(const TriaxialResult& r);

// Runs the cases (settings.jobs at once), writing into settings.output_dir as each one ends; progress
// to log (may be null). If a case fails, no new case starts and the error of the first failing case
// (in case order) is thrown once the running ones end.
StudyResult run_study(const StudySettings& settings, const std::vector<CaseSpec>& cases, std::ostream* log);

// Genesis up to the packed specimen (cloud, frictionless packing with `model` contacts) for one
// grading, or the specimen loaded from settings.specimen_file; with save, written to
// <output>/specimens/<grading>_<model>_packed.csv (model: hill or linear) with its realised grading
// (<grading>_<model>_gsd.csv) and genesis report (<grading>_<model>_genesis.txt).
struct PackedResult {
  Specimen specimen;
  GradingReport report;
  SpecimenState state;
  std::string file;     // where it was saved or loaded from
  double seconds = 0.0;
};
PackedResult make_packed(const StudySettings& settings, const std::string& grading, GrainModel model, bool save,
                         std::ostream* log);
// The vessel [m] (radius, height) a grading is packed in: genesis's, scaled up for min_grains.
std::pair<double, double> vessel_for(const StudySettings& settings, const Grading& g);
// Expected grain count of a grading in a vessel of radius R and height H [m] at cloud porosity n_c:
// (1 − n_c) π R² H Σ φ_j / E[V_j], E[V_j] the mean volume of a grain of bin j (diameter uniform).
double expected_grains(const Grading& g, double d_mult, double R, double H, double n_c);
// The σ_c of a case [Pa].
double confinement_of(const StudySettings& settings, const CaseSpec& c);

// The packing model of a case: its material's, or linear with settings.pack_linear.
GrainModel packing_model(const StudySettings& settings, const CaseSpec& c);
// make_packed for each distinct (grading, packing model) of the cases (by resolved name, in case
// order; one per grading when loading settings.specimen_file), settings.jobs at once.
std::vector<PackedResult> make_all_packed(const StudySettings& settings, const std::vector<CaseSpec>& cases, bool save,
                                          std::ostream* log);
// One line per packed specimen: grading, packing model, seed, grains, porosities, coordination, pressures, steps, time.
std::string packing_table(const std::vector<PackedResult>& packed);

}  // namespace hilldem
