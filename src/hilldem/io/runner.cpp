#include "hilldem/io/runner.hpp"

#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <ostream>

#include "hilldem/core/error.hpp"

namespace hilldem {

const ProbeValue* RunResult::find(const std::string& label) const {
  for (const ProbeValue& p : probes)
    if (p.label == label) return &p;
  return nullptr;
}

std::string contact_listing(const Simulation& sim) {
  std::string out = fmt::format("{:<24} {:<7} {:>12} {:>12} {:<5} {}\n", "pieces", "model", "gap[m]",
                                "normal[N]", "state", "assigned by");
  const ContactStore& c = sim.contacts;
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (!c.exists[k]) continue;
    const ContactKey& key = c.key[k];
    const std::string pieces =
        key.kind == ContactKind::BallBall
            ? fmt::format("ball {} - ball {}", sim.balls.id[key.a], sim.balls.id[key.b])
            : fmt::format("ball {} - wall {}", sim.balls.id[key.a], sim.walls.walls[key.b].name);
    const char* state = c.model[k] == ModelKind::Linear ? "-"
                        : c.moisture[k] == Moisture::Wet ? "wet"
                        : c.moisture[k] == Moisture::Ruptured ? "rupt"
                                                              : "dry";
    out += fmt::format("{:<24} {:<7} {:>12.5g} {:>12.5g} {:<5} {}\n", pieces, to_string(c.model[k]), c.gap[k],
                       c.normal_force[k], state, sim.table.explain(c.rule[k]));
  }
  out += fmt::format("{} contacts; {} neighbour pairs matched no rule at the last detection\n", sim.contact_count(),
                     sim.unassigned_pairs());
  return out;
}

namespace {

class HistoryWriter {
 public:
  HistoryWriter(const Scenario& sc, const std::string& path) : sc_(sc), out_(path) {
    if (!out_) throw InputError(path + ": cannot write the history file");
    out_ << "step,time[s]";
    for (const History& h : sc.histories) out_ << "," << h.name << "[" << h.quantity.unit << "]";
    out_ << "\n";
  }
  void sample(const Simulation& sim) {
    out_ << sim.steps << "," << fmt::format("{:.9e}", sim.time);
    for (const History& h : sc_.histories) {
      const double v = evaluate(sim, h.quantity);
      out_ << ",";
      if (std::isfinite(v)) out_ << fmt::format("{:.9e}", v);
    }
    out_ << "\n";
  }
  void flush() { out_.flush(); }

 private:
  const Scenario& sc_;
  std::ofstream out_;
};

// Translate (by [m]) or rotate (by [rad], rotation vector) the selected balls over `steps` cycles
// with imposed velocities, so that the contacts see the motion increment by increment. The balls are
// fixed in the moved components during the stage, then left at rest with their former fixity.
void impose_motion(Simulation& sim, const Stage& s) {
  const bool spin = s.type == StageType::Rotate;
  const FixityMask mask = spin ? kFixSpin : kFixVel;
  std::vector<FixityMask> saved;
  for (std::size_t i : s.sel.balls) {
    saved.push_back(sim.balls.fixity[i]);
    sim.balls.fixity[i] |= mask;
  }
  Vec3 done;
  for (std::int64_t k = 0; k < s.steps; ++k) {
    const double dt = sim.next_timestep();
    const Vec3 rate = (s.by - done) / (static_cast<double>(s.steps - k) * dt);
    for (std::size_t i : s.sel.balls) (spin ? sim.balls.spin[i] : sim.balls.velocity[i]) = rate;
    sim.cycle(1);
    done += rate * sim.last_dt;
  }
  for (std::size_t n = 0; n < s.sel.balls.size(); ++n) {
    const std::size_t i = s.sel.balls[n];
    (spin ? sim.balls.spin[i] : sim.balls.velocity[i]) = Vec3{};
    sim.balls.fixity[i] = saved[n];
  }
}

void apply_set(Simulation& sim, const Stage& s) {
  for (std::size_t k : s.sel.walls) {
    Wall& w = sim.walls.walls[k];
    if (s.velocity) w.velocity = *s.velocity;
    if (s.spin) w.spin = *s.spin;
    if (s.radial_velocity) w.radial_velocity = *s.radial_velocity;
  }
  for (std::size_t i : s.sel.balls) {
    BallStore& b = sim.balls;
    if (s.velocity) b.velocity[i] = *s.velocity;
    if (s.spin) b.spin[i] = *s.spin;
    if (s.applied_force) b.applied_force[i] = *s.applied_force;
    b.fixity[i] = static_cast<FixityMask>((b.fixity[i] | s.fix) & ~s.free);
    if (s.position) {
      b.position[i] = *s.position;
      sim.invalidate_forces();
    }
  }
}

void apply_set_contacts(Simulation& sim, const Stage& s) {
  ContactStore& c = sim.contacts;
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (c.model[k] != *s.model_filter) continue;
    if (c.model[k] == ModelKind::Hill) {
      HillParams& p = c.hill_params[k];
      if (s.fric) p.fric_coef = *s.fric;
      if (s.damp_con) p.damp_con = *s.damp_con;
      if (s.suction) p.suction = *s.suction;
    } else {
      LinearParams& p = c.linear_params[k];
      if (s.fric) p.fric = *s.fric;
      if (s.emod) p.emod = *s.emod;
      if (s.kratio) p.kratio = *s.kratio;
    }
  }
  sim.refresh_mappings();  // β_n, β_s depend on γ_h; k_n on E* (spec §2.4)
}

}  // namespace

