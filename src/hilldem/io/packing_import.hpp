// Import of a packing: the LAMMPS data file that shared bench `in.pack` writes (atom_style sphere:
// `id type diameter density x y z`, SI units) or a plain text file of `x y z radius` rows [m].
// Optional replication along x, y, z by the box lengths.
#pragma once

#include <string>
#include <vector>

#include "hilldem/core/vec3.hpp"

namespace hilldem {

struct ImportedBall {
  Vec3 position;         // [m]
  double radius = 0.0;   // [m]
  double density = 0.0;  // [kg/m^3], 0 when the file has none (xyzr)
};

struct Packing {
  std::vector<ImportedBall> balls;
  bool has_box = false;  // LAMMPS files carry the box
  Vec3 box_lo, box_hi;   // [m]
};

enum class PackingFormat { Lammps, Xyzr };

// Throws InputError naming the file and line on any malformed input.
Packing read_packing(const std::string& path, PackingFormat format);
Packing parse_packing(const std::string& text, const std::string& name, PackingFormat format);

// Copies the packing n[0] × n[1] × n[2] times by the box lengths (needs a box).
void replicate(Packing& p, const int n[3]);

// Write a packing as a LAMMPS data file (atom_style sphere, SI), which LAMMPS and hilldem both read:
// the benchmark's two codes then start from the very same bed. Atomic (temporary file + rename).
void write_lammps_data(const std::string& path, const Packing& p, const std::string& title);

}  // namespace hilldem
