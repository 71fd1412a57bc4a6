#include "hilldem/labtests/study.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <numbers>
#include <ostream>
#include <streambuf>
#include <thread>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "hilldem/core/error.hpp"
#include "hilldem/engine/thread_budget.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/labtests/specimen_io.hpp"

namespace hilldem {

namespace fs = std::filesystem;

std::string CaseSpec::name() const {
  std::string g = grading;
  const std::string low = [&] {
    std::string s = grading;
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
  }();
  if (low == "c5n") g = "C5n";
  else if (low == "c5b") g = "C5b";
  else g = fs::path(grading).stem().string();
  return g + (model == GrainModel::Hill ? "_Hill" : "_Linear") + (wet ? "_wet" : "") +
         (confinement > 0 ? fmt::format("_{:g}kPa", confinement / 1e3) : std::string());
}

std::vector<CaseSpec> sweep_confinements(const std::vector<CaseSpec>& cases, const std::vector<double>& confinements) {
  std::vector<CaseSpec> out;
  for (double sc : confinements)
    for (CaseSpec c : cases) {
      c.confinement = sc;
      out.push_back(c);
    }
  return out;
}

double confinement_of(const StudySettings& settings, const CaseSpec& c) {
  return c.confinement > 0 ? c.confinement : settings.triaxial.confinement;
}

double expected_grains(const Grading& g, double d_mult, double R, double H, double n_c) {
  double per_volume = 0.0;  // grains per unit solid volume
  for (const GradingBin& b : g.bins) {
    const double lo = b.d_lower * d_mult, hi = b.d_upper * d_mult;
    // E[π d³/6] for d uniform in [lo, hi]: π (hi⁴ − lo⁴) / (24 (hi − lo)); π lo³/6 for a single size.
    const double mean_v = hi > lo ? std::numbers::pi * (std::pow(hi, 4) - std::pow(lo, 4)) / (24.0 * (hi - lo))
                                  : std::numbers::pi * lo * lo * lo / 6.0;
    if (mean_v > 0) per_volume += b.fraction / mean_v;
  }
  return (1.0 - n_c) * std::numbers::pi * R * R * H * per_volume;
}

std::pair<double, double> vessel_for(const StudySettings& settings, const Grading& g) {
  const GenesisSpec& v = settings.genesis;
  const double n = expected_grains(g, v.d_mult, v.vessel_radius, v.vessel_height, v.packing.cloud_porosity);
  const double f = settings.min_grains > 0 && n > 0 && n < settings.min_grains ? std::cbrt(settings.min_grains / n) : 1.0;
  return {f * v.vessel_radius, f * v.vessel_height};
}

std::vector<CaseSpec> memo_cases() {
  return {{"C5n", GrainModel::Linear, false},
          {"C5n", GrainModel::Hill, false},
          {"C5b", GrainModel::Linear, false},
          {"C5b", GrainModel::Hill, false},
          {"C5b", GrainModel::Hill, true}};
}

void validate(const StudySettings& s, const std::vector<CaseSpec>& cases) {
  if (cases.empty()) throw InputError("no cases to run");
  validate(s.triaxial);
  if (s.min_grains < 0 || s.min_grains > 1'000'000)
    throw InputError(fmt::format("--min-grains must be in [0, 1000000], got {}", s.min_grains));
  for (const CaseSpec& c : cases) {
    if (!(c.confinement >= 0) || !std::isfinite(c.confinement))
      throw InputError(fmt::format("case {}: confinement must be 0 (the test's) or a finite number > 0 Pa, got {:g}", c.name(),
                                   c.confinement));
    GenesisSpec g = s.genesis;
    g.grading = resolve_grading(c.grading);
    std::tie(g.vessel_radius, g.vessel_height) = vessel_for(s, g.grading);
    validate(g);
    if (c.wet && c.model != GrainModel::Hill)
      throw InputError("--wet needs the hill material: the linear model has no liquid bridges");
  }
  if (s.pack_linear && !s.specimen_file.empty())
    throw InputError("--pack-linear and --specimen: the specimen file says which contacts packed it");
  const EquilibriumSettings& e = s.finalize;
  if (!(e.pressure > 0) || !std::isfinite(e.pressure)) throw InputError(fmt::format("pressure must be > 0 Pa, got {:g}", e.pressure));
  if (!(e.ratio > 0 && e.ratio < 1)) throw InputError(fmt::format("equilibrium ratio must be in (0, 1), got {:g}", e.ratio));
  if (!(s.suction >= 0) || !std::isfinite(s.suction)) throw InputError(fmt::format("suction must be >= 0 Pa, got {:g}", s.suction));
  if (!(s.moisture_gap >= 0) || !std::isfinite(s.moisture_gap))
    throw InputError(fmt::format("moisture gap must be >= 0 m, got {:g}", s.moisture_gap));
  const Class5Material& m = s.material;
  if (!(m.fric >= 0) || !(m.young_mod > 0) || !(m.pois_ratio > -1 && m.pois_ratio <= 0.5) || !(m.linear_emod > 0) ||
      !(m.linear_kratio > 0) || !(m.damp_con >= 0 && m.damp_con < 1) || !(m.density > 0))
    throw InputError("material properties out of range");
  if (s.jobs < 0 || s.jobs > 1024) throw InputError(fmt::format("--jobs must be in [0, 1024], got {}", s.jobs));
  if (!s.genesis.clump_mix.empty() && s.triaxial.density_scaling > 0)
    throw InputError("density scaling does not apply to clumps (docs/clumps.md, Limits): give --density-scaling 0 with "
                     "--clump-template");
  if (!s.specimen_file.empty()) {
    // Parse it now: a bad file stops before any work.
    const Specimen sp = load_packed_specimen(s.specimen_file);
    const ClumpMix& want = s.genesis.clump_mix;
    if (!want.empty() && sp.clump_mix != want)
      throw InputError(fmt::format("--clump-template {} and --specimen {}: the file's grains are {}", clump_mix_text(want),
                                   s.specimen_file, sp.clump_mix.empty() ? "balls" : "clumps of " + clump_mix_text(sp.clump_mix)));
    if (!sp.clump_mix.empty() && s.triaxial.density_scaling > 0)
      throw InputError(fmt::format("density scaling does not apply to clumps (docs/clumps.md, Limits): the specimen {} has clumps "
                                   "of {}",
                                   s.specimen_file, clump_mix_text(sp.clump_mix)));
    for (const CaseSpec& c : cases)
      if (c.grading != cases.front().grading)
        throw InputError("--specimen gives one packed specimen: all cases must use its grading");
  }
}

namespace {

void write_file(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream f(p, std::ios::binary);
  f << text;
  if (!f) throw RunError(p.string() + ": cannot write");
}

std::string state_text(const char* label, const SpecimenState& s) {
  return fmt::format("{}: grains {}, porosity {:.4f} (interior {}), coordination {:.3f} (mechanical {:.3f}), sigma_r {:.2f} kPa, "
                     "sigma_bottom {:.2f} kPa, sigma_top {:.2f} kPa, R {:.3f} mm, H {:.3f} mm, wet contacts {}, ratio {:.2e}\n",
                     label, s.grains, s.porosity, interior_text(s), s.coordination, s.mech_coordination, s.radial_stress / 1e3,
                     s.bottom_stress / 1e3, s.top_stress / 1e3, s.radius * 1e3, s.height * 1e3, s.wet_contacts, s.ratio);
}

// A CSV cell of a fit: its slope or (se) its standard error [Pa]; empty when not fitted.
std::string fit_cell(const LineFit& f, bool se) {
  return f.valid ? fmt::format("{:.9g}", se ? f.slope_se : f.slope) : std::string();
}

std::string loops_csv(const std::vector<LoopResult>& loops) {
  std::string out =
      "cycle,target_strain[-],eps_A[-],q_A[Pa],eps_B[-],q_B[Pa],q_C[Pa],closed,resilient_modulus_fit[Pa],"
      "resilient_modulus_fit_se[Pa],fit_points,unload_secant[Pa],reload_fit[Pa],reload_fit_se[Pa],reload_secant[Pa],"
      "loop_area[J/m3],damping_ratio[-]\n";
  for (const LoopResult& l : loops)
    out += fmt::format("{},{:.6g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{},{},{},{},{:.9g},{},{},{:.9g},{:.9g},{:.6g}\n", l.cycle,
                       l.target_strain, l.eps_a, l.q_a, l.eps_b, l.q_b, l.q_c, l.closed ? 1 : 0, fit_cell(l.unload, false),
                       fit_cell(l.unload, true), l.unload.points, l.unload_secant, fit_cell(l.reload, false), fit_cell(l.reload, true),
                       l.reload_secant, l.loop_area, l.damping_ratio);
  return out;
}

// A CSV cell of the interior porosity: empty when it could not be measured.
std::string interior_cell(const SpecimenState& s) {
  return s.interior_margin == SpecimenState::Margin::None ? std::string() : fmt::format("{:.6g}", s.interior_porosity);
}

// The packing's convergence: its porosity change per 1,000 steps at the end, or why there is none.
std::string packing_change_text(const std::vector<PhaseReport>& phases) {
  for (const PhaseReport& ph : phases)
    if (ph.name == "packing" && ph.porosity_change >= 0) return fmt::format("{:.1e}", ph.porosity_change);
  return "n/a (loaded)";
}

std::size_t max_loops(const std::vector<CaseResult>& cases) {
  std::size_t n = 0;
  for (const CaseResult& c : cases) n = std::max(n, c.test.loops.size());
  return n;
}

}  // namespace

std::string StudyResult::summary_csv() const {
  const std::size_t nl = max_loops(cases);
  std::string out =
      "case,grading,material,wet,packing_model,confinement[Pa],grains,porosity_packed[-],interior_porosity_packed[-],interior_margin_packed[m],"
      "porosity_test_start[-],interior_porosity_test_start[-],coordination_packed[-],coordination_test_start[-],"
      "sigma_r_start[Pa],sigma_axial_start[Pa],peak_q[Pa],peak_eps_a[-],peak_eps_r[-],peak_eps_v[-],packing_porosity_change_per_1000_steps[-]";
  for (std::size_t k = 1; k <= nl; ++k)
    out += fmt::format(",eps_A_cycle{0}[-],Mr_fit_cycle{0}[Pa],Mr_fit_se_cycle{0}[Pa],Mr_unload_secant_cycle{0}[Pa],"
                       "reload_fit_cycle{0}[Pa],reload_fit_se_cycle{0}[Pa],reload_secant_cycle{0}[Pa],loop_area_cycle{0}[J/m3],"
                       "damping_ratio_cycle{0}[-]",
                       k);
  out += ",worst_confinement_error[-],worst_platen_mismatch[-],test_steps,packing_seconds,seconds\n";
  for (const CaseResult& c : cases) {
    out += fmt::format("{},{},{},{},{},{:g},{},{:.6g},{},{:.6g},{:.6g},{},{:.6g},{:.6g},{:.9g},{:.9g},{:.9g},{:.6g}", c.spec.name(),
                       c.grading.name, to_string(c.spec.model), c.spec.wet ? 1 : 0, to_string(c.packed_with), c.confinement, c.initial.grains,
                       c.packed.porosity, interior_cell(c.packed), c.packed.interior_margin_length, c.initial.porosity,
                       interior_cell(c.initial), c.packed.coordination, c.initial.coordination, c.initial.radial_stress,
                       0.5 * (c.initial.bottom_stress + c.initial.top_stress), c.test.peak_q, c.test.peak_strain);
    const std::string dn = packing_change_text(c.phases);
    out += fmt::format(",{:.6g},{:.6g},{}", c.test.peak_radial_strain, c.test.peak_volumetric_strain, dn.rfind("n/a", 0) == 0 ? "" : dn);
    for (std::size_t k = 0; k < nl; ++k) {
      if (k < c.test.loops.size()) {
        const LoopResult& l = c.test.loops[k];
        out += fmt::format(",{:.6g},{},{},{:.9g},{},{},{},{:.9g},{}", l.eps_a, fit_cell(l.unload, false), fit_cell(l.unload, true),
                           l.unload_secant, fit_cell(l.reload, false), fit_cell(l.reload, true),
                           l.closed ? fmt::format("{:.9g}", l.reload_secant) : "", l.loop_area,
                           l.closed ? fmt::format("{:.6g}", l.damping_ratio) : "");
      } else {
        out += ",,,,,,,,,";
      }
    }
    out += fmt::format(",{:.6g},{:.6g},{},{:.1f},{:.1f}\n", c.test.worst_confinement_error, c.test.worst_platen_mismatch,
                       c.test.steps, c.packing_seconds, c.seconds);
  }
  return out;
}

std::string StudyResult::summary_markdown() const {
  const std::size_t nl = max_loops(cases);
  std::string head =
      "| case | packed with | grains | porosity packed: vessel / interior | packing dn per 1000 steps | at test start: vessel / interior | "
      "Z packed | Z | peak q [kPa] | at eps_a [%] | eps_v at peak [%] |";
  std::string rule = "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|";
  for (std::size_t k = 1; k <= nl; ++k) {
    head += fmt::format(" M_r c{0} [MPa] | secant c{0} [MPa] | reload c{0} [MPa] | loop c{0} [J/m³] |", k);
    rule += "---:|---:|---:|---:|";
  }
  head += " worst sigma_r error [%] | worst platen mismatch [%] | test steps | time [s] |";
  rule += "---:|---:|---:|---:|";
  std::string out = head + "\n" + rule + "\n";
  for (const CaseResult& c : cases) {
    out += fmt::format("| {} | {} | {} | {:.4f} / {} | {} | {:.4f} / {} | {:.2f} | {:.2f} | {:.1f} | {:.3f} | {:.3f} |", c.spec.name(),
                       c.clump_template.empty() ? std::string(to_string(c.packed_with))
                                                : fmt::format("{} (clumps of {})", to_string(c.packed_with), c.clump_template),
                       c.initial.grains, c.packed.porosity, interior_text(c.packed),
                       packing_change_text(c.phases), c.initial.porosity, interior_text(c.initial), c.packed.coordination,
                       c.initial.coordination, c.test.peak_q / 1e3, 100 * c.test.peak_strain, 100 * c.test.peak_volumetric_strain);
    for (std::size_t k = 0; k < nl; ++k) {
      if (k < c.test.loops.size()) {
        const LoopResult& l = c.test.loops[k];
        out += fmt::format(" {} | {:.1f} | {} | {:.3g} |", fit_text(l.unload), l.unload_secant / 1e6, fit_text(l.reload), l.loop_area);
      } else {
        out += " | | | |";
      }
    }
    out += fmt::format(" {:.2f} | {:.2f} | {} | {:.0f} |\n", 100 * c.test.worst_confinement_error, 100 * c.test.worst_platen_mismatch,
                       c.test.steps, c.seconds);
  }
  out += "\nM_r: resilient modulus, the slope of the least-squares line through the unload branch's points with q in the middle\n"
         "80 % of q_B..q_A, +- its standard error (block jackknife: honest for the ringing's correlated residuals); secant: the\n"
         "two-point unload "
         "secant (q_A − q_B)/(eps_A − eps_B); reload: the same fit over the reload branch (q_B..q_C);\n"
         "loop: hysteresis, loop area ∮ q d(eps_a) = energy dissipated per unit volume. Z: touching grain-grain contacts per grain\n"
         "(Z packed: after packing; Z: at the test start).\n"
         "Packed with: the grain-grain contact model of the frictionless packing (mu = 0); finalization installs the material\n"
         "and restores its friction (mu = 0.4). Each material is packed with its own model unless --pack-linear.\n"
         "Porosity: vessel = 1 − V_grains/(π R² H); interior = in the coaxial cylinder one D_max in from every wall (D50 where\n"
         "the vessel is too small for that: marked; n/a where even that leaves less than D_max in radius or 2 D_max in height).\n"
         "Time: finalization, wetting and test of the case (wall clock); packing is done once per grading and packing model.\n"
         "eps_v = eps_a + 2 eps_r (compression positive; negative: dilation), at the peak deviator.\n";
  if (!criterion.empty())
    out += "Packing, finalization and wetting converged when " + criterion +
           "; packing dn: the packing's vessel-porosity change per 1,000 steps at its end.\n";
  out += "\nWhere the time goes:\n\n" + time_markdown();
  const auto f = findings();
  if (!f.empty()) {
    out += "\nFindings of the memo, checked (a comparison of M_r holds or fails only where the difference exceeds twice its\n"
           "standard error; otherwise it is within noise):\n\n";
    for (const std::string& s : f) out += "* " + s + "\n";
  }
  return out;
}

std::string StudyResult::time_markdown() const {
  struct Row {
    std::string work;
    std::size_t grains = 0;
    std::int64_t steps = 0;
    double seconds = 0.0;
  };
  std::vector<Row> rows;
  std::vector<std::string> packings_seen;  // a packing shared by several cases is listed once
  for (const CaseResult& c : cases) {
    const std::string packing = fmt::format("packing {} {}", c.grading.name, to_string(c.packed_with));
    const bool first = std::find(packings_seen.begin(), packings_seen.end(), packing) == packings_seen.end();
    if (first) packings_seen.push_back(packing);
    for (const PhaseReport& ph : c.phases) {
      const bool shared = ph.name == "cloud" || ph.name == "packing";
      if (shared && !first) continue;
      rows.push_back({shared ? packing + ": " + (ph.name == "cloud" ? "cloud relaxation" : "servo packing") : c.spec.name() + ": " + ph.name,
                      ph.state.grains, ph.steps, ph.seconds});
    }
    rows.push_back({c.spec.name() + ": triaxial test", c.initial.grains, c.test.steps, c.test.seconds});
  }
  double total = 0.0, seconds = 0.0;
  std::int64_t steps = 0;
  for (const Row& r : rows) total += static_cast<double>(r.grains) * static_cast<double>(r.steps), steps += r.steps, seconds += r.seconds;
  std::string out = "| work | grains | steps | grain-steps [1e6] | share of grain-steps [%] | wall [s] | wall per 1e6 grain-steps [s] |\n"
                    "|---|---:|---:|---:|---:|---:|---:|\n";
  auto per = [](double s, double gs) { return gs > 0 ? fmt::format("{:.3f}", s / (gs / 1e6)) : std::string("n/a"); };
  for (const Row& r : rows) {
    const double gs = static_cast<double>(r.grains) * static_cast<double>(r.steps);
    out += fmt::format("| {} | {} | {} | {:.1f} | {:.1f} | {:.1f} | {} |\n", r.work, r.grains, r.steps, gs / 1e6,
                       total > 0 ? 100.0 * gs / total : 0.0, r.seconds, per(r.seconds, gs));
  }
  out += fmt::format("| all rows | | {} | {:.1f} | 100.0 | {:.1f} | {} |\n", steps, total / 1e6, seconds, per(seconds, total));
  if (this->seconds > 0)
    out += fmt::format("\nThe study: {:.1f} s wall clock, {:.1f} s CPU (all threads).\n", this->seconds, cpu_seconds);
  return out;
}

namespace {
// The memo's findings over cases of one confinement.
std::vector<std::string> findings_of(const std::vector<CaseResult>& cases) {
  std::vector<std::string> out;
  auto find = [&](const std::string& grading, GrainModel m, bool wet) -> const CaseResult* {
    for (const CaseResult& c : cases)
      if (c.grading.name == grading && c.spec.model == m && c.spec.wet == wet) return &c;
    return nullptr;
  };
  // Each claim is a set of comparisons "a > b". A comparison of fitted moduli holds or fails only when
  // the difference exceeds twice its standard error, sqrt(s_a² + s_b²); otherwise it is within noise.
  // Loop areas and peak deviators carry no uncertainty here: their comparisons are taken as they are.
  struct Tally {
    int yes = 0, no = 0, noise = 0, n = 0;
    void add(bool b) { add(b ? 1.0 : -1.0, 0.0, 0.0, 0.0); }
    void add(double a, double sa, double b, double sb) {
      ++n;
      const double d = a - b, s = std::sqrt(sa * sa + sb * sb);
      if (!(std::abs(d) > 2.0 * s)) ++noise;
      else if (d > 0) ++yes;
      else ++no;
    }
  };
  auto verdict = [](const Tally& t) {
    const std::string noise = t.noise > 0 ? fmt::format("; {} within noise", t.noise) : std::string();
    if (t.yes == t.n) return fmt::format("HOLDS ({} of {} comparisons)", t.yes, t.n);
    if (t.noise == t.n) return fmt::format("WITHIN NOISE ({} of {} comparisons within 2 standard errors)", t.noise, t.n);
    if (t.yes == 0) return fmt::format("DOES NOT HOLD (0 of {} comparisons{})", t.n, noise);
    return fmt::format("HOLDS IN PART ({} of {} comparisons{})", t.yes, t.n, noise);
  };
  // A loop's M_r (the unload fit) and its standard error; an unfitted loop has no usable value.
  auto mr = [](const LoopResult& l) { return l.unload.valid ? l.unload.slope : 0.0; };
  auto mr_se = [](const LoopResult& l) { return l.unload.valid ? l.unload.slope_se : std::numeric_limits<double>::infinity(); };
  auto mr_text = [](const LoopResult& l) {
    return l.unload.valid ? fmt::format("{:.1f} +- {:.1f}", l.unload.slope / 1e6, l.unload.slope_se / 1e6) : std::string("n/a");
  };
  // 1. Hysteresis loops larger for hill than for linear.
  {
    std::string detail;
    Tally ok;
    bool any = false;
    for (const char* g : {"C5n", "C5b"}) {
      const CaseResult *h = find(g, GrainModel::Hill, false), *l = find(g, GrainModel::Linear, false);
      if (!h || !l) continue;
      for (std::size_t k = 0; k < std::min(h->test.loops.size(), l->test.loops.size()); ++k) {
        const double a = h->test.loops[k].loop_area, b = l->test.loops[k].loop_area;
        detail += fmt::format("{}{} cycle {}: hill {:.3g} vs linear {:.3g} J/m³ (x{:.2f})", detail.empty() ? "" : "; ", g, k + 1, a, b,
                              b > 0 ? a / b : 0.0);
        ok.add(a > b);
        any = true;
      }
    }
    if (any) out.push_back("hysteresis loops larger for hill than for linear: " + detail + " -> " + verdict(ok));
  }
  // 2-3. C5b stiffer and stronger than C5n, more so for hill.
  {
    // Per model: the M_r ratios per cycle with their standard errors, and the peak ratio.
    std::map<GrainModel, std::pair<std::vector<std::pair<double, double>>, double>> ratios;
    std::string stiff, strong;
    Tally ok_stiff, ok_strong;
    bool any = false;
    for (GrainModel m : {GrainModel::Linear, GrainModel::Hill}) {
      const CaseResult *b = find("C5b", m, false), *n = find("C5n", m, false);
      if (!b || !n) continue;
      any = true;
      auto& r = ratios[m];
      for (std::size_t k = 0; k < std::min(b->test.loops.size(), n->test.loops.size()); ++k) {
        const LoopResult &lb = b->test.loops[k], &ln = n->test.loops[k];
        const double x = mr(lb), y = mr(ln), sx = mr_se(lb), sy = mr_se(ln);
        const double ratio = x > 0 && y > 0 ? x / y : 0.0;
        // σ of a ratio: (x/y) sqrt((σ_x/x)² + (σ_y/y)²).
        const double s_ratio = ratio > 0 ? ratio * std::hypot(sx / x, sy / y) : std::numeric_limits<double>::infinity();
        r.first.emplace_back(ratio, s_ratio);
        stiff += fmt::format("{}{} cycle {}: M_r C5b {} vs C5n {} MPa (x{:.2f})", stiff.empty() ? "" : "; ", to_string(m), k + 1,
                             mr_text(lb), mr_text(ln), ratio);
        ok_stiff.add(x, sx, y, sy);
      }
      r.second = n->test.peak_q > 0 ? b->test.peak_q / n->test.peak_q : 0.0;
      strong += fmt::format("{}{}: peak q C5b {:.1f} vs C5n {:.1f} kPa (x{:.2f})", strong.empty() ? "" : "; ", to_string(m),
                            b->test.peak_q / 1e3, n->test.peak_q / 1e3, r.second);
      ok_strong.add(b->test.peak_q > n->test.peak_q);
    }
    if (any) {
      out.push_back("C5b stiffer than C5n: " + stiff + " -> " + verdict(ok_stiff));
      out.push_back("C5b stronger than C5n: " + strong + " -> " + verdict(ok_strong));
    }
    if (ratios.count(GrainModel::Hill) && ratios.count(GrainModel::Linear)) {
      const auto &h = ratios[GrainModel::Hill], &l = ratios[GrainModel::Linear];
      std::string d;
      Tally ok;
      ok.add(h.second > l.second);
      for (std::size_t k = 0; k < std::min(h.first.size(), l.first.size()); ++k) {
        d += fmt::format("{}M_r ratio cycle {}: hill x{:.3f} +- {:.3f} vs linear x{:.3f} +- {:.3f}", d.empty() ? "" : "; ", k + 1,
                         h.first[k].first, h.first[k].second, l.first[k].first, l.first[k].second);
        ok.add(h.first[k].first, h.first[k].second, l.first[k].first, l.first[k].second);
      }
      d += fmt::format("; peak-q ratio: hill x{:.3f} vs linear x{:.3f}", h.second, l.second);
      out.push_back("the C5b/C5n difference is larger for hill: " + d + " -> " + verdict(ok));
    }
  }
  // 4. Wet C5b hill has a higher resilient modulus than dry.
  {
    const CaseResult *w = find("C5b", GrainModel::Hill, true), *d = find("C5b", GrainModel::Hill, false);
    if (w && d) {
      std::string detail;
      Tally ok;
      for (std::size_t k = 0; k < std::min(w->test.loops.size(), d->test.loops.size()); ++k) {
        const LoopResult &lw = w->test.loops[k], &ld = d->test.loops[k];
        const double a = mr(lw), b = mr(ld);
        detail += fmt::format("{}cycle {}: M_r wet {} vs dry {} MPa (x{:.2f})", detail.empty() ? "" : "; ", k + 1, mr_text(lw),
                              mr_text(ld), a > 0 && b > 0 ? a / b : 0.0);
        ok.add(a, mr_se(lw), b, mr_se(ld));
      }
      out.push_back("wet C5b hill has a higher resilient modulus than dry: " + detail + " -> " + verdict(ok));
    }
  }
  return out;
}
}  // namespace

std::vector<std::string> StudyResult::findings() const {
  std::vector<double> levels;  // the confinements, in case order
  for (const CaseResult& c : cases)
    if (std::find(levels.begin(), levels.end(), c.spec.confinement) == levels.end()) levels.push_back(c.spec.confinement);
  std::vector<std::string> out;
  for (double sc : levels) {
    std::vector<CaseResult> group;
    for (const CaseResult& c : cases)
      if (c.spec.confinement == sc) group.push_back(c);
    for (const std::string& f : findings_of(group))
      out.push_back(levels.size() > 1 ? fmt::format("at sigma_c = {:g} kPa: {}", sc / 1e3, f) : f);
  }
  return out;
}

std::vector<std::string> impossible_state(const SpecimenState& st, double target) {
  std::vector<std::string> out;
  for (const auto& [name, v] : {std::pair{"sigma_r", st.radial_stress}, std::pair{"sigma_bottom", st.bottom_stress},
                                std::pair{"sigma_top", st.top_stress}})
    if (!std::isfinite(v) || std::abs(v - target) > kStateTolerance * target)
      out.push_back(fmt::format("{} {:.6g} kPa, more than {:g} % from the target {:g} kPa", name, v / 1e3, 100 * kStateTolerance,
                                target / 1e3));
  if (!std::isfinite(st.porosity) || st.porosity <= 0.0 || st.porosity >= 1.0)
    out.push_back(fmt::format("vessel porosity {:.6g} outside (0, 1)", st.porosity));
  return out;
}

std::vector<std::string> impossible_results(const TriaxialResult& r) {
  std::vector<std::string> out;
  for (const LoopResult& l : r.loops) {
    if (!(l.q_a > 0.0))
      out.push_back(fmt::format("cycle {}: deviator at the reversal q_A = {:.6g} kPa under compression (must be > 0)", l.cycle,
                                l.q_a / 1e3));
    if (l.closed && !(l.loop_area >= 0.0))
      out.push_back(fmt::format("cycle {}: loop area {:.6g} J/m^3 < 0 (a loop cannot return energy)", l.cycle, l.loop_area));
    if (l.closed && !(l.damping_ratio >= 0.0))
      out.push_back(fmt::format("cycle {}: damping ratio {:.6g} < 0", l.cycle, l.damping_ratio));
    if (l.unload.valid && !(l.unload.slope > 0.0))
      out.push_back(fmt::format("cycle {}: resilient modulus {:.6g} MPa (must be > 0)", l.cycle, l.unload.slope / 1e6));
  }
  if (!(r.peak_q > 0.0)) out.push_back(fmt::format("peak deviator {:.6g} kPa under compression (must be > 0)", r.peak_q / 1e3));
  return out;
}

namespace {
std::string joined(const std::vector<std::string>& v) {
  std::string out;
  for (const std::string& s : v) out += (out.empty() ? "" : "; ") + s;
  return out;
}
}  // namespace

GrainModel packing_model(const StudySettings& settings, const CaseSpec& c) {
  return settings.pack_linear ? GrainModel::Linear : c.model;
}

PackedResult make_packed(const StudySettings& settings, const std::string& grading_name, GrainModel model, bool save,
                         std::ostream* log) {
  const auto t0 = std::chrono::steady_clock::now();
  const Grading grading = resolve_grading(grading_name);
  const fs::path dir = fs::path(settings.output_dir) / "specimens";
  const std::string stem = grading.name + "_" + to_string(model);
  PackedResult p;
  PackingSettings ps = settings.genesis.packing;
  ps.contact.model = model;
  if (!settings.specimen_file.empty()) {
    p.specimen = load_packed_specimen(settings.specimen_file, &ps);
    p.specimen.sim.interrupt = settings.genesis.interrupt;
    p.specimen.ranks = settings.genesis.ranks;  // (the whole specimen on every rank: each reads the file)
    p.file = settings.specimen_file;
    if (log)
      *log << fmt::format("specimen {}: {} grains of {} packed at {:g} kPa (seed {})\n", settings.specimen_file,
                          grain_count(p.specimen.sim), p.specimen.grading, p.specimen.pressure / 1e3, p.specimen.seed);
    if (log && !p.specimen.clump_mix.empty())
      *log << fmt::format("specimen {}: grains are clumps of {} ({} pebbles, {})\n", settings.specimen_file,
                          clump_mix_words(p.specimen.clump_mix), p.specimen.sim.clumps.pebbles.size(), to_string(p.specimen.clump_size));
    if (log)
      *log << fmt::format("specimen {}: packed with {} contacts\n", settings.specimen_file, to_string(p.specimen.packed_with));
    if (p.specimen.grading != grading.name && log)
      *log << fmt::format("note: the specimen was packed from grading '{}'; its distribution is compared with '{}'\n",
                          p.specimen.grading, grading.name);
  } else {
    GenesisSpec g = settings.genesis;
    g.grading = grading;
    std::tie(g.vessel_radius, g.vessel_height) = vessel_for(settings, grading);
    g.grain = settings.material;
    g.packing = ps;
    p.specimen = pack_specimen(g, log);  // (with ranks: the whole run on every rank)
    if (save) {
      p.file = (dir / (stem + "_packed.csv")).string();
      if (is_root(p.specimen)) save_packed_specimen(p.specimen, g.packing, p.file);
      if (log) *log << "packed specimen saved: " << p.file << "\n";
    }
  }
  p.report = grading_report(grading, p.specimen.d_mult, p.specimen.diameters());
  p.state = measure(p.specimen);
  if (const auto bad = impossible_state(p.state, p.specimen.pressure); !bad.empty())
    throw RunError(fmt::format("{}: the packed specimen is physically impossible: {}", p.file.empty() ? stem : p.file, joined(bad)));
  p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (log) *log << p.report.text() << state_text("packed", p.state);
  if (save && settings.specimen_file.empty() && is_root(p.specimen)) {
    write_file(dir / (stem + "_gsd.csv"), p.report.csv());
    const auto [vr, vh] = vessel_for(settings, grading);
    std::string gen = fmt::format("grading {}, seed {}, vessel {:g} mm x {:g} mm, P_m {:g} kPa, packed with {} contacts, friction {:g}\n",
                                  grading.name, p.specimen.seed, 2e3 * vr, 1e3 * vh, settings.genesis.packing.equilibrium.pressure / 1e3,
                                  to_string(model), ps.contact.fric);
    for (const PhaseReport& ph : p.specimen.phases) gen += ph.line() + "\n";
    gen += state_text("packed", p.state) + p.report.text();
    write_file(dir / (stem + "_genesis.txt"), gen);
  }
  return p;
}

std::string packing_table(const std::vector<PackedResult>& packed) {
  std::string out = "| grading | packed with | seed | grains | porosity (vessel) | porosity (interior) | Z | sigma_r [kPa] | "
                    "sigma_bottom [kPa] | sigma_top [kPa] | packing steps | dn per 1000 steps | time [s] |\n"
                    "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const PackedResult& p : packed) {
    std::int64_t steps = 0;
    for (const PhaseReport& ph : p.specimen.phases) steps += ph.steps;
    out += fmt::format("| {} | {} | {} | {} | {:.4f} | {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {} | {} | {:.0f} |\n", p.report.name,
                       to_string(p.specimen.packed_with), p.specimen.seed, p.state.grains, p.state.porosity, interior_text(p.state),
                       p.state.coordination, p.state.radial_stress / 1e3, p.state.bottom_stress / 1e3, p.state.top_stress / 1e3, steps,
                       packing_change_text(p.specimen.phases), p.seconds);
  }
  return out;
}

