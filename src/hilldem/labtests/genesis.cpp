#include "hilldem/labtests/genesis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <numeric>
#include <ostream>
#include <unordered_map>

#include "hilldem/bodies/clump_shapes.hpp"
#include "hilldem/control/controller_scope.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/io/checkpoint.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/state_io.hpp"
#include "hilldem/labtests/measure_region.hpp"

namespace hilldem {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Grid hash of placed grains for the cloud (cell = largest diameter).
class PlacementGrid {
 public:
  PlacementGrid(double radius, double height, double cell) : cell_(cell) {
    n_[0] = n_[1] = std::max(1, static_cast<int>(std::ceil(2 * radius / cell)));
    n_[2] = std::max(1, static_cast<int>(std::ceil(height / cell)));
    lo_ = Vec3{-radius, -radius, 0.0};
    cells_.resize(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2]);
  }
  void insert(std::size_t i, const Vec3& x) { cells_[index(coords(x))].push_back(static_cast<std::uint32_t>(i)); }
  // Σ of overlap depths of a grain (x, r) with the placed grains.
  double overlap(const Vec3& x, double r, const std::vector<Vec3>& pos, const std::vector<double>& rad) const {
    const auto c = coords(x);
    double sum = 0.0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int q[3] = {c[0] + dx, c[1] + dy, c[2] + dz};
          if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= n_[0] || q[1] >= n_[1] || q[2] >= n_[2]) continue;
          for (std::uint32_t j : cells_[index({q[0], q[1], q[2]})]) {
            const double d = norm(pos[j] - x), ov = r + rad[j] - d;
            if (ov > 0.0) sum += ov;
          }
        }
    return sum;
  }

 private:
  std::array<int, 3> coords(const Vec3& x) const {
    std::array<int, 3> c{};
    for (int d = 0; d < 3; ++d) c[d] = std::clamp(static_cast<int>((x[d] - lo_[d]) / cell_), 0, n_[d] - 1);
    return c;
  }
  std::size_t index(const std::array<int, 3>& c) const {
    return (static_cast<std::size_t>(c[2]) * n_[1] + c[1]) * n_[0] + c[0];
  }
  double cell_;
  int n_[3];
  Vec3 lo_;
  std::vector<std::vector<std::uint32_t>> cells_;
};

void check_range(bool ok, const std::string& what, double value, const std::string& range) {
  if (!ok) throw InputError(fmt::format("{} must be {}, got {:g}", what, range, value));
}

}  // namespace

void validate(const GenesisSpec& s) {
  validate_grading(s.grading);
  const PackingSettings& p = s.packing;
  const EquilibriumSettings& e = p.equilibrium;
  check_range(s.d_mult > 0 && std::isfinite(s.d_mult), "diameter multiplier", s.d_mult, "> 0");
  check_range(s.vessel_radius > 0 && std::isfinite(s.vessel_radius), "vessel radius [m]", s.vessel_radius, "> 0");
  check_range(s.vessel_height > 0 && std::isfinite(s.vessel_height), "vessel height [m]", s.vessel_height, "> 0");
  check_range(p.cloud_porosity > 0 && p.cloud_porosity < 1, "cloud porosity", p.cloud_porosity, "in (0, 1)");
  check_range(p.local_damping >= 0 && p.local_damping < 1, "local damping", p.local_damping, "in [0, 1)");
  check_range(p.contact.fric >= 0 && std::isfinite(p.contact.fric), "packing friction", p.contact.fric, ">= 0");
  check_range(p.contact.damp_con >= 0 && p.contact.damp_con < 1, "packing hill damping", p.contact.damp_con, "in [0, 1)");
  check_range(p.contact.emod > 0 && std::isfinite(p.contact.emod), "packing E* [Pa]", p.contact.emod, "> 0");
  check_range(p.contact.kratio > 0 && std::isfinite(p.contact.kratio), "packing kratio", p.contact.kratio, "> 0");
  check_range(s.grain.density > 0 && std::isfinite(s.grain.density), "grain density [kg/m3]", s.grain.density, "> 0");
  check_range(s.grain.young_mod > 0 && std::isfinite(s.grain.young_mod), "grain Young's modulus [Pa]", s.grain.young_mod, "> 0");
  check_range(s.grain.pois_ratio > -1 && s.grain.pois_ratio <= 0.5, "grain Poisson's ratio", s.grain.pois_ratio, "in (-1, 0.5]");
  check_range(e.pressure > 0 && std::isfinite(e.pressure), "pressure [Pa]", e.pressure, "> 0");
  check_range(e.pressure_tolerance > 0 && e.pressure_tolerance < 1, "pressure tolerance", e.pressure_tolerance, "in (0, 1)");
  check_range(e.ratio > 0 && e.ratio < 1, "equilibrium ratio", e.ratio, "in (0, 1)");
  check_range(e.servo_gain > 0 && e.servo_gain <= 1, "servo gain", e.servo_gain, "in (0, 1]");
  check_range(e.wall_speed_limit > 0 && std::isfinite(e.wall_speed_limit), "wall speed limit [m/s]", e.wall_speed_limit, "> 0");
  check_range(e.porosity_change > 0 && e.porosity_change < 1, "porosity change per 1,000 steps", e.porosity_change, "in (0, 1)");
  check_range(e.porosity_window >= 1000, "porosity window [steps]", static_cast<double>(e.porosity_window), ">= 1000");
  check_clump_mix(s.clump_mix, "clump templates");  // names the known templates, the fractions' range and sum
  double d_max = 0.0;
  for (const GradingBin& b : s.grading.bins) d_max = std::max(d_max, b.d_upper * s.d_mult);
  if (d_max >= std::min(2 * s.vessel_radius, s.vessel_height))
    throw InputError(fmt::format("the largest grain ({:g} mm) does not fit in the vessel ({:g} mm x {:g} mm)",
                                 d_max * 1e3, 2e3 * s.vessel_radius, 1e3 * s.vessel_height));
}

