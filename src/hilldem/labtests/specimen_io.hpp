// Saved packed specimens: the state at the end of frictionless packing (before finalization), as a
// text file of settings and `id,x,y,z,radius,...` rows. Contact forces of the packing contacts are
// functions of the positions and grain properties alone (linear or hill, frictionless, no dashpot
// with the default γ_h = 0), so a loaded specimen is the saved one: finalization, wetting and tests
// can start from it without repacking. The file says which model packed it (`packing_model`;
// files without that key were packed with linear contacts). A specimen of clumps names its template
// or mix (`clump_template`: clump_mix_text) and size measure (`clump_size`) and has one row per
// clump: its first pebble's ball id, its template, centre of mass, orientation quaternion, scale of
// the unit template and pebble properties; it loads bitwise (centres, orientations, pebbles, each
// clump's template) as saved. Files of one template without the template column (written before
// mixes) load as that template's.
#pragma once

#include <string>

#include "hilldem/labtests/genesis.hpp"

namespace hilldem {

// Throws InputError unless s is a packed (not finalized) specimen; RunError if the file cannot be written.
void save_packed_specimen(const Specimen& s, const PackingSettings& p, const std::string& path);
std::string packed_specimen_text(const Specimen& s, const PackingSettings& p);

// What a grain of a specimen file may be: outside these a file is refused (InputError naming the file,
// the line, the column, the range and the value), as a scenario is. The ranges bound real grains
// (radius 1 µm .. 1 m; density of pumice to osmium; E of soft rubber to diamond; ν of an isotropic
// elastic solid), and a packed state: two grains overlap by at most kMaxOverlap of the smaller one's
// diameter (a packing at P_m overlaps by ~1e-4 .. 1e-3 of it), no two share a centre, no grain
// reaches beyond a wall by more than kMaxOverlap of its diameter.
inline constexpr double kMinGrainRadius = 1e-6, kMaxGrainRadius = 1.0;       // [m]
inline constexpr double kMinGrainDensity = 100, kMaxGrainDensity = 25'000;   // [kg/m³]
inline constexpr double kMinGrainModulus = 1e5, kMaxGrainModulus = 1.2e12;   // E [Pa]
inline constexpr double kMinPoisson = -1.0, kMaxPoisson = 0.5;               // ν [-], (−1, 0.5]
inline constexpr double kMaxOverlap = 0.01;                                   // [-] of the smaller diameter

// Throws InputError naming the file, line and value on malformed input or a grain out of range. The packing contact and wall
// settings stored in the file are written to *p when p is not null.
Specimen load_packed_specimen(const std::string& path, PackingSettings* p = nullptr);
Specimen parse_packed_specimen(const std::string& text, const std::string& source, PackingSettings* p = nullptr);

}  // namespace hilldem