namespace {

// A log shared by work running at once: each line appears whole, prefixed with the name of the work
// that wrote it ("[C5b_Hill] ..."). Lines are written under one mutex.
class PrefixedLog : public std::streambuf {
 public:
  PrefixedLog(std::ostream& out, std::mutex& mutex, const std::string& name) : out_(out), mutex_(mutex) {
    prefix_.reserve(name.size() + 3);
    prefix_.append(1, '[').append(name).append("] ");
  }
  ~PrefixedLog() override { flush_line(); }

 protected:
  int_type overflow(int_type ch) override {
    if (ch == traits_type::eof()) return traits_type::not_eof(ch);
    line_ += static_cast<char>(ch);
    if (ch == '\n') flush_line();
    return ch;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    for (std::streamsize i = 0; i < n; ++i) overflow(traits_type::to_int_type(s[i]));
    return n;
  }

 private:
  void flush_line() {
    if (line_.empty()) return;
    if (line_.back() != '\n') line_ += '\n';
    const std::lock_guard<std::mutex> lock(mutex_);
    out_ << prefix_ << line_ << std::flush;
    line_.clear();
  }
  std::ostream& out_;
  std::mutex& mutex_;
  std::string prefix_;
  std::string line_;
};

// The cores shared by the items running at once: each gets cores / running threads (at least the
// caller's OpenMP thread count, the --threads of the CLI), so that when fewer items than cores are left
// the ones still running take the idle cores. Read by each simulation before every step.
class SharedCores : public ThreadBudget {
 public:
  SharedCores(int cores, int min_threads) : cores_(std::max(1, cores)), min_threads_(std::max(1, min_threads)) {}
  int threads() const override { return std::max(min_threads_, cores_ / std::max(1, running.load())); }
  std::atomic<int> running{0};