const char* to_string(SizeMeasure m) {
  return m == SizeMeasure::EnclosingDiameter ? "sizes = enclosing diameter" : "sizes = equal-volume diameter";
}

namespace {
// Each clump's union volume [m³]: its mass over its pebbles' density (ρV / ρ).
std::vector<double> clump_volumes(const Simulation& sim) {
  const ClumpBodies& c = sim.clumps;
  std::vector<double> v(c.size(), 0.0);
  for (std::size_t k = 0; k < c.pebbles.size(); ++k) {
    const std::uint32_t i = c.pebbles.clump[k];
    if (v[i] == 0.0) v[i] = c.state.mass[i] / sim.balls.density[c.ball[k]];
  }
  return v;
}
}  // namespace

std::size_t grain_count(const Simulation& sim) { return sim.balls.size() - sim.clumps.pebbles.size() + sim.clumps.size(); }

double solid_volume(const Simulation& sim) {
  double solid = 0.0;
  if (sim.clumps.empty()) {
    for (double r : sim.balls.radius) solid += 4.0 / 3.0 * std::numbers::pi * r * r * r;
    return solid;
  }
  const std::vector<std::uint32_t> of = sim.clumps.clump_of_balls(sim.balls.size());
  for (double v : clump_volumes(sim)) solid += v;
  for (std::size_t i = 0; i < sim.balls.size(); ++i)
    if (of[i] == kNoClump) solid += 4.0 / 3.0 * std::numbers::pi * sim.balls.radius[i] * sim.balls.radius[i] * sim.balls.radius[i];
  return solid;
}

std::string criterion_text(const EquilibriumSettings& e) {
  return fmt::format("every wall within {:g} % of {:g} kPa, mean unbalanced-force ratio (per body) <= {:g}, vessel porosity "
                     "changing by <= {:g} per 1,000 steps over the last {} steps (checked every {} steps)",
                     100 * e.pressure_tolerance, e.pressure / 1e3, e.ratio, e.porosity_change, e.porosity_window, e.check_every);
}

void PorosityHistory::add(std::int64_t step, double porosity) {
  samples_.emplace_back(step, porosity);
  // Keep the newest sample at least a window old and everything after it.
  std::size_t keep = 0;
  for (std::size_t i = 0; i < samples_.size(); ++i)
    if (samples_[i].first <= step - window_) keep = i;
  if (keep > 0) samples_.erase(samples_.begin(), samples_.begin() + static_cast<std::ptrdiff_t>(keep));
}

bool PorosityHistory::change_per_1000(double& out) const {
  if (samples_.size() < 2) return false;
  const auto& [s1, n1] = samples_.back();
  const auto& [s0, n0] = samples_.front();
  if (s1 - s0 < window_ || s1 <= s0) return false;
  out = std::abs(n1 - n0) * 1000.0 / static_cast<double>(s1 - s0);
  return true;
}

bool PorosityHistory::converged(double tolerance) const {
  double c = 0.0;
  return change_per_1000(c) && c <= tolerance;
}

std::string interior_text(const SpecimenState& s) {
  switch (s.interior_margin) {
    case SpecimenState::Margin::DMax: return fmt::format("{:.4f}", s.interior_porosity);
    case SpecimenState::Margin::D50: return fmt::format("{:.4f} (D50 margin)", s.interior_porosity);
    case SpecimenState::Margin::None: break;
  }
  return "n/a (vessel radius under D_max + D50 or height under 2 (D_max + D50))";
}

