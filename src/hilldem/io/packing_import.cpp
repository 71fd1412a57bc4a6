#include "hilldem/io/packing_import.hpp"

#include <cmath>
#include <fmt/format.h>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "hilldem/core/error.hpp"

namespace hilldem {

namespace {

std::string strip_comment(const std::string& line) {
  const auto hash = line.find('#');
  return hash == std::string::npos ? line : line.substr(0, hash);
}

bool blank(const std::string& s) { return s.find_first_not_of(" \t\r") == std::string::npos; }

std::vector<double> numbers(const std::string& line, const std::string& name, int lineno, std::size_t at_least) {
  std::istringstream in(line);
  std::vector<double> v;
  std::string tok;
  while (in >> tok) {
    char* end = nullptr;
    const double x = std::strtod(tok.c_str(), &end);
    if (end == tok.c_str() || *end != '\0' || !std::isfinite(x))
      throw InputError(fmt::format("{}: line {}: '{}' is not a finite number", name, lineno, tok));
    v.push_back(x);
  }
  if (v.size() < at_least)
    throw InputError(fmt::format("{}: line {}: expected at least {} numbers, got {}", name, lineno, at_least, v.size()));
  return v;
}

void check_ball(const ImportedBall& b, const std::string& name, int lineno) {
  if (!(b.radius > 0.0)) throw InputError(fmt::format("{}: line {}: radius must be > 0 m; got {}", name, lineno, b.radius));
  if (b.density < 0.0) throw InputError(fmt::format("{}: line {}: density must be > 0 kg/m^3; got {}", name, lineno, b.density));
}

Packing parse_lammps(const std::string& text, const std::string& name) {
  Packing p;
  std::istringstream in(text);
  std::string raw;
  int lineno = 0;
  long expected = -1;
  bool in_atoms = false;
  bool seen_x = false, seen_y = false, seen_z = false;
  std::getline(in, raw);  // first line is a title
  ++lineno;
  while (std::getline(in, raw)) {
    ++lineno;
    const std::string line = strip_comment(raw);
    if (blank(line)) continue;
    std::istringstream ls(line);
    std::string first;
    ls >> first;
    const bool numeric = std::isdigit(static_cast<unsigned char>(first[0])) || first[0] == '-' || first[0] == '+' || first[0] == '.';
    if (!numeric) {
      // A section header: Atoms, Velocities, Masses ...
      in_atoms = first == "Atoms";
      if (in_atoms && raw.find("sphere") == std::string::npos && raw.find('#') != std::string::npos)
        throw InputError(fmt::format("{}: line {}: only 'Atoms # sphere' (id type diameter density x y z) is supported", name, lineno));
      continue;
    }
    if (in_atoms) {
      const auto v = numbers(line, name, lineno, 7);
      ImportedBall b{{v[4], v[5], v[6]}, 0.5 * v[2], v[3]};
      check_ball(b, name, lineno);
      if (!(b.density > 0.0)) throw InputError(fmt::format("{}: line {}: density must be > 0 kg/m^3", name, lineno));
      p.balls.push_back(b);
      continue;
    }
    if (line.find("atoms") != std::string::npos && line.find("types") == std::string::npos) {
      const double count = numbers(line.substr(0, line.find("atoms")), name, lineno, 1)[0];
      if (!(count >= 0.0 && count <= 5e7 && count == std::floor(count)))
        throw InputError(fmt::format("{}: line {}: the atom count must be a whole number in [0, 5e7]; got {}", name, lineno, count));
      expected = static_cast<long>(count);
    } else if (line.find("xlo xhi") != std::string::npos) {
      const auto v = numbers(line.substr(0, line.find("xlo")), name, lineno, 2);
      p.box_lo.x = v[0], p.box_hi.x = v[1], seen_x = true;
    } else if (line.find("ylo yhi") != std::string::npos) {
      const auto v = numbers(line.substr(0, line.find("ylo")), name, lineno, 2);
      p.box_lo.y = v[0], p.box_hi.y = v[1], seen_y = true;
    } else if (line.find("zlo zhi") != std::string::npos) {
      const auto v = numbers(line.substr(0, line.find("zlo")), name, lineno, 2);
      p.box_lo.z = v[0], p.box_hi.z = v[1], seen_z = true;
    }
    // Other header lines (atom types, velocities of other sections) are ignored.
  }
  p.has_box = seen_x && seen_y && seen_z;
  if (!p.has_box) throw InputError(name + ": the LAMMPS data file has no complete 'xlo xhi / ylo yhi / zlo zhi' box");
  if (expected >= 0 && static_cast<long>(p.balls.size()) != expected)
    throw InputError(fmt::format("{}: the header says {} atoms but the Atoms section has {}", name, expected, p.balls.size()));
  if (p.balls.empty()) throw InputError(name + ": no atoms found (an 'Atoms # sphere' section is required)");
  return p;
}

Packing parse_xyzr(const std::string& text, const std::string& name) {
  Packing p;
  std::istringstream in(text);
  std::string raw;
  int lineno = 0;
  while (std::getline(in, raw)) {
    ++lineno;
    const std::string line = strip_comment(raw);
    if (blank(line)) continue;
    const auto v = numbers(line, name, lineno, 4);
    ImportedBall b{{v[0], v[1], v[2]}, v[3], 0.0};
    check_ball(b, name, lineno);
    p.balls.push_back(b);
  }
  if (p.balls.empty()) throw InputError(name + ": no balls found (rows of 'x y z radius' in m)");
  return p;
}

}  // namespace

Packing parse_packing(const std::string& text, const std::string& name, PackingFormat format) {
  return format == PackingFormat::Lammps ? parse_lammps(text, name) : parse_xyzr(text, name);
}

Packing read_packing(const std::string& path, PackingFormat format) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the packing file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_packing(ss.str(), path, format);
}

void write_lammps_data(const std::string& path, const Packing& p, const std::string& title) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path + ": cannot write");
    out << title << "\n\n" << p.balls.size() << " atoms\n1 atom types\n\n";
    out << fmt::format("{:.17g} {:.17g} xlo xhi\n{:.17g} {:.17g} ylo yhi\n{:.17g} {:.17g} zlo zhi\n\n", p.box_lo.x,
                       p.box_hi.x, p.box_lo.y, p.box_hi.y, p.box_lo.z, p.box_hi.z);
    out << "Atoms # sphere\n\n";
    std::size_t id = 1;
    for (const ImportedBall& b : p.balls)
      out << fmt::format("{} 1 {:.17g} {:.17g} {:.17g} {:.17g} {:.17g}\n", id++, 2.0 * b.radius, b.density, b.position.x,
                         b.position.y, b.position.z);
    out.flush();
    if (!out) throw InputError(path + ": write failed");
  }
  std::filesystem::rename(tmp, path);
}

void replicate(Packing& p, const int n[3]) {
  if (n[0] == 1 && n[1] == 1 && n[2] == 1) return;
  if (!p.has_box) throw InputError("replication needs a box (a LAMMPS data file, or box_min/box_max)");
  const Vec3 l = p.box_hi - p.box_lo;
  std::vector<ImportedBall> out;
  out.reserve(p.balls.size() * n[0] * n[1] * n[2]);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        for (ImportedBall b : p.balls) {
          b.position += Vec3{i * l.x, j * l.y, k * l.z};
          out.push_back(b);
        }
  p.balls = std::move(out);
  p.box_hi = p.box_lo + Vec3{n[0] * l.x, n[1] * l.y, n[2] * l.z};
}

}  // namespace hilldem