 private:
  int cores_, min_threads_;
};

int resolved_jobs(int jobs, std::size_t work) {
  int n = jobs > 0 ? jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(n), std::max<std::size_t>(work, 1)));
}

// Runs task(i, log) for i in [0, count) on `jobs` threads, taking the items in the given order (a
// permutation of 0..count-1; empty: index order), or one after the other in index order in the
// calling thread when jobs is 1. With `prefix` each item's log lines are prefixed with names[i];
// else the log is passed as given. With several jobs, or with share_cores, the cores are shared
// (SharedCores): each item runs with at least the caller's OpenMP thread count, more when fewer items
// than cores are left (a single job takes them all).
// After a failure no new item starts; the first failure by index is rethrown once the running items
// end.
template <class Task>
void for_each_job(std::size_t count, int jobs, bool share_cores, bool prefix, const std::vector<std::string>& names,
                  std::ostream* log, std::vector<std::size_t> order, Task&& task) {
  if (order.empty())
    for (std::size_t i = 0; i < count; ++i) order.push_back(i);
  std::mutex log_mutex;
  auto run_one = [&](std::size_t i) {
    if (!log || !prefix) return task(i, log);
    PrefixedLog buffer(*log, log_mutex, names[i]);
    std::ostream line_log(&buffer);
    task(i, &line_log);
  };
#ifdef _OPENMP
  SharedCores cores(omp_get_num_procs(), omp_get_max_threads());
#else
  SharedCores cores(1, 1);
#endif
  // The calling thread's budget and OpenMP thread count back as they were, however this ends.
  struct BudgetGuard {
    const ThreadBudget* before = thread_budget();
#ifdef _OPENMP
    int threads = omp_get_max_threads();
    ~BudgetGuard() {
      set_thread_budget(before);
      omp_set_num_threads(threads);
    }
#else
    ~BudgetGuard() { set_thread_budget(before); }
#endif
  } guard;
  if (jobs <= 1 || count <= 1) {
    if (share_cores) {  // one job: it takes every core
      cores.running = 1;
      set_thread_budget(&cores);
    }
    for (std::size_t i = 0; i < count; ++i) run_one(i);  // one at a time: in index order
    return;
  }
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::vector<std::exception_ptr> errors(count);
  auto worker = [&] {
    set_thread_budget(&cores);
    for (std::size_t k; !failed && (k = next++) < count;) {
      const std::size_t i = order[k];
      ++cores.running;
      try {
        run_one(i);
      } catch (...) {
        errors[i] = std::current_exception();
        failed = true;
      }
      --cores.running;
    }
    set_thread_budget(nullptr);
  };
  std::vector<std::thread> threads;
  for (int k = 0; k < jobs; ++k) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

// The distinct packings of the cases, in case order: the grading as given, its resolved name and the
// packing model. One per grading when the specimen is loaded from a file (its own model).
struct PackingKey {
  std::string grading, name;
  GrainModel model;
  bool operator==(const PackingKey& o) const { return name == o.name && model == o.model; }
};
std::vector<PackingKey> distinct_packings(const StudySettings& settings, const std::vector<CaseSpec>& cases) {
  std::vector<PackingKey> out;
  const bool loaded = !settings.specimen_file.empty();
  for (const CaseSpec& c : cases) {
    const PackingKey k{c.grading, resolve_grading(c.grading).name, loaded ? GrainModel::Linear : packing_model(settings, c)};
    if (std::find(out.begin(), out.end(), k) == out.end()) out.push_back(k);
  }
  return out;
}

}  // namespace