double volume_median_diameter(std::vector<double> d) {
  if (d.empty()) return 0.0;
  std::sort(d.begin(), d.end());
  double total = 0.0;
  for (double x : d) total += x * x * x;
  double sum = 0.0;
  for (double x : d) {
    sum += x * x * x;
    if (sum >= 0.5 * total) return x;
  }
  return d.back();
}

std::string PhaseReport::line() const {
  return fmt::format("{:<22} {:>8} steps {:>7.1f} s  n {:.4f} (interior {})  Z {:.3f}  sigma_r {:.2f} kPa  sigma_bottom {:.2f} kPa  "
                     "sigma_top {:.2f} kPa  ratio {:.2e}{}",
                     name, steps, seconds, state.porosity, interior_text(state), state.coordination, state.radial_stress / 1e3,
                     state.bottom_stress / 1e3, state.top_stress / 1e3, state.ratio,
                     porosity_change >= 0 ? fmt::format("  dn {:.1e} per 1000 steps", porosity_change) : std::string());
}

std::vector<double> Specimen::diameters() const {
  if (sim.clumps.empty()) {
    std::vector<double> d(sim.balls.size());
    for (std::size_t i = 0; i < d.size(); ++i) d[i] = 2.0 * sim.balls.radius[i];
    return d;
  }
  const ClumpBodies& c = sim.clumps;
  std::vector<double> d;
  if (clump_size == SizeMeasure::EnclosingDiameter) {
    d.assign(c.size(), 0.0);
    for (std::size_t k = 0; k < c.pebbles.size(); ++k) {
      double& x = d[c.pebbles.clump[k]];
      x = std::max(x, 2.0 * (norm(c.pebbles.body_position[k]) + c.pebbles.radius[k]));
    }
  } else {
    for (double v : clump_volumes(sim)) d.push_back(std::cbrt(6.0 * v / std::numbers::pi));
  }
  const std::vector<std::uint32_t> of = c.clump_of_balls(sim.balls.size());
  for (std::size_t i = 0; i < sim.balls.size(); ++i)
    if (of[i] == kNoClump) d.push_back(2.0 * sim.balls.radius[i]);
  return d;
}

double interior_porosity(const MeasurementCylinder& m, const Simulation& sim) {
  if (sim.clumps.empty()) return region_porosity(m, sim.balls.position, sim.balls.radius);
  const ClumpBodies& c = sim.clumps;
  const std::vector<double> volume = clump_volumes(sim);
  double solid = 0.0;
  std::vector<Vec3> centres;
  std::vector<double> radii;
  for (std::size_t k = 0; k < c.pebbles.size();) {  // the pebbles of a clump are consecutive (ClumpBodies::add)
    const std::uint32_t i = c.pebbles.clump[k];
    centres.clear();
    radii.clear();
    for (; k < c.pebbles.size() && c.pebbles.clump[k] == i; ++k) {
      centres.push_back(sim.balls.position[c.ball[k]]);
      radii.push_back(sim.balls.radius[c.ball[k]]);
    }
    solid += clump_volume_inside(m, centres, radii, volume[i]);
  }
  const std::vector<std::uint32_t> of = c.clump_of_balls(sim.balls.size());
  for (std::size_t b = 0; b < sim.balls.size(); ++b)
    if (of[b] == kNoClump) solid += sphere_volume_inside(m, sim.balls.position[b], sim.balls.radius[b]);
  const double v = m.volume();
  return v > 0.0 ? 1.0 - solid / v : 0.0;
}

// ---- over MPI ranks (docs/mpi.md, "The lab tests over ranks") ----

bool decomposed(const Specimen& s) { return s.ranks && s.sim.domain; }
bool is_root(const Specimen& s) { return !s.ranks || s.ranks->rank() == 0; }

void attach_to_ranks(Specimen& s, double reach) {
  if (!s.ranks || s.sim.domain) return;
  // Taken here, on the whole run: a rank's balls (owned and ghosts) are not the grains.
  s.whole_grains = grain_count(s.sim);
  s.whole_solid = solid_volume(s.sim);
  s.ranks->attach(s.sim, reach);
}

void detach_from_ranks(Specimen& s) {
  if (decomposed(s)) s.ranks->detach();
}

