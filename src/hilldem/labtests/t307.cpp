#include "hilldem/labtests/t307.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <ostream>

#include "hilldem/core/error.hpp"

namespace hilldem {

void validate(const T307Settings& t) {
  validate(t.timing);
  if (t.sequences.empty()) throw InputError("T 307: no sequences to run");
  for (const T307Sequence& s : t.sequences) {
    const double v[] = {s.confining, s.max_stress, s.cyclic, s.contact};
    for (double x : v)
      if (!(x >= 0) || !std::isfinite(x))
        throw InputError(fmt::format("T 307 sequence {}: stresses must be finite and >= 0 Pa, got sigma3 {:g}, sigma_max {:g}, "
                                     "sigma_cyclic {:g}, sigma_contact {:g} Pa",
                                     s.number, s.confining, s.max_stress, s.cyclic, s.contact));
    if (!(s.confining > 0) || !(s.cyclic > 0))
      throw InputError(fmt::format("T 307 sequence {}: sigma3 and sigma_cyclic must be > 0 Pa, got {:g} and {:g}", s.number,
                                   s.confining, s.cyclic));
  }
  if (!(t.max_permanent_strain > 0 && t.max_permanent_strain <= 0.5))
    throw InputError(fmt::format("T 307: permanent strain limit must be in (0, 0.5], got {:g}", t.max_permanent_strain));
  if (t.max_steps < 1) throw InputError(fmt::format("T 307: max steps must be >= 1, got {}", t.max_steps));
}

T307Result run_t307(Specimen& s, const T307Settings& t, std::ostream* log) {
  validate(t);
  const auto wall0 = std::chrono::steady_clock::now();
  Simulation& sim = s.sim;
  const Vessel v = s.vessel;
  T307Result res;
  const double h0 = res.height0 = v.height(sim);
  const double r0 = res.radius0 = v.radius(sim);
  const std::int64_t step0 = sim.steps;
  const T307Timing& tm = t.timing;
  v.stop(sim);

  // What the controller follows: σ_r → radial, σ_top → axial_base + cyclic · haversine(t − pulse_start).
  struct Targets {
    double radial = 0.0, axial_base = 0.0, cyclic = 0.0;
    double pulse_start = std::numeric_limits<double>::infinity();  // no pulse
    double axial = 0.0;  // the axial target at the end of the coming step [Pa]
  };
  Targets targets;
  const ServoSettings ss{t.sequences.front().confining, tm.servo_gain, tm.wall_speed_limit};
  Servo radial = v.radial_servo(ss);
  Servo axial = v.platen_servo(true, ss);
  const double pulse = tm.pulse_duration;
  auto control = [&](double dt) {
    // The target at t + Δt: the wall velocity set now acts over the coming step.
    targets.axial = targets.axial_base + targets.cyclic * haversine(sim.time + dt - targets.pulse_start, pulse);
    radial.settings.target_stress = targets.radial;
    axial.settings.target_stress = targets.axial;
    radial.control(sim, dt);
    axial.control(sim, dt);
  };
  auto eps_a = [&] { return (h0 - v.height(sim)) / h0; };
  auto eps_r = [&] { return (r0 - v.radius(sim)) / r0; };
  auto check_limit = [&] {
    if (sim.steps - step0 >= t.max_steps) {
      v.stop(sim);
      throw RunError(fmt::format("T 307: not finished within {} steps", t.max_steps));
    }
  };
  // Cycles until `duration` [s] has passed since `start` (at least one), calling after() at the end of
  // each with what the walls say. Through Simulation::drive: the servos are set in its plan, and only
  // the last cycle writes its results. The time after a cycle is time + Δt, the same addition as
  // the engine's, so the last cycle is known before it runs (and the test reads only walls and the
  // clock: the same bits as cycle(1) after each cycle).
  auto run_for = [&](double start, double duration, const auto& after) {
    bool pending = false;  // a cycle ran whose end after() has not seen
    do {
      sim.drive(t.max_steps, [&](double dt) {
        if (pending) after(), check_limit();
        pending = true;
        control(dt);
        return !(sim.time + dt - start < duration) || sim.steps + 1 - step0 >= t.max_steps;
      });
      pending = false;
      after();
      check_limit();
    } while (sim.time - start < duration);
  };
  if (log)
    *log << fmt::format("t307: H0 {:.2f} mm, R0 {:.2f} mm; pulse {:g} s, rest {:g} s, settle {:g} s, {} cycles per sequence "
                        "({} conditioning), M_r from the last {}\n",
                        h0 * 1e3, r0 * 1e3, tm.pulse_duration, tm.rest_duration, tm.settle_duration, tm.cycles,
                        tm.conditioning_cycles, tm.averaged_cycles);

  double eps_first = std::numeric_limits<double>::quiet_NaN();  // ε_a at the first sequence after conditioning
  for (const T307Sequence& seq : t.sequences) {
    if (res.stopped) break;
    const int n = seq.number == 0 ? tm.conditioning_cycles : tm.cycles;
    if (n == 0) continue;
    const std::int64_t seq_step0 = sim.steps;
    targets.radial = seq.confining;
    targets.axial_base = seq.confining + seq.contact;
    targets.pulse_start = std::numeric_limits<double>::infinity();
    run_for(sim.time, tm.settle_duration, [] {});
    const double eps_start = eps_a();
    if (seq.number != 0 && std::isnan(eps_first)) eps_first = eps_start;
    double gain = 1.0;  // commanded / target pulse amplitude, from 1 at each sequence's first cycle
    T307Row row;
    row.nominal = seq;
    row.cycles = n;
    for (int c = 1; c <= n; ++c) {
      T307Cycle cy;
      cy.sequence = seq.number, cy.cycle = c;
      cy.command = targets.cyclic = gain * seq.cyclic;
      targets.pulse_start = sim.time;
      double eps_max = -std::numeric_limits<double>::infinity(), eps_r_at_max = 0.0;
      cy.q_peak = -std::numeric_limits<double>::infinity();
      run_for(targets.pulse_start, tm.pulse_duration + tm.rest_duration, [&] {
        const double sig_r = v.radial_stress(sim), q = v.axial_stress(sim) - sig_r, ea = eps_a();
        if (q > cy.q_peak) cy.q_peak = q, cy.sigma_r_peak = sig_r;
        if (ea > eps_max) eps_max = ea, eps_r_at_max = eps_r();
      });
      cy.q_end = v.axial_stress(sim) - v.radial_stress(sim);
      cy.eps_a_end = eps_a();
      cy.recoverable_axial = eps_max - cy.eps_a_end;
      cy.recoverable_radial = eps_r_at_max - eps_r();
      cy.modulus = cy.recoverable_axial > 0 ? (cy.q_peak - cy.q_end) / cy.recoverable_axial
                                            : std::numeric_limits<double>::quiet_NaN();
      const double amplitude = cy.q_peak - cy.q_end;
      cy.amplitude_error = amplitude / seq.cyclic - 1.0;
      // Peak compensation: the next command scaled by target / measured, within [0.5, 3] × the target.
      if (amplitude > 0) gain = std::clamp(gain * seq.cyclic / amplitude, 0.5, 3.0);
      res.cycles.push_back(cy);
      // The standard's stop, in the conditioning (from its start) as in the sequences (from the first one's).
      const double eps_ref = std::isnan(eps_first) ? eps_start : eps_first;
      if (cy.eps_a_end - eps_ref > t.max_permanent_strain) {
        res.stopped = true;
        res.stop_reason = fmt::format("total permanent axial strain {:.3g} % passed the limit {:g} % in sequence {}, cycle {}",
                                      100 * (cy.eps_a_end - eps_ref), 100 * t.max_permanent_strain, seq.number, c);
        row.cycles = c;
        break;
      }
    }
    // Means over the last `averaged` cycles of this sequence.
    row.averaged = std::min(row.cycles, tm.averaged_cycles);
    const std::size_t first = res.cycles.size() - static_cast<std::size_t>(row.averaged);
    double nu = 0.0;
    for (std::size_t k = first; k < res.cycles.size(); ++k) {
      const T307Cycle& cy = res.cycles[k];
      const double w = 1.0 / row.averaged;
      row.cyclic_stress += w * (cy.q_peak - cy.q_end);
      row.max_deviator += w * cy.q_peak;
      row.confining += w * cy.sigma_r_peak;
      row.recoverable_axial += w * cy.recoverable_axial;
      row.modulus += w * cy.modulus;
      row.amplitude_error += w * cy.amplitude_error;
      nu += w * (-cy.recoverable_radial / cy.recoverable_axial);
    }
    row.poisson = nu;
    row.bulk_stress = 3.0 * row.confining + row.max_deviator;  // σ_a + 2σ_r with σ_a = σ_r + q
    row.octahedral_shear = std::numbers::sqrt2 / 3.0 * row.max_deviator;
    row.permanent_strain = res.cycles.back().eps_a_end - eps_start;
    row.total_permanent_strain = seq.number == 0 ? row.permanent_strain : res.cycles.back().eps_a_end - eps_first;
    row.steps = sim.steps - seq_step0;
    res.rows.push_back(row);
    if (log) {
      *log << fmt::format("  sequence {:>2}: sigma3 {:6.1f} kPa, sigma_cyc {:6.1f} kPa (measured {:6.1f}): M_r {:8.2f} MPa, "
                          "nu {:6.3f}, permanent strain {:.3e}, {} steps\n",
                          seq.number, seq.confining / 1e3, seq.cyclic / 1e3, row.cyclic_stress / 1e3, row.modulus / 1e6,
                          row.poisson, row.permanent_strain, row.steps);
      if (res.stopped) *log << "t307: stopped: " << res.stop_reason << "\n";
      log->flush();
    }
  }
  v.stop(sim);
  std::vector<UniversalPoint> pts;
  for (const T307Row& r : res.rows)
    if (r.nominal.number != 0 && r.cycles == (r.nominal.number == 0 ? tm.conditioning_cycles : tm.cycles) && r.modulus > 0 &&
        std::isfinite(r.modulus))
      pts.push_back({r.bulk_stress, r.octahedral_shear, r.modulus});
  try {
    res.fit = fit_universal_model(pts);
    res.fitted = true;
  } catch (const InputError& e) {
    res.fit_error = e.what();
  }
  res.timestep = sim.last_dt;
  res.steps = sim.steps - step0;
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (log)
    *log << fmt::format("t307: {} steps, {:.1f} s; {}\n", res.steps, res.seconds,
                        res.fitted ? res.fit.text() : "no fit: " + res.fit_error);
  return res;
}

std::string T307Result::sequences_csv() const {
  std::string out =
      "seq,sigma3[Pa],sigma_max[Pa],sigma_cyclic[Pa],sigma_contact[Pa],theta_nominal[Pa],tau_oct_nominal[Pa],"
      "sigma3_measured[Pa],sigma_cyclic_measured[Pa],theta[Pa],tau_oct[Pa],M_r[Pa],poisson[-],permanent_strain[-],"
      "total_permanent_strain[-],recoverable_strain[-],amplitude_error[-],cycles,averaged,steps\n";
  for (const T307Row& r : rows) {
    if (r.nominal.number == 0) continue;
    const T307Sequence& n = r.nominal;
    out += fmt::format("{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},{:.5g},{:.6g},{:.6g},{:.6g},"
                       "{:.4g},{},{},{}\n",
                       n.number, n.confining, n.max_stress, n.cyclic, n.contact, n.bulk_stress(), n.octahedral_shear(), r.confining,
                       r.cyclic_stress, r.bulk_stress, r.octahedral_shear, r.modulus, r.poisson, r.permanent_strain,
                       r.total_permanent_strain, r.recoverable_axial, r.amplitude_error, r.cycles, r.averaged, r.steps);
  }
  return out;
}

std::string T307Result::cycles_csv() const {
  std::string out =
      "seq,cycle,q_peak[Pa],q_end[Pa],sigma_r_peak[Pa],recoverable_axial[-],recoverable_radial[-],eps_a_end[-],M_r[Pa],"
      "command[Pa],amplitude_error[-]\n";
  for (const T307Cycle& c : cycles)
    out += fmt::format("{},{},{:.7g},{:.7g},{:.7g},{:.6g},{:.6g},{:.7g},{:.7g},{:.7g},{:.4g}\n", c.sequence, c.cycle, c.q_peak,
                       c.q_end, c.sigma_r_peak, c.recoverable_axial, c.recoverable_radial, c.eps_a_end, c.modulus, c.command,
                       c.amplitude_error);
  return out;
}

std::string T307Result::text() const {
  std::string out =
      "| seq | sigma3 [kPa] | sigma_cyc [kPa] | measured [kPa] | theta [kPa] | tau_oct [kPa] | M_r [MPa] | nu [-] | "
      "eps_p [-] | amplitude error [%] |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const T307Row& r : rows)
    out += fmt::format("| {} | {:.1f} | {:.1f} | {:.1f} | {:.1f} | {:.1f} | {:.2f} | {:.3f} | {:.3e} | {:.2f} |\n",
                       r.nominal.number == 0 ? std::string("0 (cond.)") : std::to_string(r.nominal.number), r.nominal.confining / 1e3,
                       r.nominal.cyclic / 1e3, r.cyclic_stress / 1e3, r.bulk_stress / 1e3, r.octahedral_shear / 1e3,
                       r.modulus / 1e6, r.poisson, r.permanent_strain, 100 * r.amplitude_error);
  if (stopped) out += "stopped: " + stop_reason + "\n";
  out += fitted ? fit.text() + "\n" : "no universal-model fit: " + fit_error + "\n";
  return out;
}

}  // namespace hilldem