std::vector<PackedResult> make_all_packed(const StudySettings& settings, const std::vector<CaseSpec>& cases, bool save,
                                          std::ostream* log) {
  const auto packings = distinct_packings(settings, cases);
  std::vector<PackedResult> packed(packings.size());
  const bool loaded = !settings.specimen_file.empty();
  std::vector<std::string> labels;
  for (const PackingKey& k : packings)
    labels.push_back(loaded ? "specimen " + k.name : "packing " + k.name + " " + to_string(k.model));
  // Prefixed log lines whenever the study runs more than one job, so that its whole log reads alike.
  // Over MPI ranks one at a time, on the main thread (MPI is called from it alone), each with the
  // caller's threads.
  const bool ranks = settings.genesis.ranks != nullptr;
  const bool prefix = !ranks && resolved_jobs(settings.jobs, cases.size()) > 1;
  // The longest expected first (the packing time grows with the grains; hill packing is the slower).
  std::vector<std::size_t> order(packings.size());
  std::vector<double> cost(packings.size());
  for (std::size_t i = 0; i < packings.size(); ++i) {
    order[i] = i;
    double grains = 0.0;  // grains per unit solid volume, ∝ Σ φ_j / d_j³
    for (const GradingBin& b : resolve_grading(packings[i].grading).bins) grains += b.fraction / std::pow(0.5 * (b.d_lower + b.d_upper), 3);
    cost[i] = grains * (packings[i].model == GrainModel::Hill ? 1.5 : 1.0);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return cost[x] > cost[y]; });
  for_each_job(packings.size(), ranks ? 1 : resolved_jobs(settings.jobs, packings.size()), !ranks && settings.jobs != 1, prefix,
               labels, log, order,
               [&](std::size_t i, std::ostream* out) {
                 if (out) *out << fmt::format("\n=== {} ===\n", labels[i]) << std::flush;
                 packed[i] = make_packed(settings, packings[i].grading, packings[i].model, save, out);
               });
  return packed;
}