Specimen whole_run(Specimen& s) {
  if (!decomposed(s)) return s;
  RunDecomposition& r = *s.ranks;
  // With the cycle state, as a checkpoint of a decomposed run is written and resumed: the copy
  // continues as the whole run would, attached again or not.
  const Simulation gathered = r.gather(true);
  std::string bytes;
  if (r.rank() == 0) {
    CheckpointWriter w;
    write_simulation(w, gathered);
    bytes = w.bytes();
  }
  bytes = r.from_root(bytes);
  r.detach();
  Specimen out = s;  // (the metadata; its sim, this rank's part, is replaced)
  read_simulation(CheckpointReader::from_bytes(std::move(bytes), "the gathered specimen"), out.sim);
  out.sim.interrupt = s.sim.interrupt;
  return out;
}

std::string on_whole_run_bytes(const Specimen& s, const std::function<std::string(const Specimen&)>& f) {
  RunDecomposition& r = *s.ranks;
  Simulation gathered = r.gather(false);
  std::string bytes;
  if (r.rank() == 0) {
    Specimen whole = s;  // (the metadata; this rank's part replaced by the whole run)
    whole.sim = std::move(gathered);
    whole.ranks = nullptr;
    bytes = f(whole);
  }
  return r.from_root(bytes);
}

double whole_run_ratio(const Specimen& s) {
  if (!decomposed(s)) return s.sim.mean_unbalanced_ratio();
  return on_whole_run<double>(s, [](const Specimen& w) { return w.sim.mean_unbalanced_ratio(); });
}

std::size_t whole_run_rows(const Specimen& s, bool (*pred)(const ContactStore&, std::size_t)) {
  const ContactStore& c = s.sim.contacts;
  const bool ranks = decomposed(s);
  std::uint64_t n = 0;
  for (std::size_t k = 0; k < c.size(); ++k) n += pred(c, k) && (!ranks || s.ranks->owns(c.key[k].a));
  return static_cast<std::size_t>(ranks ? s.ranks->sum(n) : n);
}

namespace {
// The largest over the ranks of x ≥ 0: non-negative doubles order as their bit patterns do as
// integers, so an integer maximum gives it exactly.
double max_over_ranks(const Specimen& s, double x) {
  if (!decomposed(s)) return x;
  return std::bit_cast<double>(s.ranks->max(std::bit_cast<std::int64_t>(x)));
}
}  // namespace

SpecimenState measure(const Specimen& s, bool interior) {
  if (decomposed(s)) return on_whole_run<SpecimenState>(s, [interior](const Specimen& w) { return measure(w, interior); });
  const Simulation& sim = s.sim;
  SpecimenState st;
  st.grains = grain_count(sim);
  const double solid = solid_volume(sim);
  const std::vector<double> sizes = s.diameters();
  st.radius = s.vessel.radius(sim);
  st.height = s.vessel.height(sim);
  st.porosity = 1.0 - solid / s.vessel.volume(sim);
  if (interior) {
    double d_max = 0.0;
    for (double d : sizes) d_max = std::max(d_max, d);
    // The region must hold at least one D_max in radius and two in height. Margin D_max from every
    // wall; failing that (a small vessel) D50; failing that there is no interior to measure.
    auto region = [&](double margin) {
      return MeasurementCylinder{st.radius - margin, s.vessel.bottom_z(sim) + margin, s.vessel.top_z(sim) - margin};
    };
    auto fits = [&](const MeasurementCylinder& m) { return m.radius >= d_max && m.z_hi - m.z_lo >= 2.0 * d_max; };
    st.interior_margin = SpecimenState::Margin::None;
    st.interior_porosity = std::numeric_limits<double>::quiet_NaN();
    if (d_max > 0.0 && fits(region(d_max))) {
      st.interior_margin = SpecimenState::Margin::DMax;
      st.interior_margin_length = d_max;
    } else if (const double d50 = volume_median_diameter(sizes); d50 > 0.0 && fits(region(d50))) {
      st.interior_margin = SpecimenState::Margin::D50;
      st.interior_margin_length = d50;
    }
    if (st.interior_margin != SpecimenState::Margin::None)
      st.interior_porosity = interior_porosity(region(st.interior_margin_length), sim);
  } else {
    st.interior_porosity = st.porosity;  // not measured: the vessel's
  }
  // Contacts per grain: a pebble's count as its clump's (grains: clumps first, then the other balls).
  const std::vector<std::uint32_t> of = sim.clumps.clump_of_balls(sim.balls.size());
  std::vector<std::uint32_t> grain_of(sim.balls.size());
  {
    std::uint32_t next = static_cast<std::uint32_t>(sim.clumps.size());
    for (std::size_t i = 0; i < grain_of.size(); ++i) grain_of[i] = of.empty() ? static_cast<std::uint32_t>(i) : of[i] != kNoClump ? of[i] : next++;
  }
  std::vector<std::uint32_t> per_ball(st.grains, 0);
  std::size_t touching = 0;
  for (std::size_t c = 0; c < sim.contacts.size(); ++c) {
    if (!sim.contacts.exists[c]) continue;
    const ContactKey& k = sim.contacts.key[c];
    if (k.kind == ContactKind::BallBall && sim.contacts.model[c] == ModelKind::Hill &&
        sim.contacts.moisture[c] == Moisture::Wet)
      ++st.wet_contacts;
    if (k.kind != ContactKind::BallBall || !sim.contacts.active[c] || sim.contacts.gap[c] >= 0.0) continue;
    ++touching;
    ++per_ball[grain_of[k.a]];
    ++per_ball[grain_of[k.b]];
  }
  if (st.grains > 0) st.coordination = 2.0 * static_cast<double>(touching) / static_cast<double>(st.grains);
  std::size_t n0 = 0, n1 = 0;
  for (std::uint32_t z : per_ball) n0 += z == 0, n1 += z == 1;
  if (st.grains > n0 + n1)
    st.mech_coordination = (2.0 * static_cast<double>(touching) - static_cast<double>(n1)) /
                           static_cast<double>(st.grains - n0 - n1);
  st.radial_stress = s.vessel.radial_stress(sim);
  st.bottom_stress = s.vessel.bottom_stress(sim);
  st.top_stress = s.vessel.top_stress(sim);
  st.ratio = sim.mean_unbalanced_ratio();
  st.timestep = sim.last_dt;
  return st;
}

