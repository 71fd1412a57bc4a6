// AASHTO T 307 resilient-modulus protocol for base and subbase materials (docs/spec/lab-tests.md §5,
// docs/t307.md): a conditioning sequence, then 15 sequences of confining pressure σ₃ and maximum
// axial (deviator) stress σ_max, each applied as haversine pulses of σ_cyclic = 0.9 σ_max on a contact
// stress σ_contact = 0.1 σ_max. The standard's 0.1 s pulses and 100 cycles per sequence are out of
// reach of explicit DEM (Δt ≈ 1e-6 s), so the driver runs a time-scaled variant (T307Timing).
#pragma once

#include <string>
#include <vector>

namespace hilldem {

inline constexpr double kAtmosphericPressure = 101.325e3;  // p_a [Pa], the universal model's reference

struct T307Sequence {
  int number = 0;           // 0: conditioning, 1..15
  double confining = 0.0;   // σ₃ [Pa]
  double max_stress = 0.0;  // σ_max: the maximum axial stress above σ₃, i.e. the peak deviator [Pa]
  double cyclic = 0.0;      // σ_cyclic: the haversine amplitude [Pa]
  double contact = 0.0;     // σ_contact: the deviator held between pulses [Pa]
  int standard_cycles = 0;  // load repetitions in the standard (conditioning: 500–1000, here 500)
  // At the peak of the pulse (σ₁ = σ₃ + σ_max, σ₂ = σ₃): θ = σ₁ + σ₂ + σ₃ = 3σ₃ + σ_max [Pa],
  // τ_oct = (√2/3)(σ₁ − σ₃) = (√2/3) σ_max [Pa].
  double bulk_stress() const;
  double octahedral_shear() const;
};

// The standard's table for base and subbase materials, in kPa as tabulated (the psi values of the
// standard, 3–20 psi confining, converted and rounded to 0.1 kPa), returned in Pa: row 0 the
// conditioning, rows 1–15 the sequences.
std::vector<T307Sequence> t307_base_sequences();

// The time-scaled variant (docs/t307.md). A cycle is a haversine pulse of `pulse_duration` then a
// rest at the contact stress of `rest_duration`. Before each sequence the specimen is brought to the
// sequence's σ₃ and contact stress and held there for `settle_duration`. The standard: 0.1 s pulse,
// 0.9 s rest, 100 cycles (500–1000 conditioning), M_r averaged over the last 5.
struct T307Timing {
  double pulse_duration = 2e-3;      // haversine load pulse [s], in [1e-5, 1]
  double rest_duration = 1e-3;       // rest at σ_contact after each pulse [s], in [0, 10]
  double settle_duration = 2e-3;     // hold at σ₃, σ_contact before a sequence's first pulse [s], in [0, 10]
  int cycles = 10;                   // pulses per sequence, in [1, 100]
  int conditioning_cycles = 20;      // pulses of the conditioning sequence, in [0, 1000] (0: none)
  int averaged_cycles = 5;           // M_r, ν: the mean over the last this many cycles, in [1, cycles]
  double servo_gain = 0.5;           // α_s of the axial and radial servos [-], in (0, 1]
  double wall_speed_limit = 1.0;     // servo speed cap [m/s], in (0, 100]
};
// Throws InputError naming the first bad field, its range and its value.
void validate(const T307Timing& t);

// The haversine pulse shape: (1 − cos(2π t/T))/2 for 0 ≤ t ≤ T, 0 outside [-].
double haversine(double t, double duration);

}  // namespace hilldem
