// AASHTO T 307 resilient-modulus test (docs/t307.md) on a finalized specimen in the vessel: the
// lateral wall holds σ₃ through the radial servo; the top platen is a stress servo that follows the
// axial target σ₃ + σ_contact + σ_cyclic · haversine(t) (the bottom platen stays fixed, as on a load
// frame). The pulse amplitude commanded to the servo is corrected after every cycle by the ratio of
// the target to the measured cyclic deviator (peak compensation, as on a servo-hydraulic frame; from
// the target itself at each sequence's first cycle), so
// that the measured amplitude reaches σ_cyclic although the servo lags a fast pulse. Per sequence: conditioning or one of the 15 stress states, `cycles` pulses of the
// time-scaled timing; per cycle the recoverable axial and radial strains; per sequence M_r and ν from
// the last `averaged_cycles` cycles, the permanent axial strain, and the fit of the universal model.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "hilldem/labtests/genesis.hpp"
#include "hilldem/labtests/t307_sequences.hpp"
#include "hilldem/labtests/universal_model.hpp"

namespace hilldem {

struct T307Settings {
  T307Timing timing;
  // Run in this order; number 0 is the conditioning (timing.conditioning_cycles pulses, skipped when
  // 0), every other row timing.cycles pulses. Default: the standard's table.
  std::vector<T307Sequence> sequences = t307_base_sequences();
  // The standard stops the test when the total permanent axial strain passes 5 %; so does the driver,
  // after the cycle that passed it [-], in (0, 0.5].
  double max_permanent_strain = 0.05;
  std::int64_t max_steps = 200'000'000;
};
// Throws InputError naming the first bad value (before any work).
void validate(const T307Settings& t);

// One load cycle (pulse + rest). Strains compression positive; "recoverable" = at the cycle's largest
// axial strain minus at its end.
struct T307Cycle {
  int sequence = 0, cycle = 0;  // cycle 1, 2, ...
  double q_peak = 0.0;          // largest deviator q = σ_a − σ_r in the cycle [Pa]
  double q_end = 0.0;           // q at the end of the rest [Pa]
  double sigma_r_peak = 0.0;    // σ_r at the q peak [Pa]
  double recoverable_axial = 0.0;   // [-]
  double recoverable_radial = 0.0;  // [-] (negative: the specimen bulges under the pulse)
  double eps_a_end = 0.0;       // axial strain at the end of the cycle, from the test's start [-]
  double modulus = 0.0;         // (q_peak − q_end) / recoverable_axial [Pa]
  double command = 0.0;         // pulse amplitude commanded to the top platen's servo [Pa]
  double amplitude_error = 0.0; // (q_peak − q_end) / σ_cyclic − 1 [-]
};

struct T307Row {
  T307Sequence nominal;
  int cycles = 0;                  // pulses run
  int averaged = 0;                // cycles in the means below
  double cyclic_stress = 0.0;      // mean q_peak − q_end [Pa]
  double max_deviator = 0.0;       // mean q_peak [Pa]
  double confining = 0.0;          // mean σ_r at the peak [Pa]
  double bulk_stress = 0.0;        // θ = σ_a + 2σ_r at the peak, measured [Pa]
  double octahedral_shear = 0.0;   // τ_oct = (√2/3) q_peak, measured [Pa]
  double recoverable_axial = 0.0;  // mean [-]
  double modulus = 0.0;            // M_r = mean over the averaged cycles of the cycle moduli [Pa]
  double poisson = 0.0;            // ν = −ε_r,rec / ε_a,rec, mean over the averaged cycles [-]
  double permanent_strain = 0.0;   // axial strain accumulated over the sequence's pulses [-]
  double total_permanent_strain = 0.0;  // axial strain since the first sequence after conditioning [-]
  double amplitude_error = 0.0;    // mean over the averaged cycles of (q_peak − q_end)/σ_cyclic − 1 [-]
  std::int64_t steps = 0;
};

struct T307Result {
  std::vector<T307Row> rows;       // conditioning (if run) then the sequences
  std::vector<T307Cycle> cycles;   // every cycle
  bool fitted = false;             // at least 4 sequences (1..15) with M_r > 0
  UniversalFit fit;
  std::string fit_error;           // why not fitted
  bool stopped = false;            // the permanent strain limit was passed: the later sequences did not run
  std::string stop_reason;
  double height0 = 0.0, radius0 = 0.0;  // [m] at the start
  double timestep = 0.0;           // Δt at the end [s]
  std::int64_t steps = 0;
  double seconds = 0.0;
  std::string sequences_csv() const;  // one row per sequence 1..15 (conditioning left out), units in the header
  std::string cycles_csv() const;
  std::string text() const;           // the table and the fit, for the console
};

T307Result run_t307(Specimen& s, const T307Settings& t, std::ostream* log);

}  // namespace hilldem
