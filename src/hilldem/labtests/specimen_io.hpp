// Saved packed specimens: the state at the end of frictionless packing (before finalization), as a
// text file of settings and `id,x,y,z,radius,...` rows. Contact forces of the packing contacts are
// functions of the positions and grain properties alone (linear or hill, frictionless, no dashpot
// with the default γ_h = 0), so a loaded specimen is the saved one: finalization, wetting and tests
// can start from it without repacking. The file says which model packed it (`packing_model`;
// files without that key were packed with linear contacts).
#pragma once

#include <string>

#include "hilldem/labtests/genesis.hpp"

namespace hilldem {

// Throws InputError unless s is a packed (not finalized) specimen; RunError if the file cannot be written.
void save_packed_specimen(const Specimen& s, const PackingSettings& p, const std::string& path);
std::string packed_specimen_text(const Specimen& s, const PackingSettings& p);

// Throws InputError naming the file, line and value on malformed input. The packing contact and wall
// settings stored in the file are written to *p when p is not null.
Specimen load_packed_specimen(const std::string& path, PackingSettings* p = nullptr);
Specimen parse_packed_specimen(const std::string& text, const std::string& source, PackingSettings* p = nullptr);

}  // namespace hilldem