StudyResult run_study(const StudySettings& settings, const std::vector<CaseSpec>& cases, std::ostream* log) {
  validate(settings, cases);
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  const fs::path out = settings.output_dir;
  // Over MPI ranks rank 0 writes every file; every rank runs every case, one at a time.
  RunDecomposition* const ranks = settings.genesis.ranks;
  const bool root = !ranks || ranks->rank() == 0;
  if (root) fs::create_directories(out);
  // One packing per grading, all before the first case (at once when jobs allow).
  const std::vector<PackedResult> all_packed = make_all_packed(settings, cases, settings.save_specimens, log);
  // Each case's packing, looked up once (resolving a grading may read its file), before any job starts.
  const auto packings = distinct_packings(settings, cases);
  const bool loaded = !settings.specimen_file.empty();
  std::vector<const PackedResult*> packed_of(cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const PackingKey key{cases[i].grading, resolve_grading(cases[i].grading).name,
                         loaded ? GrainModel::Linear : packing_model(settings, cases[i])};
    std::size_t k = 0;
    while (!(packings[k] == key)) ++k;
    packed_of[i] = &all_packed[k];
  }
  std::vector<std::optional<CaseResult>> done(cases.size());
  std::mutex done_mutex;
  StudyResult study;
  study.criterion = criterion_text(settings.genesis.packing.equilibrium);
  std::vector<std::string> names;
  for (const CaseSpec& c : cases) names.push_back(c.name());
  const int jobs = ranks ? 1 : resolved_jobs(settings.jobs, cases.size());
  // Several at once: the longest expected first, so that the longest case does not start last (the
  // time of a case grows with its grains; measured on the study, a hill case takes ≈ 1.5 × a linear
  // one and a wet case ≈ 1.5 × a dry one). The order changes no result.
  std::vector<std::size_t> order(cases.size());
  std::vector<double> cost(cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    order[i] = i;
    cost[i] = static_cast<double>(packed_of[i]->specimen.sim.balls.size()) *
              (cases[i].model == GrainModel::Hill ? 1.5 : 1.0) * (cases[i].wet ? 1.5 : 1.0);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return cost[x] > cost[y]; });
  for_each_job(cases.size(), jobs, !ranks && settings.jobs != 1, jobs > 1, names, log, order, [&](std::size_t i, std::ostream* clog) {
    const CaseSpec& c = cases[i];
    const PackedResult& p = *packed_of[i];
    if (clog) *clog << fmt::format("\n=== {} ===\n", c.name()) << std::flush;
    const auto tc = std::chrono::steady_clock::now();
    CaseResult r;
    r.packing_seconds = p.seconds;
    r.spec = c;
    r.grading = p.report;
    r.packed = p.state;
    r.packed_with = p.specimen.packed_with;
    r.clump_template = clump_mix_text(p.specimen.clump_mix);
    r.packing_file = p.file;
    Specimen s = p.specimen;  // a copy: every case starts from the same packed state
    // Over ranks this case's part of it; the ghosts cover make_wet's gap.
    const RanksScope on_ranks(s, c.wet ? settings.moisture_gap : 0.0);
    Class5Material m = settings.material;
    m.model = c.model;
    EquilibriumSettings e = settings.finalize;
    finalize(s, m, settings.test_walls, e, clog);
    if (c.wet) make_specimen_wet(s, settings.suction, settings.moisture_gap, e, clog);
    TriaxialSettings ts = settings.triaxial;
    ts.confinement = r.confinement = confinement_of(settings, c);
    if (ts.confinement != e.pressure) {  // isotropic at σ_c before the test
      EquilibriumSettings ce = e;
      ce.pressure = ts.confinement;
      servo_equilibrium(s, ce, "confine " + s.material, clog);
    }
    r.initial = measure(s);
    r.phases = s.phases;
    if (const auto bad = impossible_state(r.initial, ts.confinement); !bad.empty())
      throw RunError(fmt::format("case {}: the state at the test start is physically impossible: {}", c.name(), joined(bad)));
    r.test = run_triaxial(s, ts, clog);
    if (const auto bad = impossible_results(r.test); !bad.empty())
      throw RunError(fmt::format("case {}: physically impossible results (no summary written): {}", c.name(), joined(bad)));
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
    const fs::path dir = out / c.name();
    r.dir = dir.string();
    if (!root) {
      done[i] = std::move(r);  // (one case at a time over ranks)
      return;
    }
    write_file(dir / "history.csv", r.test.history_csv());
    write_file(dir / "loops.csv", loops_csv(r.test.loops));
    write_file(dir / "gsd.csv", r.grading.csv());
    std::string gen = fmt::format("case {}: grading {}, material {}, {}\n", c.name(), r.grading.name, to_string(c.model),
                                  c.wet ? fmt::format("wet (make_wet {:g} kPa, {:g} mm)", settings.suction / 1e3, settings.moisture_gap * 1e3)
                                        : "dry");
    for (const PhaseReport& ph : r.phases) gen += ph.line() + "\n";
    gen += state_text("packed", r.packed) + state_text("test start", r.initial);
    gen += r.grading.text() + r.test.loops_text();
    write_file(dir / "genesis.txt", gen);
    // The summary so far: the cases that have ended, in case order.
    const std::lock_guard<std::mutex> lock(done_mutex);
    done[i] = std::move(r);
    StudyResult so_far;
    so_far.criterion = study.criterion;
    for (const auto& d : done)
      if (d) so_far.cases.push_back(*d);
    write_file(out / "summary.csv", so_far.summary_csv());
    write_file(out / "summary.md", so_far.summary_markdown());
  });
  for (auto& d : done) study.cases.push_back(std::move(*d));
  study.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  study.cpu_seconds = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  if (root) {
    write_file(out / "summary.csv", study.summary_csv());
    write_file(out / "summary.md", study.summary_markdown());
  }
  return study;
}

}  // namespace hilldem