Specimen make_cloud(const GenesisSpec& spec) {
  validate(spec);
  const PackingSettings& p = spec.packing;
  Specimen s;
  s.grading = spec.grading.name;
  s.d_mult = spec.d_mult;
  s.seed = p.seed;
  s.pressure = p.equilibrium.pressure;
  s.packed_with = p.contact.model;
  s.ranks = spec.ranks;
  Simulation& sim = s.sim;
  sim.interrupt = spec.interrupt;
  sim.settings.local_damping = p.local_damping;
  sim.settings.auto_timestep = true;
  const std::uint64_t grain_bit = sim.groups.bit(kGrainGroup);
  const std::uint64_t vessel_bit = sim.groups.bit(kVesselGroup);
  const double R = spec.vessel_radius, H = spec.vessel_height;
  s.vessel = add_vessel(sim, R, H, vessel_bit);

  Rng rng(p.seed);
  const double volume = std::numbers::pi * R * R * H;
  const Class5Material& grain_defaults = spec.grain;  // density, E, ν until finalization sets the material
  const bool clumps = !spec.clump_mix.empty();
  s.clump_mix = spec.clump_mix;
  s.clump_size = spec.clump_size;
  // Per template: its unit (as named_template makes it), its volume factor f and its enclosing diameter per
  // size. A clump of size d by the chosen measure has volume f π d³/6: f = 1 for the equal-volume
  // diameter, below 1 for the enclosing one. The grading is sampled for the sphere volume
  // Σ_t (1 − n_c) V_vessel w_t / f_t (w_t the template's solid fraction), so that the clumps' union
  // volumes fill (1 − n_c) V_vessel; with one template, (1 − n_c) V_vessel / f.
  std::vector<ClumpTemplate> unit;
  std::vector<double> volume_factor, enclosing;
  const double solid = (1.0 - p.cloud_porosity) * volume;
  double sphere_volume = clumps ? 0.0 : solid;
  for (const auto& [name, fraction] : spec.clump_mix) {
    unit.push_back(named_template(name, grain_defaults.density));
    const double d = unit.back().size(spec.clump_size);
    volume_factor.push_back(unit.back().volume / (std::numbers::pi * d * d * d / 6.0));
    // A clump is placed as the sphere that encloses it (about its centre of mass): its enclosing
    // radius is d/2 × (enclosing diameter / size) of the unit template.
    enclosing.push_back(unit.back().size(SizeMeasure::EnclosingDiameter) / d);
    sphere_volume += solid * fraction / volume_factor.back();
  }
  const GrainSample sample = sample_grains(spec.grading, spec.d_mult, sphere_volume, rng);
  // Each grain's template, from a stream of its own: the sizes above and the positions and
  // orientations below are the seed's draws whatever the mix.
  const std::vector<std::uint32_t> kind =
      clumps ? assign_clump_templates(sample.diameters, spec.clump_mix, volume_factor, p.seed) : std::vector<std::uint32_t>{};
  std::vector<std::size_t> order(sample.diameters.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return sample.diameters[a] > sample.diameters[b]; });
  auto reach = [&](std::size_t i) { return clumps ? enclosing[kind[i]] : 1.0; };  // enclosing diameter per size
  double d_max = 0.0;
  for (std::size_t i : order) d_max = std::max(d_max, sample.diameters[i] * reach(i));
  PlacementGrid grid(R, H, std::max(d_max, 1e-9));
  std::vector<Vec3> pos;
  std::vector<double> rad;
  pos.reserve(order.size());
  rad.reserve(order.size());
  std::int64_t next_id = 1;
  for (std::size_t i : order) {
    const double r = 0.5 * sample.diameters[i] * reach(i);
    Vec3 best;
    double best_overlap = std::numeric_limits<double>::infinity();
    for (int t = 0; t < std::max(1, p.placement_tries); ++t) {
      const double rho = (R - r) * std::sqrt(rng.uniform());
      const double phi = 2.0 * std::numbers::pi * rng.uniform();
      const Vec3 x{rho * std::cos(phi), rho * std::sin(phi), rng.uniform(r, H - r)};
      const double ov = grid.overlap(x, r, pos, rad);
      if (ov < best_overlap) best_overlap = ov, best = x;
      if (ov == 0.0) break;
    }
    grid.insert(pos.size(), best);
    pos.push_back(best);
    rad.push_back(r);
    if (clumps) {
      // A uniformly random rotation (Shoemake, Graphics Gems III, 1992), drawn after the position.
      const double u1 = rng.uniform(), u2 = 2.0 * std::numbers::pi * rng.uniform(), u3 = 2.0 * std::numbers::pi * rng.uniform();
      const Quat q{std::sqrt(1.0 - u1) * std::sin(u2), std::sqrt(1.0 - u1) * std::cos(u2), std::sqrt(u1) * std::sin(u3),
                   std::sqrt(u1) * std::cos(u3)};
      const ClumpTemplate t = unit[kind[i]].scaled(sample.diameters[i], spec.clump_size);
      ClumpInit c;
      c.first_ball_id = next_id;
      c.position = best;
      c.orientation = normalized(q);
      c.young_mod = grain_defaults.young_mod;
      c.pois_ratio = grain_defaults.pois_ratio;
      c.groups = grain_bit;
      sim.clumps.add(sim.balls, t, c);
      s.clump_kind.push_back(kind[i]);
      next_id += static_cast<std::int64_t>(t.pebbles.size());
      continue;
    }
    BallInit b;
    b.id = next_id++;
    b.position = best;
    b.radius = r;
    b.density = grain_defaults.density;
    b.young_mod = grain_defaults.young_mod;
    b.pois_ratio = grain_defaults.pois_ratio;
    b.groups = grain_bit;
    sim.balls.add(b);
  }
  sim.sort_balls_spatially();
  install_table(sim, packing_table(sim, p.contact, p.walls));
  return s;
}