RunResult run_scenario(Scenario& sc, const RunOptions& options, std::ostream& log) {
  Simulation& sim = sc.sim;
  RunResult result;
  const std::string dir = options.output_dir.empty() ? sc.output_dir : options.output_dir;
  std::unique_ptr<HistoryWriter> history;
  if (options.write_files && !dir.empty() && !sc.histories.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw InputError(dir + ": cannot create the output folder: " + ec.message());
    result.history_path = (std::filesystem::path(dir) / sc.history_file).string();
    history = std::make_unique<HistoryWriter>(sc, result.history_path);
    const std::int64_t every = sc.history_every;
    sim.observers.push_back([h = history.get(), every](const Simulation& s) {
      if (s.steps % every == 0) h->sample(s);
    });
  }
  sim.update_forces();
  if (history) history->sample(sim);

  const std::size_t n = sc.stages.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Stage& s = sc.stages[k];
    const std::string head = fmt::format("[{}/{}] {} '{}'", k + 1, n, to_string(s.type), s.name);
    std::string what;
    switch (s.type) {
      case StageType::Cycle: sim.cycle(s.steps); what = fmt::format("{} steps", s.steps); break;
      case StageType::Solve: {
        const std::int64_t used = sim.solve(s.ratio, s.max_steps);
        if (used < 0)
          throw RunError(fmt::format("{}: no equilibrium within max_steps = {} (mean unbalanced-force ratio {:.3g} > {:.3g})",
                                     head, s.max_steps, sim.mean_unbalanced_ratio(), s.ratio));
        what = fmt::format("equilibrium after {} steps (ratio {:.3g})", used, sim.mean_unbalanced_ratio());
        break;
      }
      case StageType::Translate:
      case StageType::Rotate:
        impose_motion(sim, s);
        what = fmt::format("{} by [{:g}, {:g}, {:g}] {} in {} steps", s.sel.text, s.by.x, s.by.y, s.by.z,
                           s.type == StageType::Rotate ? "rad" : "m", s.steps);
        break;
      case StageType::Set: apply_set(sim, s); what = s.sel.text; break;
      case StageType::SetContacts: apply_set_contacts(sim, s); break;
      case StageType::SetSimulation:
        if (s.gravity) sim.settings.gravity = *s.gravity;
        if (s.local_damping) sim.settings.local_damping = *s.local_damping;
        if (s.timestep) {
          sim.settings.auto_timestep = *s.timestep == 0.0;
          if (*s.timestep > 0.0) sim.settings.timestep = *s.timestep;
        }
        break;
      case StageType::MakeWet:
        what = fmt::format("{} wet hill contacts", sim.make_wet(s.wet_suction, s.wet_gap));
        break;
      case StageType::MakeDry: what = fmt::format("{} contacts dried", sim.make_dry()); break;
      case StageType::Probe: {
        double v = evaluate(sim, s.quantity);
        if (!s.ratio_to.empty()) v /= result.find(s.ratio_to)->value;
        v *= s.scale;
        result.probes.push_back({s.label, s.quantity.name, s.quantity.target_text,
                                 s.ratio_to.empty() ? s.quantity.unit : "-", v});
        what = fmt::format("{} = {:.6g} {}", s.label, v, result.probes.back().unit);
        break;
      }
      case StageType::ListContacts:
        if (!options.quiet) log << contact_listing(sim);
        break;
    }
    if (!options.quiet)
      log << fmt::format("{} {}  (step {}, t = {:.6g} s, {} contacts)\n", head, what, sim.steps, sim.time,
                         sim.contact_count());
  }
  if (history) history->flush();
  sim.observers.clear();
  return result;
}

}  // namespace hilldem
