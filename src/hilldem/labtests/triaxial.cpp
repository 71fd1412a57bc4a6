#include "hilldem/labtests/triaxial.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <ostream>
#include <stdexcept>

#include "hilldem/core/error.hpp"

namespace hilldem {

const char* to_string(TriaxialPhase p) {
  switch (p) {
    case TriaxialPhase::Load: return "load";
    case TriaxialPhase::Unload: return "unload";
    case TriaxialPhase::Reload: return "reload";
    case TriaxialPhase::Final: return "final";
  }
  return "?";
}

void validate(const TriaxialSettings& t) {
  auto bad = [](const std::string& what, double v, const std::string& range) {
    return InputError(fmt::format("{} must be {}, got {:g}", what, range, v));
  };
  if (!(t.confinement > 0) || !std::isfinite(t.confinement)) throw bad("confinement [Pa]", t.confinement, "> 0");
  double prev = 0.0;
  for (std::size_t k = 0; k < t.cycle_strains.size(); ++k) {
    const double e = t.cycle_strains[k];
    if (!std::isfinite(e) || e <= prev)
      throw InputError(fmt::format("cycle strains must be positive and increasing: cycle {} at {:g} % follows {:g} %", k + 1,
                                   100 * e, 100 * prev));
    prev = e;
  }
  if (!std::isfinite(t.final_strain) || t.final_strain <= prev)
    throw InputError(fmt::format("final strain ({:g} %) must exceed the last cycle strain ({:g} %)", 100 * t.final_strain,
                                 100 * prev));
  if (t.final_strain >= 0.5) throw bad("final strain", t.final_strain, "below 0.5 (50 %)");
  if (!(t.unload_fraction >= 0 && t.unload_fraction < 1)) throw bad("unload fraction", t.unload_fraction, "in [0, 1)");
  if (!(t.strain_rate > 0) || !std::isfinite(t.strain_rate)) throw bad("strain rate [1/s]", t.strain_rate, "> 0");
  if (!(t.final_strain_rate > 0) || !std::isfinite(t.final_strain_rate))
    throw bad("final strain rate [1/s]", t.final_strain_rate, "> 0");
  if (!(t.servo_gain > 0 && t.servo_gain <= 1)) throw bad("servo gain", t.servo_gain, "in (0, 1]");
  if (!(t.wall_speed_limit > 0) || !std::isfinite(t.wall_speed_limit)) throw bad("wall speed limit [m/s]", t.wall_speed_limit, "> 0");
  if (!(t.cycle_record_strain >= 0) || !std::isfinite(t.cycle_record_strain))
    throw bad("cycle record strain", t.cycle_record_strain, ">= 0");
  if (t.final_records < 1) throw bad("final records", t.final_records, ">= 1");
  if (t.max_steps < 1) throw bad("max steps", static_cast<double>(t.max_steps), ">= 1");
  if (!(t.density_scaling == 0 || (t.density_scaling >= 1 && t.density_scaling <= 50)))
    throw bad("density scaling factor", t.density_scaling, "0 (off) or in [1, 50]");
}

// ---------------------------------------------------------------------------------------------------
// Loops

LineFit fit_branch(const std::vector<double>& strain, const std::vector<double>& q, double lo, double hi) {
  std::vector<double> x, y;
  for (std::size_t i = 0; i < std::min(strain.size(), q.size()); ++i)
    if (q[i] >= lo && q[i] <= hi) x.push_back(strain[i]), y.push_back(q[i]);
  return fit_line(x, y);
}

void LoopTracker::close_current() {
  LoopResult& l = cur_;
  const double de = l.eps_a - l.eps_b, dq = l.q_a - l.q_b;
  const double trim = kFitTrim * dq;
  l.unload = fit_branch(unload_e_, unload_q_, l.q_b + trim, l.q_a - trim);
  const double q_end = l.closed ? l.q_c : (reload_q_.empty() ? l.q_b : *std::max_element(reload_q_.begin(), reload_q_.end()));
  l.reload = fit_branch(reload_e_, reload_q_, l.q_b + trim, q_end - trim);
  if (de > 0.0) {
    l.unload_secant = dq / de;
    if (l.closed) l.reload_secant = (l.q_c - l.q_b) / de;
    if (l.closed && dq > 0.0) l.damping_ratio = 2.0 * l.loop_area / (std::numbers::pi * dq * de);
  }
  done_.push_back(l);
  open_ = false;
}

void LoopTracker::add(TriaxialPhase phase, int cycle, double strain, double q) {
  if (phase == TriaxialPhase::Unload && (!open_ || cur_.cycle != cycle)) {
    if (open_) close_current();
    cur_ = LoopResult{};
    cur_.cycle = cycle;
    // A is the last point before unloading (or this one, if the path starts here).
    cur_.eps_a = have_prev_ ? prev_strain_ : strain;
    cur_.q_a = have_prev_ ? prev_q_ : q;
    cur_.eps_b = cur_.eps_a, cur_.q_b = cur_.q_a;
    unload_e_.assign(1, cur_.eps_a), unload_q_.assign(1, cur_.q_a);
    reload_e_.clear(), reload_q_.clear();
    open_ = true;
  }
  if (open_) {
    const bool same_loop = cur_.cycle == cycle;
    if (phase == TriaxialPhase::Unload && same_loop) {
      if (have_prev_) cur_.loop_area += 0.5 * (q + prev_q_) * (strain - prev_strain_);
      cur_.eps_b = strain, cur_.q_b = q;
      unload_e_.push_back(strain), unload_q_.push_back(q);
    } else if (phase == TriaxialPhase::Reload && same_loop) {
      if (strain >= cur_.eps_a) {  // back at ε_A: C by linear interpolation, the loop closes
        const double span = strain - prev_strain_;
        const double t = span > 0.0 ? (cur_.eps_a - prev_strain_) / span : 1.0;
        cur_.q_c = prev_q_ + t * (q - prev_q_);
        cur_.loop_area += 0.5 * (prev_q_ + cur_.q_c) * (cur_.eps_a - prev_strain_);
        reload_e_.push_back(cur_.eps_a), reload_q_.push_back(cur_.q_c);
        cur_.closed = true;
        close_current();
      } else {
        cur_.loop_area += 0.5 * (q + prev_q_) * (strain - prev_strain_);
        if (reload_e_.empty()) reload_e_.push_back(cur_.eps_b), reload_q_.push_back(cur_.q_b);
        reload_e_.push_back(strain), reload_q_.push_back(q);
      }
    } else {
      close_current();  // left the loop without closing it
    }
  }
  have_prev_ = true;
  prev_phase_ = phase;
  prev_strain_ = strain, prev_q_ = q;
}

std::vector<LoopResult> LoopTracker::loops() const {
  if (!open_) return done_;
  LoopTracker copy = *this;
  copy.close_current();
  return copy.done_;
}

// ---------------------------------------------------------------------------------------------------
// The test

TriaxialResult run_triaxial(Specimen& s, const TriaxialSettings& t, std::ostream* log) {
  validate(t);
  const auto t0 = std::chrono::steady_clock::now();
  Simulation& sim = s.sim;
  const Vessel v = s.vessel;
  TriaxialResult res;
  const double h0 = res.height0 = v.height(sim);
  const double r0 = res.radius0 = v.radius(sim);
  const double time0 = sim.time;
  const std::int64_t step0 = sim.steps;

  // Density scaling for the test only: the settings are restored when it ends (or throws).
  struct SettingsScope {
    Simulation& sim;
    SimulationSettings saved;
    bool active;
    ~SettingsScope() {
      if (active) sim.settings = saved;
    }
  } settings_scope{sim, sim.settings, t.density_scaling > 0};
  if (t.density_scaling > 0) {
    sim.update_forces();
    const double dt = t.density_scaling * sim.next_timestep();
    sim.settings.auto_timestep = false;
    sim.settings.timestep = dt;
    sim.settings.density_scaling = true;
    if (log) *log << fmt::format("triaxial: density scaling, fixed time step {:.4g} s ({:g} x the automatic one)\n", dt,
                                 t.density_scaling);
  }

  Servo servo = v.radial_servo(ServoSettings{t.confinement, t.servo_gain, t.wall_speed_limit});
  double closing = 0.0;  // each platen's speed towards the other [m/s]

  const std::size_t n_cycles = t.cycle_strains.size();
  TriaxialPhase phase = n_cycles > 0 ? TriaxialPhase::Load : TriaxialPhase::Final;
  std::size_t k = 0;  // current cycle index
  double eps_rev = 0.0, q_rev = 0.0;
  const double cycle_rec = t.cycle_record_strain > 0 ? t.cycle_record_strain
                                                      : (n_cycles > 0 ? t.cycle_strains[0] / 100.0 : t.final_strain / 500.0);
  const double start_final = n_cycles > 0 ? t.cycle_strains.back() : 0.0;
  const double final_rec = (t.final_strain - start_final) / t.final_records;
  LoopTracker tracker;
  double last_rec_eps = -1.0;
  bool force_record = true;

  auto row_now = [&](TriaxialPhase p, int cycle) {
    TriaxialRow r;
    r.step = sim.steps - step0;
    r.time = sim.time - time0;
    r.phase = p;
    r.cycle = cycle;
    const double h = v.height(sim), rad = v.radius(sim);
    r.eps_a = (h0 - h) / h0;
    r.eps_r = (r0 - rad) / r0;
    r.eps_v = r.eps_a + 2.0 * r.eps_r;
    r.sigma_top = v.top_stress(sim);
    r.sigma_bottom = v.bottom_stress(sim);
    r.sigma_a = 0.5 * (r.sigma_top + r.sigma_bottom);
    r.sigma_r = v.radial_stress(sim);
    r.q = r.sigma_a - r.sigma_r;
    r.platen_mismatch = r.sigma_a > 0 ? std::abs(r.sigma_top - r.sigma_bottom) / r.sigma_a : 0.0;
    return r;
  };
  auto record = [&](TriaxialRow r) {
    if (decomposed(s)) {
      // Over ranks without a gather: measure's formulas on the whole run's grains and solid volume
      // (taken when attached) and its touching grain-grain rows, an integer sum over the ranks.
      r.porosity = 1.0 - s.whole_solid / v.volume(sim);
      const std::size_t touching = whole_run_rows(s, [](const ContactStore& c, std::size_t k) {
        return c.exists[k] && c.key[k].kind == ContactKind::BallBall && c.active[k] && c.gap[k] < 0.0;
      });
      r.coordination = s.whole_grains > 0 ? 2.0 * static_cast<double>(touching) / static_cast<double>(s.whole_grains) : 0.0;
    } else {
      const SpecimenState st = measure(s, false);
      r.porosity = st.porosity;
      r.coordination = st.coordination;
    }
    res.history.push_back(r);
    last_rec_eps = r.eps_a;
  };
  if (log)
    *log << fmt::format("triaxial: confinement {:g} kPa, H0 {:.2f} mm, R0 {:.2f} mm, cycles at {} %, final {:g} %, "
                        "strain rate {:g} /s (cycles) and {:g} /s (final)\n",
                        t.confinement / 1e3, h0 * 1e3, r0 * 1e3,
                        [&] {
                          std::string out;
                          for (double e : t.cycle_strains) out += (out.empty() ? "" : ", ") + fmt::format("{:g}", 100 * e);
                          return out.empty() ? std::string("none") : out;
                        }(),
                        100 * t.final_strain, t.strain_rate, t.final_strain_rate);
  record(row_now(phase, n_cycles > 0 ? 1 : 0));  // the initial state
  tracker.add(phase, 1, res.history.back().eps_a, res.history.back().q);

  // The cycles run through Simulation::drive: the servo and the platens are set in its plan, and
  // a cycle after which the test may record a row (its porosity and coordination read the
  // contacts) or change phase is planned as the call's last, so that its results are written. The
  // strain conditions are predicted from the platens' speed over the coming Δt, within a slack far
  // above the rounding (1e-16) and far below any threshold (≥ 1e-7 here); the unload's end, decided
  // on q, is not predicted: every unload cycle is written. So every row and decision is made on the
  // state that cycle(1) after each cycle gives, bit for bit (test
  // Triaxial.DrivenCyclesGiveTheResultsOfWatchedCycles); the other cycles skip writing what nobody reads.
  constexpr double kStrainSlack = 1e-12;  // [-]
  auto may_need_results = [&](double dt) {
    if (force_record || phase == TriaxialPhase::Unload || sim.steps + 1 - step0 >= t.max_steps) return true;
    const double h = v.height(sim);
    const double eps_next = (h0 - (h - 2.0 * closing * dt)) / h0;  // closing ≥ 0 outside the unload
    const double rec = phase == TriaxialPhase::Final ? final_rec : cycle_rec;
    if (std::abs(eps_next - last_rec_eps) >= rec - kStrainSlack) return true;
    const double limit = phase == TriaxialPhase::Load     ? t.cycle_strains[k]
                         : phase == TriaxialPhase::Reload ? eps_rev
                                                          : t.final_strain;
    return eps_next >= limit - kStrainSlack;
  };
  // The end of a cycle: its row, the peaks, the records and the phase; true when the test is over.
  // `written`: the cycle's results were written (drive's last); one that was not cannot need them.
  auto after_cycle = [&](bool written) {
    auto need = [&](const char* what) {
      if (!written)
        throw std::logic_error(fmt::format("triaxial test: {} at step {} after a cycle that was not planned to write its results",
                                           what, sim.steps - step0));
    };
    const int cycle = phase == TriaxialPhase::Final ? 0 : static_cast<int>(k) + 1;
    const TriaxialRow r = row_now(phase, cycle);
    const double conf_err = std::abs(r.sigma_r - t.confinement) / t.confinement;
    if (conf_err > res.worst_confinement_error) res.worst_confinement_error = conf_err, res.worst_confinement_strain = r.eps_a;
    if (r.platen_mismatch > res.worst_platen_mismatch) res.worst_platen_mismatch = r.platen_mismatch, res.worst_mismatch_strain = r.eps_a;
    if (r.q > res.peak_q)
      res.peak_q = r.q, res.peak_strain = r.eps_a, res.peak_radial_strain = r.eps_r, res.peak_volumetric_strain = r.eps_v;
    tracker.add(phase, cycle, r.eps_a, r.q);
    const double rec = phase == TriaxialPhase::Final ? final_rec : cycle_rec;
    if (force_record || std::abs(r.eps_a - last_rec_eps) >= rec) {
      need("a row to record");
      record(r);
    }
    force_record = false;

    if (log && r.step % 20000 == 0) {
      *log << fmt::format("  {:>6} step {:>8}: eps_a {:.4f} %  q {:.2f} kPa  sigma_r {:.2f} kPa  dt {:.3g} s\n", to_string(phase),
                          r.step, 100 * r.eps_a, r.q / 1e3, r.sigma_r / 1e3, sim.last_dt);
      log->flush();
    }
    // Phase changes, decided on this cycle's state; the row of the turning point is always recorded.
    TriaxialPhase next = phase;
    if (phase == TriaxialPhase::Load && r.eps_a >= t.cycle_strains[k]) {
      next = TriaxialPhase::Unload;
      eps_rev = r.eps_a, q_rev = r.q;
    } else if (phase == TriaxialPhase::Unload && (r.q <= t.unload_fraction * q_rev || r.eps_a <= 0.0)) {
      next = TriaxialPhase::Reload;
    } else if (phase == TriaxialPhase::Reload && r.eps_a >= eps_rev) {
      ++k;
      next = k < n_cycles ? TriaxialPhase::Load : TriaxialPhase::Final;
    } else if (phase == TriaxialPhase::Final && r.eps_a >= t.final_strain) {
      need("the final strain");
      if (res.history.back().step != r.step) record(r);
      return true;
    }
    if (next != phase) {
      need("a phase change");
      if (res.history.back().step != r.step) record(r);
      force_record = true;
      if (log)
        *log << fmt::format("  {:>6} {}: eps_a {:.5f} %  q {:.2f} kPa  sigma_r {:.2f} kPa  step {}\n", to_string(phase),
                            cycle, 100 * r.eps_a, r.q / 1e3, r.sigma_r / 1e3, r.step);
      if (log) log->flush();
      phase = next;
    }
    if (sim.steps - step0 >= t.max_steps) {
      need("the step limit");
      v.stop(sim);
      throw RunError(fmt::format("triaxial test: final strain {:g} % not reached within {} steps (at {:.4f} %)",
                                 100 * t.final_strain, t.max_steps, 100 * r.eps_a));
    }
    return false;
  };
  bool pending = false;  // a cycle ran whose end after_cycle has not seen
  for (bool done = false; !done;) {
    sim.drive(t.max_steps, [&](double dt) {
      if (pending) after_cycle(false);  // (it cannot end the test: may_need_results planned that cycle as the last)
      pending = true;
      const double rate = phase == TriaxialPhase::Final ? t.final_strain_rate : t.strain_rate;
      closing = (phase == TriaxialPhase::Unload ? -0.5 : 0.5) * rate * h0;
      servo.control(sim, dt);
      sim.walls.walls[v.top].velocity = Vec3{0, 0, -closing};
      sim.walls.walls[v.bottom].velocity = Vec3{0, 0, closing};
      return may_need_results(dt);
    });
    pending = false;
    done = after_cycle(true);
  }
  v.stop(sim);
  res.loops = tracker.loops();
  for (LoopResult& l : res.loops)
    if (l.cycle >= 1 && static_cast<std::size_t>(l.cycle) <= n_cycles) l.target_strain = t.cycle_strains[l.cycle - 1];
  res.steps = sim.steps - step0;
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (log) {
    *log << res.loops_text();
    *log << fmt::format("triaxial: {} steps, {:.1f} s; peak q {:.2f} kPa at eps_a {:.3f} % (eps_r {:.3f} %, eps_v {:.3f} %); "
                        "worst confinement error {:.3f} % "
                        "(at {:.4f} %); worst platen mismatch {:.2f} % (at {:.4f} %)\n",
                        res.steps, res.seconds, res.peak_q / 1e3, 100 * res.peak_strain, 100 * res.peak_radial_strain,
                        100 * res.peak_volumetric_strain, 100 * res.worst_confinement_error,
                        100 * res.worst_confinement_strain, 100 * res.worst_platen_mismatch, 100 * res.worst_mismatch_strain);
  }
  return res;
}

std::string TriaxialResult::history_csv() const {
  std::string out =
      "step,time[s],phase,cycle,eps_a[-],eps_r[-],eps_v[-],sigma_a[Pa],sigma_r[Pa],q[Pa],sigma_top[Pa],sigma_bottom[Pa],"
      "porosity[-],coordination[-],platen_mismatch[-]\n";
  for (const TriaxialRow& r : history)
    out += fmt::format("{},{:.9g},{},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.7g},{:.6g},{:.5g}\n", r.step,
                       r.time, to_string(r.phase), r.cycle, r.eps_a, r.eps_r, r.eps_v, r.sigma_a, r.sigma_r, r.q, r.sigma_top,
                       r.sigma_bottom, r.porosity, r.coordination, r.platen_mismatch);
  return out;
}

std::string fit_text(const LineFit& f) {
  if (!f.valid) return fmt::format("n/a ({} points in the fitted part)", f.points);
  return fmt::format("{:.1f} +- {:.1f}", f.slope / 1e6, f.slope_se / 1e6);
}

std::string TriaxialResult::loops_text() const {
  std::string out;
  for (const LoopResult& l : loops)
    out += fmt::format("  cycle {} (reversal at {:.4f} %): resilient modulus M_r (unload fit) {} MPa, unload secant {:.1f} MPa; "
                       "reload fit {} MPa, reload secant {} MPa; loop area {:.4g} J/m^3; damping ratio {}\n",
                       l.cycle, 100 * l.eps_a, fit_text(l.unload), l.unload_secant / 1e6, fit_text(l.reload),
                       l.closed ? fmt::format("{:.1f}", l.reload_secant / 1e6) : std::string("n/a (loop not closed)"),
                       l.loop_area, l.closed ? fmt::format("{:.4f}", l.damping_ratio) : std::string("n/a"));
  return out;
}

}  // namespace hilldem