PhaseReport relax_cloud(Specimen& s, const PackingSettings& p, std::ostream* log) {
  const auto t0 = std::chrono::steady_clock::now();
  Simulation& sim = s.sim;
  s.vessel.stop(sim);
  const double d_min = on_whole_run<double>(s, [](const Specimen& w) {
    double d = std::numeric_limits<double>::infinity();
    for (double r : w.sim.balls.radius) d = std::min(d, 2.0 * r);
    return d;
  });
  const double cap = p.cloud_speed_limit;
  // A clump's speed is capped at its centre of mass, and its spin so that no point of it within its
  // enclosing radius moves faster than the cap from the turn (ω and L_b scaled together: ω = R I⁻¹ L_b).
  // The radii from the clumps held at each step: over MPI ranks they change with every migration.
  ControllerScope scope(sim);
  sim.controllers.push_back([cap, reach = std::vector<double>()](Simulation& m, double) mutable {
    for (Vec3& v : m.balls.velocity) {
      const double speed = norm(v);
      if (speed > cap) v *= cap / speed;
    }
    reach.assign(m.clumps.size(), 0.0);
    for (std::size_t k = 0; k < m.clumps.pebbles.size(); ++k) {
      double& x = reach[m.clumps.pebbles.clump[k]];
      x = std::max(x, norm(m.clumps.pebbles.body_position[k]) + m.clumps.pebbles.radius[k]);
    }
    ClumpState& c = m.clumps.state;
    for (std::size_t i = 0; i < c.size(); ++i) {
      const double speed = norm(c.velocity[i]);
      if (speed > cap) c.velocity[i] *= cap / speed;
      const double turn = norm(c.spin[i]) * reach[i];
      if (turn > cap) {
        c.spin[i] *= cap / turn;
        c.body_momentum[i] *= cap / turn;
      }
    }
  });
  const std::int64_t start = sim.steps;
  // The whole run's deepest overlap [m] (over ranks: each row by the owner of its first ball).
  const bool ranks = decomposed(s);
  auto worst_overlap = [&] {
    double worst = 0.0;
    for (std::size_t c = 0; c < sim.contacts.size(); ++c)
      if (sim.contacts.exists[c] && sim.contacts.active[c] && (!ranks || s.ranks->owns(sim.contacts.key[c].a)))
        worst = std::max(worst, -sim.contacts.gap[c]);
    return max_over_ranks(s, worst);
  };
  sim.update_forces();
  for (double worst = worst_overlap(); worst > p.cloud_overlap * d_min; worst = worst_overlap()) {
    if (sim.steps - start >= p.cloud_max_steps) {
      if (log)
        *log << fmt::format("cloud: overlaps not below {:g} x D_min after {} steps (worst {:.3g} mm); packing anyway\n",
                            p.cloud_overlap, p.cloud_max_steps, worst * 1e3);
      break;
    }
    sim.cycle(50);
  }
  for (Vec3& v : sim.balls.velocity) v = Vec3{};
  for (Vec3& w : sim.balls.spin) w = Vec3{};
  if (!sim.clumps.empty()) {
    for (Vec3& v : sim.clumps.state.velocity) v = Vec3{};
    for (Vec3& w : sim.clumps.state.spin) w = Vec3{};
    for (Vec3& l : sim.clumps.state.body_momentum) l = Vec3{};
    sim.clumps.place_pebbles(sim.balls);
  }
  PhaseReport r{"cloud", sim.steps - start, seconds_since(t0), measure(s)};
  if (log) *log << r.line() << std::endl;
  s.phases.push_back(r);
  return r;
}

PhaseReport servo_equilibrium(Specimen& s, const EquilibriumSettings& e, const std::string& name, std::ostream* log) {
  const auto t0 = std::chrono::steady_clock::now();
  Simulation& sim = s.sim;
  const ServoSettings ss{e.pressure, e.servo_gain, e.wall_speed_limit};
  std::vector<Servo> servos{s.vessel.radial_servo(ss), s.vessel.platen_servo(false, ss), s.vessel.platen_servo(true, ss)};
  // The servos read and move only the walls: every cycle but the last of each check runs unwatched
  // (Simulation::drive).
  const std::int64_t check_every = std::max<std::int64_t>(1, e.check_every);
  auto plan = [&](double dt) {
    for (Servo& sv : servos) sv.control(sim, dt);
    return false;
  };
  const std::int64_t start = sim.steps;
  const std::int64_t progress_every = 20000;
  std::int64_t next_progress = start + progress_every;
  auto within = [&](double stress) { return std::abs(stress - e.pressure) <= e.pressure_tolerance * e.pressure; };
  const double solid = decomposed(s) ? s.whole_solid : solid_volume(sim);
  auto porosity = [&] { return 1.0 - solid / s.vessel.volume(sim); };
  PorosityHistory history(e.porosity_window);
  history.add(sim.steps, porosity());
  for (;;) {
    sim.drive(check_every, plan);
    history.add(sim.steps, porosity());
    const double sr = s.vessel.radial_stress(sim), sb = s.vessel.bottom_stress(sim), st = s.vessel.top_stress(sim);
    // (The walls' sums are the whole run's on every rank, so every rank takes the same branches and
    // meets whole_run_ratio's collective together.)
    if (within(sr) && within(sb) && within(st) && whole_run_ratio(s) <= e.ratio && history.converged(e.porosity_change))
      break;
    if (sim.steps >= next_progress && (log || decomposed(s))) {  // (over ranks every rank: the ratio is collective)
      next_progress += progress_every;
      const double ratio = whole_run_ratio(s);
      double dn = 0.0;
      const bool have = history.change_per_1000(dn);
      if (log)
        *log << fmt::format("  {} step {:>8}: n {:.4f}  sigma_r {:.1f}  sigma_b {:.1f}  sigma_t {:.1f} kPa  ratio {:.2e}  dn {} per 1000 steps  "
                          "dt {:.3g} s\n",
                          name, sim.steps - start, porosity(), sr / 1e3, sb / 1e3, st / 1e3, ratio,
                          have ? fmt::format("{:.1e}", dn) : std::string("n/a"), sim.last_dt);
      if (log) log->flush();
    }
    if (sim.steps - start >= e.max_steps) {
      s.vessel.stop(sim);
      double dn = 0.0;
      const bool have = history.change_per_1000(dn);
      throw RunError(fmt::format("{}: not converged after {} steps ({}): sigma_r {:.2f}, sigma_bottom {:.2f}, sigma_top {:.2f} kPa, "
                                 "ratio {:.3g}, porosity change {} per 1,000 steps",
                                 name, e.max_steps, criterion_text(e), sr / 1e3, sb / 1e3, st / 1e3, whole_run_ratio(s),
                                 have ? fmt::format("{:.2g}", dn) : std::string("n/a")));
    }
  }
  s.vessel.stop(sim);
  PhaseReport r{name, sim.steps - start, seconds_since(t0), measure(s)};
  history.change_per_1000(r.porosity_change);
  if (log) *log << r.line() << std::endl;
  s.phases.push_back(r);
  return r;
}

std::vector<double> clump_mix_fractions(const Specimen& s) {
  std::vector<double> v(s.clump_mix.size(), 0.0);
  const std::vector<double> volume = clump_volumes(s.sim);
  if (s.clump_kind.size() != volume.size()) throw InputError("the specimen's clumps and their templates do not match");
  double total = 0.0;
  for (std::size_t i = 0; i < volume.size(); ++i) v[s.clump_kind[i]] += volume[i], total += volume[i];
  for (double& x : v) x = total > 0.0 ? x / total : 0.0;
  return v;
}

namespace {
// " (realised 0.603, 0.397)" for a mix: the solid fractions drawn; "" for one template.
std::string realised_text(const Specimen& s) {
  if (s.clump_mix.size() < 2) return {};
  std::string out = " (realised";
  const std::vector<double> f = clump_mix_fractions(s);
  for (std::size_t t = 0; t < f.size(); ++t) out += fmt::format("{} {:.3f}", t ? "," : "", f[t]);
  return out + ")";
}
}  // namespace

Specimen pack_specimen(const GenesisSpec& spec, std::ostream* log) {
  const auto t0 = std::chrono::steady_clock::now();
  Specimen s = make_cloud(spec);
  if (log)
    *log << fmt::format("cloud: {} grains{} of {} at porosity {:.3f} in a {:.0f} mm x {:.0f} mm vessel (seed {}, {:.1f} s); "
                        "packing contacts {} with friction {:g}; converged when {}\n",
                        grain_count(s.sim),
                        s.clump_mix.empty()
                            ? std::string()
                            : fmt::format(" (clumps of {}{}, {} pebbles, {})", clump_mix_words(s.clump_mix),
                                          realised_text(s), s.sim.clumps.pebbles.size(), to_string(s.clump_size)),
                        spec.grading.name, measure(s).porosity, 2e3 * spec.vessel_radius,
                        1e3 * spec.vessel_height, spec.packing.seed, seconds_since(t0), to_string(spec.packing.contact.model),
                        spec.packing.contact.fric, criterion_text(spec.packing.equilibrium));
  const RanksScope ranks(s, 0.0);
  relax_cloud(s, spec.packing, log);
  servo_equilibrium(s, spec.packing.equilibrium, "packing", log);
  if (decomposed(s)) return whole_run(s);
  return s;
}

PhaseReport finalize(Specimen& s, const Class5Material& m, const WallContact& walls, const EquilibriumSettings& e,
                     std::ostream* log) {
  apply_grain_properties(s.sim, m);
  install_table(s.sim, material_table(s.sim, m, walls));
  s.material = m.name(s.grading);
  s.wet = false;
  return servo_equilibrium(s, e, "finalize " + s.material, log);
}

PhaseReport make_specimen_wet(Specimen& s, double suction, double gap, const EquilibriumSettings& e, std::ostream* log) {
  if (!(suction >= 0) || !std::isfinite(suction)) throw InputError(fmt::format("suction must be >= 0 Pa, got {:g}", suction));
  if (!(gap >= 0) || !std::isfinite(gap)) throw InputError(fmt::format("moisture gap must be >= 0 m, got {:g}", gap));
  bool hill = false;
  for (const ModelRule& r : s.sim.table.rules) hill = hill || (r.kind == ContactKind::BallBall && r.model == ModelKind::Hill);
  if (!hill) throw InputError("only a hill material can be made wet (the linear model has no liquid bridges)");
  std::size_t wet = s.sim.make_wet(suction, gap);
  // Over ranks each rank wets its part (the ghosts cover the gap: attach_to_ranks' reach); the count
  // is the whole run's, each wet row counted by the owner of its first ball.
  if (decomposed(s))
    wet = whole_run_rows(s, [](const ContactStore& c, std::size_t k) {
      return c.exists[k] && c.model[k] == ModelKind::Hill && c.moisture[k] == Moisture::Wet;
    });
  s.wet = true;
  if (log) *log << fmt::format("make_wet({:g} kPa, {:g} mm): {} wet contacts\n", suction / 1e3, gap * 1e3, wet);
  return servo_equilibrium(s, e, "wet " + s.material, log);
}

}  // namespace hilldem
