#include "hilldem/io/runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <memory>
#include <ostream>
#include <unistd.h>

#include "hilldem/core/error.hpp"
#include "hilldem/io/fault_injection.hpp"
#include "hilldem/io/output_folder.hpp"
#include "hilldem/io/state_io.hpp"
#include "hilldem/io/stop_signal.hpp"
#include "hilldem/io/vtk_writer.hpp"

namespace hilldem {

namespace fs = std::filesystem;

const ProbeValue* RunResult::find(const std::string& label) const {
  for (const ProbeValue& p : probes)
    if (p.label == label) return &p;
  return nullptr;
}

namespace {

const char* moisture_text(const ContactStore& c, std::size_t k) {
  return c.model[k] != ModelKind::Hill ? "-"
         : c.moisture[k] == Moisture::Wet ? "wet"
         : c.moisture[k] == Moisture::Ruptured ? "rupt"
                                               : "dry";
}

std::string pieces_text(const Simulation& sim, std::size_t k) {
  const ContactKey& key = sim.contacts.key[k];
  return key.kind == ContactKind::BallBall
             ? fmt::format("ball {} - ball {}", sim.balls.id[key.a], sim.balls.id[key.b])
             : fmt::format("ball {} - wall {}", sim.balls.id[key.a], sim.walls.walls[key.b].name);
}

}  // namespace

std::string contact_listing(const Simulation& sim) {
  std::string out = fmt::format("{:<24} {:<7} {:>12} {:>12} {:<5} {}\n", "pieces", "model", "gap[m]",
                                "normal[N]", "state", "assigned by");
  const ContactStore& c = sim.contacts;
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (!c.exists[k]) continue;
    out += fmt::format("{:<24} {:<7} {:>12.5g} {:>12.5g} {:<5} {}\n", pieces_text(sim, k), to_string(c.model[k]), c.gap[k],
                       c.normal_force[k], moisture_text(c, k), sim.table.explain(c.rule[k]));
  }
  out += fmt::format("{} contacts; {} neighbour pairs matched no rule at the last detection\n", sim.contact_count(),
                     sim.unassigned_pairs());
  return out;
}

std::string probe_table(const RunResult& res) {
  if (res.probes.empty()) return "";
  std::string out = fmt::format("{:<12} {:<26} {:<22} {:>16} {}\n", "label", "quantity", "target", "value", "unit");
  for (const auto& p : res.probes)
    out += fmt::format("{:<12} {:<26} {:<22} {:>16.8g} {}\n", p.label, p.quantity, p.target, p.value, p.unit);
  return out;
}

void OutputOverrides::apply(Scenario& sc) const {
  if (snapshot_every) {
    sc.snapshots.enabled = true;
    sc.snapshots.every = *snapshot_every;
  }
  if (snapshot_binary) sc.snapshots.binary = *snapshot_binary;
  if (checkpoint_every) sc.checkpoints.every = *checkpoint_every;
  if (checkpoint_seconds) sc.checkpoints.every_seconds = *checkpoint_seconds;
  if (no_checkpoints) sc.checkpoints.enabled = false;
  if (blowup_fraction) sc.blowup_fraction = *blowup_fraction;
}

OutputOverrides& output_overrides() {
  static OutputOverrides o;
  return o;
}

namespace {
// The quantity on `sim`: the scenario's Simulation, or (over MPI ranks) the gathered whole run.
double evaluate_on(const Scenario& sc, const Simulation& sim, const Quantity& q, int servo) {
  if (servo < 0) return evaluate(sim, q);
  const Servo& s = sc.servos[static_cast<std::size_t>(servo)].servo;
  if (q.field == "stress") return s.stress(sim);
  if (q.field == "target_stress") return s.settings.target_stress;
  if (q.field == "speed") return s.speed();
  return s.enabled ? 1.0 : 0.0;  // "enabled"
}
}  // namespace

double evaluate(const Scenario& sc, const Quantity& q, int servo) {
  if (servo < 0) return evaluate(sc.sim, q);
  const Servo& s = sc.servos[static_cast<std::size_t>(servo)].servo;
  if (q.field == "stress") return s.stress(sc.sim);
  if (q.field == "target_stress") return s.settings.target_stress;
  if (q.field == "speed") return s.speed();
  return s.enabled ? 1.0 : 0.0;  // "enabled"
}

namespace {

constexpr const char* kCheckpointFolder = "checkpoints";
constexpr const char* kMetaSection = "run.meta";

// Temporary files of atomic writes (NAME.tmp.PID, io/checkpoint.cpp) that a killed run left in
// `folder`. Called only while holding the folder's lock, so no live writer owns them.
void remove_torn_files(const std::string& folder) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec)) {
    const std::string name = e.path().filename().string();
    const std::size_t at = name.rfind(".tmp.");
    if (at == std::string::npos || at == 0 || at + 5 == name.size()) continue;
    if (name.find_first_not_of("0123456789", at + 5) != std::string::npos) continue;
    if (e.is_regular_file(ec)) fs::remove(e.path(), ec);
  }
}

// ---- history CSV ----

class HistoryWriter {
 public:
  // A new file with its header line.
  HistoryWriter(const Scenario& sc, const std::string& path) : sc_(sc), path_(path) { open_fresh(); }
  // Continue a file whose first `bytes` bytes check_history_prefix verified (their CRC-32 is `crc`):
  // rows written after that checkpoint are cut off (the resumed run writes them again).
  HistoryWriter(const Scenario& sc, const std::string& path, std::uint64_t bytes, std::uint32_t crc)
      : sc_(sc), path_(path), crc_(crc) {
    std::error_code ec;
    fs::resize_file(path, bytes, ec);
    if (ec) throw InputError(path + ": cannot cut the history back to the checkpoint: " + ec.message());
    out_.open(path, std::ios::binary | std::ios::app);
    if (!out_) throw InputError(path + ": cannot append to the history file");
  }
  void sample(const Simulation& sim) {
    std::string row = fmt::format("{},{:.9e}", sim.steps, sim.time);
    for (const History& h : sc_.histories) {
      const double v = evaluate_on(sc_, sim, h.quantity, h.servo);
      row += ",";
      if (std::isfinite(v)) row += fmt::format("{:.9e}", v);
    }
    row += "\n";
    put(row);
  }
  // Flush and return the file's length [bytes].
  std::uint64_t flush() {
    out_.flush();
    if (!out_) throw RunError(path_ + ": writing the history failed");
    return static_cast<std::uint64_t>(out_.tellp());
  }
  // CRC-32 of every byte of the file, for the checkpoints (a resume checks the file against it).
  std::uint32_t crc() const { return crc_; }
  const std::string& path() const { return path_; }

 private:
  void put(const std::string& text) {
    crc_ = crc32(text.data(), text.size(), crc_);
    out_ << text;
  }
  void open_fresh() {
    out_.open(path_, std::ios::binary | std::ios::trunc);
    if (!out_) throw InputError(path_ + ": cannot write the history file");
    std::string head = "step,time[s]";
    for (const History& h : sc_.histories) head += "," + h.name + "[" + h.quantity.unit + "]";
    put(head + "\n");
  }
  const Scenario& sc_;
  std::string path_;
  std::ofstream out_;
  std::uint32_t crc_ = 0;
};

// The history a checkpoint continues: the first `bytes` bytes of `path` must be what the run had
// written when `checkpoint` was taken (that length and, when the checkpoint records it, that CRC-32),
// or the resumed history would silently lose or mix rows. With `copy_to`, those bytes are copied
// there (resume -o NEWDIR). Returns their CRC-32. InputError otherwise, naming both files.
std::uint32_t check_history_prefix(const std::string& path, std::uint64_t bytes, std::optional<std::uint32_t> crc,
                                   const std::string& checkpoint, const std::string& copy_to) {
  const std::string advice = "; resuming would lose or mix its rows. Restore the file, or start the run again";
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw InputError(fmt::format("{}: the history file is missing; the checkpoint {} continues it from {} bytes{}", path,
                                 checkpoint, bytes, advice));
  const auto size = fs::file_size(path, ec);
  if (ec || size < bytes)
    throw InputError(fmt::format("{}: the history file has {} bytes, shorter than the {} bytes the checkpoint {} recorded{}",
                                 path, ec ? 0 : size, bytes, checkpoint, advice));
  std::ifstream in(path, std::ios::binary);
  std::ofstream out;
  if (!copy_to.empty()) {
    out.open(copy_to, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(copy_to + ": cannot write the history file");
  }
  std::vector<char> buf(std::size_t{1} << 20);
  std::uint32_t sum = 0;
  for (std::uint64_t left = bytes; left > 0;) {
    const auto n = static_cast<std::streamsize>(std::min<std::uint64_t>(left, buf.size()));
    if (!in.read(buf.data(), n)) throw InputError(path + ": cannot read the history file");
    sum = crc32(buf.data(), static_cast<std::size_t>(n), sum);
    if (out) out.write(buf.data(), n);
    left -= static_cast<std::uint64_t>(n);
  }
  if (crc && *crc != sum)
    throw InputError(fmt::format("{}: the history file's first {} bytes are not the rows the run had written when the "
                                 "checkpoint {} was taken (CRC-32 {:08x}, recorded {:08x}): it was changed or written by "
                                 "another run{}",
                                 path, bytes, checkpoint, sum, *crc, advice));
  if (out && !out.flush()) throw InputError(copy_to + ": writing the history file failed");
  return sum;
}

// `balls`: the local indices of the stage's selection that this Simulation holds (all of it, but
// one rank's part over MPI ranks: the owners' copies and the ghosts', which must agree).
void apply_set(Simulation& sim, const Stage& s, const std::vector<std::size_t>& balls) {
  for (std::size_t k : s.sel.walls) {
    Wall& w = sim.walls.walls[k];
    if (s.velocity) w.velocity = *s.velocity;
    if (s.spin) w.spin = *s.spin;
    if (s.radial_velocity) w.radial_velocity = *s.radial_velocity;
  }
  for (std::size_t i : balls) {
    BallStore& b = sim.balls;
    if (s.velocity) b.velocity[i] = *s.velocity;
    if (s.spin) b.spin[i] = *s.spin;
    if (s.applied_force) b.applied_force[i] = *s.applied_force;
    b.fixity[i] = static_cast<FixityMask>((b.fixity[i] | s.fix) & ~s.free);
    if (s.position) b.position[i] = *s.position;
  }
  // On the selection, not on what is held here: over MPI ranks every rank rebuilds (its balls go to
  // the ranks their new positions call for), whether it holds a moved ball or not.
  if (s.position && !s.sel.balls.empty()) sim.invalidate_forces();
}

void apply_set_contacts(Simulation& sim, const Stage& s) {
  // Existing contacts only (docs/scenario-format.md): a neighbour pair that becomes a contact later
  // takes its properties from the assignment table, whenever the neighbour list happened to be built.
  ContactStore& c = sim.contacts;
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (!c.exists[k] || c.model[k] != *s.model_filter) continue;
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
      if (s.rolling_fric) p.rolling_fric = *s.rolling_fric;
    }
  }
  sim.refresh_mappings();  // β_n, β_s depend on γ_h; k_n on E* (spec §2.4)
}

void apply_set_servo(Scenario& sc, const Stage& s) {
  Servo& servo = sc.servos[static_cast<std::size_t>(s.servo)].servo;
  if (s.target_stress) servo.settings.target_stress = *s.target_stress;
  if (s.gain_factor) servo.settings.gain_factor = *s.gain_factor;
  if (s.max_speed) servo.settings.max_speed = *s.max_speed;
  if (s.enabled) servo.enabled = *s.enabled;
}

// Stages after which the state may differ from before (snapshots and checkpoints at stage ends).
bool changes_state(StageType t) { return t != StageType::Probe && t != StageType::ListContacts; }

// Where the runner is: the stage, and its progress inside it.
struct Position {
  std::uint64_t stage = 0;          // index of the stage running (or next to run)
  std::int64_t stage_steps = 0;     // cycles done inside it
  bool started = false;             // translate/rotate: fixity saved and the motion begun
  Vec3 motion_done;                 // translate [m] / rotate [rad] imposed so far
  std::vector<FixityMask> saved_fixity;  // translate/rotate: the fixity to restore at the end
};

struct Halted {};   // RunOptions::halt_after_step reached or stop_requested() said so
struct Stopped {};  // a stop signal arrived (io/stop_signal.hpp)

std::string stage_head(const Scenario& sc, std::size_t k) {
  const Stage& s = sc.stages[k];
  return fmt::format("[{}/{}] {} '{}'", k + 1, sc.stages.size(), to_string(s.type), s.name);
}

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool finite3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string vec_text(const Vec3& v) { return fmt::format("[{:.6g}, {:.6g}, {:.6g}]", v.x, v.y, v.z); }

// Every contact of ball index i, one line each.
std::string ball_contacts_text(const Simulation& sim, std::size_t i, std::size_t limit = 50) {
  const ContactStore& c = sim.contacts;
  std::string out;
  std::size_t n = 0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (!c.exists[k]) continue;
    const ContactKey& key = c.key[k];
    if (key.a != i && !(key.kind == ContactKind::BallBall && key.b == i)) continue;
    if (n++ == limit) {
      out += "    ...\n";
      break;
    }
    out += fmt::format("    {:<26} {:<6} {:<4} {:<6} gap {:>12.5g} m  normal {:>12.5g} N  shear {:>12.5g} N  moisture {:>12.5g} N\n",
                       pieces_text(sim, k), to_string(c.model[k]), moisture_text(c, k), c.active[k] ? "active" : "open",
                       c.gap[k], c.normal_force[k], norm(c.shear_force(k)), c.moisture_force[k]);
  }
  return n == 0 ? "    (no contacts)\n" : out;
}

// Seconds between plain progress lines: HILLDEM_PROGRESS_INTERVAL when set, else the option.
double progress_interval(const RunOptions& o) {
  const char* env = std::getenv("HILLDEM_PROGRESS_INTERVAL");
  if (!env || !*env) return o.progress_interval;
  char* end = nullptr;
  const double v = std::strtod(env, &end);
  if (end == env || *end != '\0' || !(v > 0.0) || !std::isfinite(v))
    throw InputError(std::string("HILLDEM_PROGRESS_INTERVAL must be a positive number of seconds; got \"") + env + "\"");
  return v;
}

class Runner {
 public:
  Runner(Scenario& sc, const RunOptions& options, std::ostream& log)
      : sc_(sc), sim_(sc.sim), opt_(options), log_(log), dec_(options.decomposition),
        root_(!dec_ || dec_->rank() == 0),
        progress_(options.progress_stream ? *options.progress_stream : std::cerr,
                  options.quiet || !root_ ? ProgressMode::Off : options.progress,
                  !options.progress_stream && ::isatty(STDERR_FILENO) == 1, progress_interval(options)) {
    if (!root_) opt_.quiet = true;  // (lines from rank 0 only)
  }

  ~Runner() {
    sim_.observers.clear();
    sim_.controllers.clear();
  }

  // Fresh run from the first stage.
  RunResult run(const std::string& dir) {
    decompose();
    open_outputs(dir, nullptr);
    sim_.update_forces();
    if (!result_.history_path.empty()) sample_history();
    if (!result_.snapshot_dir.empty()) write_snapshot(false);
    checkpoint("start");  // a run killed before its first periodic checkpoint can still be resumed
    return run_stages();
  }

  // Continue from a checkpoint whose sim.* sections are already restored into the scenario.
  // `source_dir`: the folder whose outputs the checkpoint continues ("": `dir` itself).
  RunResult resume(const CheckpointReader& r, const std::string& dir, const std::string& source_dir) {
    source_dir_ = source_dir;
    decompose();
    read_position(r);
    last_checkpoint_stage_ = pos_.stage;  // the checkpoint resumed from is at this position
    open_outputs(dir, &r);
    return run_stages();
  }

  void read_position(const CheckpointReader& r) {
    {
      SectionReader s = r.section("run.position");
      pos_.stage = s.u64();
      pos_.stage_steps = s.i64();
      pos_.started = s.boolean();
      pos_.motion_done = s.vec3();
      s.column(pos_.saved_fixity, "saved_fixity");
      const std::uint64_t n = s.count(8 * 5 + 8, 1'000'000);
      for (std::uint64_t k = 0; k < n; ++k) {
        ProbeValue p;
        p.label = s.str(4096);
        p.quantity = s.str(4096);
        p.target = s.str(4096);
        p.unit = s.str(4096);
        p.value = s.f64();
        result_.probes.push_back(p);
      }
      s.finish();
      if (pos_.stage > sc_.stages.size())
        s.fail(fmt::format("stage {} of a scenario with {} stages", pos_.stage + 1, sc_.stages.size()));
      if (pos_.stage_steps < 0) s.fail("a negative step count inside the stage");
      if (pos_.stage < sc_.stages.size()) {
        const Stage& st = sc_.stages[pos_.stage];
        const bool motion = st.type == StageType::Translate || st.type == StageType::Rotate;
        const bool cycling = motion || st.type == StageType::Cycle || st.type == StageType::Solve;
        if (!cycling && pos_.stage_steps != 0) s.fail("steps inside a stage that does not cycle");
        if ((st.type == StageType::Cycle || motion) && pos_.stage_steps > st.steps)
          s.fail(fmt::format("{} steps done inside a stage of {}", pos_.stage_steps, st.steps));
        if (motion && pos_.started && pos_.saved_fixity.size() != st.sel.balls.size())
          s.fail("the saved fixities do not match the stage's selection");
        if (!finite3(pos_.motion_done)) s.fail("the imposed motion so far is not finite");
      }
    }
    {
      SectionReader s = r.section("run.servos");
      const std::uint64_t n = s.count(8, 1'000'000);
      if (n != sc_.servos.size())
        s.fail(fmt::format("{} servos; the scenario defines {}", n, sc_.servos.size()));
      for (ScenarioServo& sv : sc_.servos) {
        const std::string name = s.str(4096);
        if (name != sv.name) s.fail("servo '" + name + "' is not the scenario's servo '" + sv.name + "'");
        read_servo(s, sv.servo);
      }
      s.finish();
    }
  }

 private:
  // ---- over MPI ranks ----

  // This rank's part of the run (RunOptions::decomposition). The ghosts cover the widest make_wet gap
  // of the scenario.
  void decompose() {
    if (!dec_) return;
    double reach = 0.0;  // [m]
    for (const Stage& s : sc_.stages)
      if (s.type == StageType::MakeWet) reach = std::max(reach, s.wet_gap);
    dec_->attach(sim_, reach);
  }

  // The balls of a selection (the whole run's indices) that this rank holds, as (place in the
  // selection, local index), in selection order. Over MPI ranks the set changes at each rebuild (the
  // balls migrate), so a stage asks again before every cycle.
  std::vector<std::pair<std::size_t, std::size_t>> held(const std::vector<std::size_t>& sel) const {
    std::vector<std::pair<std::size_t, std::size_t>> out;
    out.reserve(sel.size());
    for (std::size_t n = 0; n < sel.size(); ++n) {
      const std::int64_t i = dec_ ? dec_->local_of(sel[n]) : static_cast<std::int64_t>(sel[n]);
      if (i >= 0) out.emplace_back(n, static_cast<std::size_t>(i));
    }
    return out;
  }

  // The fixities of a selection's balls in the whole run, in selection order (over MPI ranks: rank
  // 0's from the gathered run, on every rank).
  std::vector<FixityMask> selected_fixity(const std::vector<std::size_t>& sel) {
    std::vector<FixityMask> f;
    if (!dec_) {
      for (std::size_t i : sel) f.push_back(sim_.balls.fixity[i]);
      return f;
    }
    const Simulation whole = dec_->gather(false);
    std::string bytes;
    if (root_)
      for (std::size_t i : sel) bytes.push_back(static_cast<char>(whole.balls.fixity[i]));
    bytes = dec_->from_root(bytes);
    for (char c : bytes) f.push_back(static_cast<FixityMask>(static_cast<unsigned char>(c)));
    return f;
  }

  // Whether rank 0's answer is yes (decisions on the clock must be the same on every rank).
  bool agreed(bool here) { return dec_ ? dec_->from_root(static_cast<std::int64_t>(here)) != 0 : here; }

  // The stop signal (io/stop_signal.hpp) any rank got, 0: none.
  int stop_signal() {
    const int s = stop_requested();
    return dec_ ? static_cast<int>(dec_->max(s)) : s;
  }

  // Existing contacts of the whole run (wet_only: wet hill contacts), each counted by the owner of
  // its first ball.
  std::size_t count_contacts(bool wet_only) {
    if (!dec_ && !wet_only) return sim_.contact_count();
    const ContactStore& c = sim_.contacts;
    std::uint64_t n = 0;
    for (std::size_t k = 0; k < c.size(); ++k)
      n += c.exists[k] && (!wet_only || (c.model[k] == ModelKind::Hill && c.moisture[k] == Moisture::Wet)) &&
           (!dec_ || dec_->owns(c.key[k].a));
    return static_cast<std::size_t>(dec_ ? dec_->sum(n) : n);
  }

  // PFC's mean unbalanced-force ratio of the whole run (over ranks: of the gathered run, on rank 0).
  double unbalanced_ratio() {
    if (!dec_) return sim_.mean_unbalanced_ratio();
    const Simulation whole = dec_->gather(false);
    return dec_->from_root(root_ ? whole.mean_unbalanced_ratio() : 0.0);
  }

  void sample_history() {
    if (!dec_) return history_->sample(sim_);
    const Simulation whole = dec_->gather(false);
    if (root_) history_->sample(whole);
  }

  void write_snapshot(bool stage_end) {
    if (!dec_) return snapshots_->write(sim_, stage_end);
    const Simulation whole = dec_->gather(false);
    if (root_) snapshots_->write(whole, stage_end);
  }

  // ---- outputs ----

  void open_outputs(const std::string& dir, const CheckpointReader* resume) {
    for (ScenarioServo& s : sc_.servos)
      sim_.controllers.push_back([servo = &s.servo](Simulation& sim, double dt) { servo->control(sim, dt); });
    if (!opt_.write_files || dir.empty()) return;
    if (!dec_) {
      open_files(dir, resume);
    } else {
      // Rank 0 opens the files; a problem with them is every rank's error (reported once, by rank 0).
      std::string error;
      if (root_) try {
          open_files(dir, resume);
        } catch (const InputError& e) {
          error = e.what();
        }
      error = dec_->from_root(error);
      if (!error.empty()) throw InputError(error);
      // The other ranks take part in each write (it gathers the state), so they know which there are.
      if (!sc_.histories.empty()) result_.history_path = (fs::path(dir) / sc_.history_file).string();
      if (sc_.snapshots.enabled) result_.snapshot_dir = (fs::path(dir) / sc_.snapshots.folder).string();
      if (sc_.checkpoints.enabled) result_.checkpoint_dir = (fs::path(dir) / kCheckpointFolder).string();
    }
    if (!result_.history_path.empty()) {
      const std::int64_t every = sc_.history_every;
      sim_.observers.push_back([this, every](const Simulation& s) {
        if (s.steps % every == 0) sample_history();
      });
    }
  }

  void open_files(const std::string& dir, const CheckpointReader* resume) {
    std::error_code ec;
    // The folder is ours until the run ends (a second run or resume on it is refused), which also
    // makes it safe to remove what killed runs left half written.
    lock_ = OutputLock(dir, "output folder");
    dir_ = dir;
    remove_torn_files(dir);

    std::uint64_t history_bytes = 0;
    std::optional<std::uint32_t> history_crc;
    std::vector<SnapshotEntry> entries;
    bool had_history = false;
    if (resume) {
      SectionReader s = resume->section("run.outputs", 2);
      had_history = s.boolean();
      history_bytes = s.u64();
      const std::uint64_t n = s.count(24, 100'000'000);
      for (std::uint64_t k = 0; k < n; ++k) {
        SnapshotEntry e;
        e.index = s.i64();
        e.step = s.i64();
        e.time = s.f64();
        if (e.index < 0 || e.step < 0) s.fail("a snapshot entry with a negative index or step");
        entries.push_back(e);
      }
      seq_ = s.u64();
      if (s.version() >= 2) history_crc = s.u32();
      s.finish();
    }
    // Resuming into another folder (-o NEWDIR): what the run had written up to the checkpoint is
    // copied there, so that the folder is complete on its own.
    std::error_code eq;
    const bool elsewhere =
        resume && !source_dir_.empty() && fs::is_directory(source_dir_, eq) && !fs::equivalent(source_dir_, dir, eq);
    if (elsewhere) {
      const std::string who = OutputLock::holder(source_dir_);
      if (!who.empty())
        throw InputError(source_dir_ + ": the run in this folder is still going (" + who +
                         "); resume it when it has stopped");
    }
    const std::string from = elsewhere ? source_dir_ : dir;
    if (!sc_.histories.empty()) {
      result_.history_path = (fs::path(dir) / sc_.history_file).string();
      if (resume && had_history) {
        const std::string source = (fs::path(from) / sc_.history_file).string();
        const std::uint32_t crc =
            check_history_prefix(source, history_bytes, history_crc, resume->source(), elsewhere ? result_.history_path : "");
        history_ = std::make_unique<HistoryWriter>(sc_, result_.history_path, history_bytes, crc);
      } else {
        history_ = std::make_unique<HistoryWriter>(sc_, result_.history_path);
      }
    }
    if (sc_.snapshots.enabled) {
      result_.snapshot_dir = (fs::path(dir) / sc_.snapshots.folder).string();
      snapshots_ = std::make_unique<SnapshotSeries>(
          result_.snapshot_dir, SnapshotOptions{sc_.snapshots.contacts, sc_.snapshots.walls, sc_.snapshots.binary});
      remove_torn_files(result_.snapshot_dir);
      if (resume) {
        // Every snapshot the index lists must be there (or be copied there), or the .pvd would
        // point at missing files.
        const fs::path src = fs::path(from) / sc_.snapshots.folder;
        std::vector<std::string> kinds{"balls"};
        if (sc_.snapshots.contacts) kinds.push_back("contacts");
        if (sc_.snapshots.walls) kinds.push_back("walls");
        for (const SnapshotEntry& e : entries)
          for (const std::string& kind : kinds) {
            const std::string name = fmt::format("{}_{:06}.vtp", kind, e.index);
            if (!fs::is_regular_file(src / name, ec))
              throw InputError(fmt::format("{}: missing; the snapshot index of the checkpoint {} lists it (step {}). "
                                           "Restore it, or start the run again",
                                           (src / name).string(), resume->source(), e.step));
            if (elsewhere) {
              fs::copy_file(src / name, fs::path(result_.snapshot_dir) / name, fs::copy_options::overwrite_existing, ec);
              if (ec) throw InputError(result_.snapshot_dir + ": cannot copy " + name + " into it: " + ec.message());
            }
          }
        snapshots_->restore(std::move(entries));
      }
    }
    if (sc_.checkpoints.enabled) {
      result_.checkpoint_dir = (fs::path(dir) / kCheckpointFolder).string();
      fs::create_directories(result_.checkpoint_dir, ec);
      if (ec) throw InputError(result_.checkpoint_dir + ": cannot create the checkpoint folder: " + ec.message());
      // Checkpoints newer than the one resumed from belong to the lost part of the run: remove them.
      for (const auto& e : fs::directory_iterator(result_.checkpoint_dir, ec)) {
        unsigned long long n = 0;
        const std::string name = e.path().filename().string();
        if (std::sscanf(name.c_str(), "ckpt-%llu.hdc", &n) == 1 && name == fmt::format("ckpt-{:06}.hdc", n) && n > seq_)
          fs::remove(e.path(), ec);
      }
      remove_torn_files(result_.checkpoint_dir);
      // A folder resumed into holds the checkpoint it starts from, so it can itself be resumed.
      if (elsewhere && fs::is_regular_file(resume->source(), ec)) {
        const fs::path copy = fs::path(result_.checkpoint_dir) / fmt::format("ckpt-{:06}.hdc", seq_);
        fs::copy_file(resume->source(), copy, fs::copy_options::overwrite_existing, ec);
        if (ec) throw InputError(copy.string() + ": cannot copy the checkpoint resumed from: " + ec.message());
      }
      last_checkpoint_time_ = now_seconds();
    }
  }

  std::uint64_t flush_history() { return history_ ? history_->flush() : 0; }

  // sim: the run's state (over MPI ranks, the gathered whole run).
  void write_run_sections(CheckpointWriter& w, const std::string& kind, const std::string& message, const Simulation& sim) {
    {
      SectionWriter& s = w.section(kMetaSection);
      s.str(kind);
      s.str(message);
      s.i64(static_cast<std::int64_t>(std::time(nullptr)));
      s.str(state_digest(sim));
    }
    {
      SectionWriter& s = w.section("run.scenario");
      s.str(sc_.file);
      s.str(sc_.text);
    }
    {
      SectionWriter& s = w.section("run.position");
      s.u64(pos_.stage);
      s.i64(pos_.stage_steps);
      s.boolean(pos_.started);
      s.vec3(pos_.motion_done);
      s.column(pos_.saved_fixity);
      s.u64(result_.probes.size());
      for (const ProbeValue& p : result_.probes) {
        s.str(p.label);
        s.str(p.quantity);
        s.str(p.target);
        s.str(p.unit);
        s.f64(p.value);
      }
    }
    {
      SectionWriter& s = w.section("run.outputs", 2);  // version 2: the history's CRC-32 at the end
      s.boolean(history_ != nullptr);
      s.u64(flush_history());
      const std::vector<SnapshotEntry> none;
      const auto& entries = snapshots_ ? snapshots_->entries() : none;
      s.u64(entries.size());
      for (const SnapshotEntry& e : entries) {
        s.i64(e.index);
        s.i64(e.step);
        s.f64(e.time);
      }
      s.u64(seq_);
      s.u32(history_ ? history_->crc() : 0);
    }
    {
      // The output settings this run uses (the scenario's, or the command line's over them).
      SectionWriter& s = w.section("run.settings", 2);  // version 2: stage_end_min_seconds at the end
      const SnapshotSettings& sn = sc_.snapshots;
      s.boolean(sn.enabled);
      s.i64(sn.every);
      s.boolean(sn.at_stage_ends);
      s.boolean(sn.contacts);
      s.boolean(sn.walls);
      s.boolean(sn.binary);
      s.str(sn.folder);
      const CheckpointSettings& c = sc_.checkpoints;
      s.boolean(c.enabled);
      s.i64(c.every);
      s.f64(c.every_seconds);
      s.boolean(c.at_stage_ends);
      s.i64(c.keep);
      s.f64(sc_.blowup_fraction);
      s.f64(c.stage_end_min_seconds);
    }
    {
      SectionWriter& s = w.section("run.servos");
      s.u64(sc_.servos.size());
      for (const ScenarioServo& sv : sc_.servos) {
        s.str(sv.name);
        write_servo(s, sv.servo);
      }
    }
    write_simulation(w, sim);
  }

  void checkpoint(const char* kind) {
    if (result_.checkpoint_dir.empty()) return;
    ++seq_;
    const std::string path = (fs::path(result_.checkpoint_dir) / fmt::format("ckpt-{:06}.hdc", seq_)).string();
    try {
      if (dec_) {
        // One file, in the single-process format, from the gathered state: any rank count resumes it.
        const Simulation whole = dec_->gather(true);
        if (root_) {
          CheckpointWriter w;
          write_run_sections(w, kind, "", whole);
          w.write_file(path);
        }
      } else {
        CheckpointWriter w;
        write_run_sections(w, kind, "", sim_);
        w.write_file(path);
      }
    } catch (const InputError& e) {
      if (dec_) throw RunError(e.what());  // (rank 0's alone: it must end every rank)
      throw;
    } catch (const std::bad_alloc&) {
      progress_.clear();
      throw OutOfMemory(fmt::format("writing the checkpoint {} ({} balls, {} neighbour rows)", path, sim_.balls.size(),
                                    sim_.contacts.size()),
                        state_memory_estimate(sim_.balls.size(), sim_.contacts.size()));
    }
    result_.last_checkpoint = path;
    last_checkpoint_stage_ = pos_.stage;
    last_checkpoint_time_ = now_seconds();
    // Keep the newest `keep`.
    if (root_ && seq_ > static_cast<std::uint64_t>(sc_.checkpoints.keep)) {
      std::error_code ec;
      for (std::uint64_t old = seq_ - static_cast<std::uint64_t>(sc_.checkpoints.keep); old > 0; --old) {
        const fs::path p = fs::path(result_.checkpoint_dir) / fmt::format("ckpt-{:06}.hdc", old);
        if (!fs::remove(p, ec)) break;
      }
    }
  }

  // The state after a blow-up, for inspection (hilldem inspect). Returns a sentence for the error.
  std::string dump_blowup(const std::string& message) {
    if (!opt_.write_files) return "no state file written (file output is off)";
    if (dec_) return "no state file written (a run over MPI ranks: resume it from its checkpoints)";
    const std::string folder = dir_.empty() ? "." : dir_;
    const std::string path = (fs::path(folder) / fmt::format("blowup-step-{}.hdc", sim_.steps)).string();
    try {
      CheckpointWriter w;
      write_run_sections(w, "blow-up", message, sim_);
      w.write_file(path);
    } catch (const std::exception& e) {
      return std::string("the state could not be written: ") + e.what();
    }
    return "state written to " + path + " (hilldem inspect " + path + " --ball ID)";
  }

  // ---- cycling ----

  void cycle_once() {
    try {
      sim_.cycle(1);
    } catch (const std::bad_alloc&) {
      progress_.clear();
      throw OutOfMemory(fmt::format("cycling {} at step {} ({} balls, {} neighbour rows)", stage_head(sc_, pos_.stage),
                                    sim_.steps, sim_.balls.size(), sim_.contacts.size()),
                        state_memory_estimate(sim_.balls.size(), sim_.contacts.size()));
    } catch (const RunError& e) {
      progress_.clear();
      const std::string what = e.what();
      throw RunError(what + "\n  " + dump_blowup(what));
    }
  }

  // A free ball moving more than blowup_fraction × its radius in one step, or anything non-finite.
  void check_blowup() {
    const double f = sc_.blowup_fraction;
    const BallStore& b = sim_.balls;
    const double dt = sim_.last_dt;
    const std::size_t n = b.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3& v = b.velocity[i];
      const double move2 = norm2(v) * dt * dt;
      const bool finite = std::isfinite(move2) && finite3(b.position[i]) && finite3(b.spin[i]);
      const bool free = (b.fixity[i] & kFixVel) != kFixVel;
      if (finite && !(f > 0.0 && free && move2 > f * f * b.radius[i] * b.radius[i])) continue;
      std::string why = finite ? fmt::format("ball {} moved {:.4g} m in one step ({:.3g} of its radius {:.4g} m; the limit, "
                                             "[simulation] blowup_fraction, is {:g})",
                                             b.id[i], std::sqrt(move2), std::sqrt(move2) / b.radius[i], b.radius[i], f)
                               : fmt::format("ball {} has a non-finite position, velocity or spin", b.id[i]);
      blowup(why + fmt::format("\n  position {} m, velocity {} m/s, spin {} rad/s, contact force {} N\n  its contacts:\n",
                               vec_text(b.position[i]), vec_text(v), vec_text(b.spin[i]), vec_text(b.contact_force[i])) +
             ball_contacts_text(sim_, i));
    }
    for (const Wall& w : sim_.walls.walls)
      if (!finite3(w.velocity) || !finite3(w.force) || !finite3(w.point) || !std::isfinite(w.radius))
        blowup(fmt::format("wall '{}' has a non-finite position, velocity or force (velocity {} m/s, force {} N)", w.name,
                           vec_text(w.velocity), vec_text(w.force)));
  }

  [[noreturn]] void blowup(const std::string& what) {
    progress_.clear();
    const std::string message = fmt::format("blow-up at step {} (t = {:.6g} s, dt = {:.4g} s, in {}): {}", sim_.steps,
                                            sim_.time, sim_.last_dt,
                                            pos_.stage < sc_.stages.size() ? stage_head(sc_, pos_.stage) : "no stage", what);
    throw RunError(message + "  " + dump_blowup(message));
  }

  // After every cycle: checks, periodic outputs (unless the stage ends with this cycle), progress,
  // fault injection and the test halt.
  void after_cycle(bool stage_ends, double ratio = -1.0) {
    check_blowup();
    if (!stage_ends) {
      if (!result_.snapshot_dir.empty() && sc_.snapshots.every > 0 && sim_.steps % sc_.snapshots.every == 0)
        write_snapshot(false);
      const CheckpointSettings& c = sc_.checkpoints;
      if (!result_.checkpoint_dir.empty()) {
        if (c.every > 0 && sim_.steps % c.every == 0) checkpoint("periodic (steps)");
        else if (c.every_seconds > 0.0 && agreed(now_seconds() - last_checkpoint_time_ >= c.every_seconds))
          checkpoint("periodic (time)");
      }
      progress_.tick(sim_, pos_.stage_steps, ratio);
    }
    fault_injection().on_step(sim_.steps);
    if (opt_.halt_after_step >= 0 && sim_.steps >= opt_.halt_after_step) throw Halted{};
    if (opt_.stop_requested && opt_.stop_requested()) throw Halted{};
    // (At a stage's last cycle the stop waits for the stage end: a solve resumed at its last step
    // would cycle once more.)
    if (!stage_ends && stop_signal()) throw Stopped{};
  }

  void run_motion(const Stage& s) {
    const bool spin = s.type == StageType::Rotate;
    const FixityMask mask = spin ? kFixSpin : kFixVel;
    if (!pos_.started) {
      pos_.saved_fixity = selected_fixity(s.sel.balls);
      for (const auto& [n, i] : held(s.sel.balls)) sim_.balls.fixity[i] |= mask;
      pos_.motion_done = Vec3{};
      pos_.started = true;
    }
    // Imposed velocities, so that the contacts see the motion step by step; the rate is re-aimed at
    // what is left each step (the time step may change). Set on every copy held here (over MPI ranks
    // the ghosts' too, so that a ghost stays an exact copy of its owner's ball).
    while (pos_.stage_steps < s.steps) {
      const double dt = sim_.next_timestep();
      const Vec3 rate = (s.by - pos_.motion_done) / (static_cast<double>(s.steps - pos_.stage_steps) * dt);
      for (const auto& [n, i] : held(s.sel.balls)) (spin ? sim_.balls.spin[i] : sim_.balls.velocity[i]) = rate;
      cycle_once();
      pos_.motion_done += rate * sim_.last_dt;
      ++pos_.stage_steps;
      after_cycle(pos_.stage_steps == s.steps);
    }
    // Left at rest with their former fixity.
    for (const auto& [n, i] : held(s.sel.balls)) {
      (spin ? sim_.balls.spin[i] : sim_.balls.velocity[i]) = Vec3{};
      sim_.balls.fixity[i] = pos_.saved_fixity[n];
    }
  }

  std::string run_stage(const Stage& s) {
    switch (s.type) {
      case StageType::Cycle:
        while (pos_.stage_steps < s.steps) {
          cycle_once();
          ++pos_.stage_steps;
          after_cycle(pos_.stage_steps == s.steps);
        }
        return fmt::format("{} steps", s.steps);
      case StageType::Solve:
        // Cycle (at least once) until the mean unbalanced-force ratio is ≤ ratio (Simulation::solve).
        while (true) {
          if (pos_.stage_steps >= s.max_steps)
            throw RunError(fmt::format("{}: no equilibrium within max_steps = {} (mean unbalanced-force ratio {:.3g} > {:.3g})",
                                       stage_head(sc_, pos_.stage), s.max_steps, unbalanced_ratio(), s.ratio));
          cycle_once();
          ++pos_.stage_steps;
          const double r = unbalanced_ratio();
          const bool done = r <= s.ratio;
          after_cycle(done, r);
          if (done) break;
        }
        return fmt::format("equilibrium after {} steps (ratio {:.3g})", pos_.stage_steps, unbalanced_ratio());
      case StageType::Translate:
      case StageType::Rotate:
        run_motion(s);
        return fmt::format("{} by [{:g}, {:g}, {:g}] {} in {} steps", s.sel.text, s.by.x, s.by.y, s.by.z,
                           s.type == StageType::Rotate ? "rad" : "m", s.steps);
      case StageType::Set: {
        std::vector<std::size_t> balls;
        for (const auto& [n, i] : held(s.sel.balls)) balls.push_back(i);
        apply_set(sim_, s, balls);
        return s.sel.text;
      }
      case StageType::SetContacts: apply_set_contacts(sim_, s); return "";
      case StageType::SetSimulation:
        if (s.gravity) sim_.settings.gravity = *s.gravity;
        if (s.local_damping) sim_.settings.local_damping = *s.local_damping;
        if (s.timestep) {
          sim_.settings.auto_timestep = *s.timestep == 0.0;
          if (*s.timestep > 0.0) sim_.settings.timestep = *s.timestep;
        }
        return "";
      case StageType::MakeWet: {
        const std::size_t wet = sim_.make_wet(s.wet_suction, s.wet_gap);
        return fmt::format("{} wet hill contacts", dec_ ? count_contacts(true) : wet);
      }
      case StageType::MakeDry: {
        const std::size_t was_wet = dec_ ? count_contacts(true) : 0;
        const std::size_t dried = sim_.make_dry();
        return fmt::format("{} contacts dried", dec_ ? was_wet : dried);
      }
      case StageType::Probe: {
        // (Over MPI ranks: on the gathered run, by rank 0, which keeps the probes.)
        const Simulation whole = dec_ ? dec_->gather(false) : Simulation{};
        if (!root_) return "";
        double v = evaluate_on(sc_, dec_ ? whole : sim_, s.quantity, s.servo);
        if (!s.ratio_to.empty()) v /= result_.find(s.ratio_to)->value;
        v *= s.scale;
        result_.probes.push_back({s.label, s.quantity.name, s.quantity.target_text,
                                  s.ratio_to.empty() ? s.quantity.unit : "-", v});
        return fmt::format("{} = {:.6g} {}", s.label, v, result_.probes.back().unit);
      }
      case StageType::ListContacts:
        if (dec_) {
          const Simulation whole = dec_->gather(false);
          if (!opt_.quiet) log_ << contact_listing(whole);
        } else if (!opt_.quiet) {
          log_ << contact_listing(sim_);
        }
        return "";
      case StageType::SetServo: {
        apply_set_servo(sc_, s);
        const ScenarioServo& sv = sc_.servos[static_cast<std::size_t>(s.servo)];
        return fmt::format("servo {}: target {:g} Pa, {}", sv.name, sv.servo.settings.target_stress,
                           sv.servo.enabled ? "on" : "off");
      }
    }
    return "";
  }

  RunResult run_stages() {
    try {
      const std::size_t n = sc_.stages.size();
      if (pos_.stage >= n) result_.already_complete = true;
      while (pos_.stage < n) {
        if (stop_signal()) throw Stopped{};
        const std::size_t k = pos_.stage;
        const Stage& s = sc_.stages[k];
        ProgressStage ps{k + 1, n, to_string(s.type), s.name, -1, 0.0, 0};
        if (s.type == StageType::Cycle || s.type == StageType::Translate || s.type == StageType::Rotate) ps.total_steps = s.steps;
        if (s.type == StageType::Solve) ps.target_ratio = s.ratio, ps.max_steps = s.max_steps;
        progress_.begin_stage(ps, pos_.stage_steps);
        const std::string what = run_stage(s);
        progress_.clear();
        const std::size_t contacts = count_contacts(false);
        if (!opt_.quiet)
          log_ << fmt::format("{} {}  (step {}, t = {:.6g} s, {} contacts)\n", stage_head(sc_, k), what, sim_.steps,
                              sim_.time, contacts);
        pos_ = Position{};
        pos_.stage = k + 1;
        if (changes_state(s.type)) {
          if (!result_.snapshot_dir.empty() && sc_.snapshots.at_stage_ends) write_snapshot(true);
          // (Many short stages would otherwise spend their time writing checkpoints.)
          if (sc_.checkpoints.at_stage_ends &&
              agreed(now_seconds() - last_checkpoint_time_ >= sc_.checkpoints.stage_end_min_seconds))
            checkpoint("stage end");
        }
      }
      if (!result_.checkpoint_dir.empty() && last_checkpoint_stage_ != n) checkpoint("final");
      flush_history();
    } catch (const Halted&) {
      progress_.clear();
      result_.halted = true;
    } catch (const Stopped&) {
      progress_.clear();
      result_.stopped_by = stop_signal();
      checkpoint(fmt::format("stopped by {}", signal_name(result_.stopped_by)).c_str());
      flush_history();
    }
    return result_;
  }

  Scenario& sc_;
  Simulation& sim_;
  RunOptions opt_;
  std::ostream& log_;
  RunDecomposition* dec_;  // (RunOptions::decomposition)
  bool root_;              // this process writes the files and lines (no decomposition, or rank 0)
  Progress progress_;
  RunResult result_;
  Position pos_;
  std::string dir_;
  std::string source_dir_;
  OutputLock lock_;
  std::unique_ptr<HistoryWriter> history_;
  std::unique_ptr<SnapshotSeries> snapshots_;
  std::uint64_t seq_ = 0;
  std::uint64_t last_checkpoint_stage_ = UINT64_MAX;
  double last_checkpoint_time_ = 0.0;
};

// The scenario a checkpoint carries, and its state restored into it.
void restore_scenario(const CheckpointReader& r, Scenario& sc) {
  SectionReader s = r.section("run.scenario");
  const std::string file = s.str(1u << 20);
  const std::string text = s.str();
  s.finish();
  // The state first: its size bounds the scenario's (a damaged text cannot ask for millions of balls).
  Simulation restored;
  read_simulation(r, restored, true);
  ScenarioDescription d;
  try {
    ScenarioLimits limits;
    limits.max_balls = std::max<std::uint64_t>(restored.balls.size(), 1);
    d = read_scenario(text, file, limits);
  } catch (const InputError& e) {
    throw InputError(r.source() + ": the scenario it carries does not load: " + e.what());
  }
  // The stages refer to balls and walls by index and to groups by bit: they must be the scenario's.
  const SimulationDescription& fresh = d.sim;
  auto mismatch = [&](const std::string& what) {
    throw InputError(r.source() + ": the saved state does not match its scenario (" + what + ")");
  };
  // (The balls, then the clumps' pebbles, in the order build_simulation adds them.)
  std::size_t pebbles = 0;
  for (const SimulationDescription::Clump& c : fresh.clumps) pebbles += fresh.clump_templates[c.tmpl].pebbles.size();
  if (restored.balls.size() != fresh.balls.size() + pebbles)
    mismatch(fmt::format("{} balls saved, the scenario has {} and {} pebbles", restored.balls.size(), fresh.balls.size(), pebbles));
  if (restored.clumps.size() != fresh.clumps.size())
    mismatch(fmt::format("{} clumps saved, the scenario has {}", restored.clumps.size(), fresh.clumps.size()));
  for (std::size_t i = 0; i < fresh.balls.size(); ++i)
    if (restored.balls.id[i] != fresh.balls[i].id) mismatch(fmt::format("ball {} is saved at index {}", restored.balls.id[i], i));
  if (restored.walls.size() != fresh.walls.size())
    mismatch(fmt::format("{} walls saved, the scenario has {}", restored.walls.size(), fresh.walls.size()));
  for (std::size_t w = 0; w < fresh.walls.size(); ++w)
    if (restored.walls.walls[w].name != fresh.walls[w].name) mismatch("wall '" + restored.walls.walls[w].name + "'");
  for (int k = 0; k < 64; ++k) {
    const std::uint64_t bit = std::uint64_t{1} << k;
    if (fresh.groups.describe(bit) != restored.groups.describe(bit)) mismatch("group names");
  }
  if (restored.table.rules.size() != fresh.rules.size()) mismatch("assignment rules");
  // The scenario's plan with the restored state (the description's bodies are not built).
  static_cast<ScenarioPlan&>(sc) = std::move(d);
  sc.sim = std::move(restored);
  // The restore must give back exactly the state that was saved.
  SectionReader meta = r.section(kMetaSection);
  meta.str(4096);
  meta.str();
  meta.i64();
  const std::string digest = meta.str(64);
  if (state_digest(sc.sim) != digest)
    throw InputError(r.source() + ": the restored state's digest " + state_digest(sc.sim) + " differs from the saved " + digest);
}

}  // namespace

RunResult run_scenario(Scenario& sc, const RunOptions& options, std::ostream& log) {
  output_overrides().apply(sc);
  const std::string dir = options.output_dir.empty() ? sc.output_dir : options.output_dir;
  Runner runner(sc, options, log);
  return runner.run(dir);
}

std::string find_checkpoint(const std::string& path, std::ostream& log) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path + ": no such file or folder");
  if (!fs::is_directory(path, ec)) return path;
  fs::path dir(path);
  if (fs::is_directory(dir / kCheckpointFolder, ec)) dir /= kCheckpointFolder;
  std::vector<std::pair<unsigned long long, fs::path>> found;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    unsigned long long n = 0;
    const std::string name = e.path().filename().string();
    if (std::sscanf(name.c_str(), "ckpt-%llu.hdc", &n) == 1 && name == fmt::format("ckpt-{:06}.hdc", n))
      found.push_back({n, e.path()});
  }
  if (ec) throw InputError(dir.string() + ": cannot list the folder: " + ec.message());
  if (found.empty()) throw InputError(dir.string() + ": no checkpoint (ckpt-NNNNNN.hdc) in this folder");
  std::sort(found.rbegin(), found.rend());
  std::string errors;
  for (const auto& [n, p] : found) {
    try {
      CheckpointReader::from_file(p.string());
      return p.string();
    } catch (const InputError& e) {
      log << "warning: skipping a damaged checkpoint: " << e.what() << "\n";
      errors += std::string("\n  ") + e.what();
    }
  }
  throw InputError(dir.string() + ": every checkpoint in this folder is damaged:" + errors);
}

namespace {

RunResult resume_from(const CheckpointReader& r, Scenario& sc, const RunOptions& options, const std::string& dir,
                      const std::string& source_dir, std::ostream& log) {
  {
    SectionReader meta = r.section(kMetaSection);
    const std::string kind = meta.str(4096);
    if (kind == "blow-up")
      throw InputError(r.source() + ": holds the state of a blow-up, for inspection (hilldem inspect); resume from the "
                                    "run's checkpoints/ folder instead");
  }
  restore_scenario(r, sc);
  {
    SectionReader s = r.section("run.settings", 2);
    SnapshotSettings& sn = sc.snapshots;
    sn.enabled = s.boolean();
    sn.every = s.i64();
    sn.at_stage_ends = s.boolean();
    sn.contacts = s.boolean();
    sn.walls = s.boolean();
    sn.binary = s.boolean();
    sn.folder = s.str(4096);
    CheckpointSettings& c = sc.checkpoints;
    c.enabled = s.boolean();
    c.every = s.i64();
    c.every_seconds = s.f64();
    c.at_stage_ends = s.boolean();
    const std::int64_t keep = s.i64();
    sc.blowup_fraction = s.f64();
    c.stage_end_min_seconds = s.version() >= 2 ? s.f64() : 0.0;  // version 1 wrote every stage end
    s.finish();
    if (sn.every < 0 || c.every < 0 || !(c.every_seconds >= 0.0) || !(c.stage_end_min_seconds >= 0.0 && c.stage_end_min_seconds <= 1e9) || keep < 1 || keep > 1000 || !(sc.blowup_fraction >= 0.0) ||
        sn.folder.empty() || sn.folder.find('/') != std::string::npos || sn.folder == "." || sn.folder == "..")
      s.fail("output settings out of range");
    c.keep = static_cast<int>(keep);
  }
  if (!options.quiet) {
    SectionReader p = r.section("run.position");
    const std::uint64_t stage = p.u64();
    const std::int64_t steps = p.i64();
    log << fmt::format("resuming from {} (step {}, t = {:.6g} s, stage {} of {}, {} steps into it)\n", r.source(),
                       sc.sim.steps, sc.sim.time, std::min<std::uint64_t>(stage + 1, sc.stages.size()), sc.stages.size(),
                       steps);
  }
  Runner runner(sc, options, log);
  RunResult result = runner.resume(r, dir, source_dir);
  result.resumed_from = r.source();
  return result;
}

}  // namespace

RunResult resume_scenario(const CheckpointReader& r, Scenario& sc, const RunOptions& options, std::ostream& log) {
  return resume_from(r, sc, options, options.output_dir, "", log);
}

namespace {
std::string find_resumable(const std::string& path, std::ostream& log);
}  // namespace

RunResult resume_scenario(const std::string& path, Scenario& sc, const RunOptions& options, std::ostream& log) {
  // (Over MPI ranks, rank 0 looks at the folder and finds the checkpoint; every rank then reads it.)
  RunDecomposition* dec = options.decomposition;
  std::string file, error;
  if (!dec || dec->rank() == 0) try {
    file = find_resumable(path, log);
  } catch (const InputError& e) {
    if (!dec) throw;
    error = e.what();
  }
  if (dec) {
    error = dec->from_root(error);
    if (!error.empty()) throw InputError(error);
    file = dec->from_root(file);
  }
  const CheckpointReader r = CheckpointReader::from_file(file);
  const fs::path parent = fs::absolute(fs::path(file)).parent_path();
  const std::string source = (parent.filename() == kCheckpointFolder ? parent.parent_path() : parent).string();
  const std::string dir = options.output_dir.empty() ? source : options.output_dir;
  return resume_from(r, sc, options, dir, source, log);
}

namespace {
// The checkpoint resume_scenario continues from, after refusing a folder whose run is still going.
std::string find_resumable(const std::string& path, std::ostream& log) {
  {
    // A folder whose run is still going is refused before anything else is looked at.
    std::error_code ec;
    fs::path folder = fs::absolute(fs::path(path), ec).lexically_normal();
    if (!folder.has_filename()) folder = folder.parent_path();  // "run/checkpoints/"
    if (!fs::is_directory(folder, ec)) folder = folder.parent_path();
    if (folder.filename() == kCheckpointFolder) folder = folder.parent_path();
    const std::string who = OutputLock::holder(folder.string());
    if (!who.empty())
      throw InputError(folder.string() + ": the output folder is in use by another hilldem process (" + who +
                       "); resume it when that process has ended");
  }
  return find_checkpoint(path, log);
}
}  // namespace

std::string describe_checkpoint(const std::string& path, std::optional<std::int64_t> ball) {
  return describe_checkpoint(CheckpointReader::from_file(path), ball);
}

std::string describe_checkpoint(const CheckpointReader& r, std::optional<std::int64_t> ball) {
  const std::string& path = r.source();
  std::string out = fmt::format("checkpoint {} (format version {})\n", path, kCheckpointFormatVersion);
  if (r.has(kMetaSection)) {
    SectionReader m = r.section(kMetaSection);
    const std::string kind = m.str(4096);
    const std::string message = m.str();
    const std::time_t when = static_cast<std::time_t>(m.i64());
    const std::string digest = m.str(64);
    char stamp[64] = "?";
    if (const std::tm* tm = std::gmtime(&when)) std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M:%S UTC", tm);
    out += fmt::format("kind: {}   written: {}   state digest: {}\n", kind, stamp, digest);
    if (!message.empty()) out += "message: " + message + "\n";
  }
  if (r.has("run.scenario")) {
    SectionReader s = r.section("run.scenario");
    out += "scenario: " + s.str(1u << 20) + "\n";
  }
  Simulation sim;
  read_simulation(r, sim, false);
  out += fmt::format("clock: step {}, t = {:.9g} s, last dt = {:.6g} s\n", sim.steps, sim.time, sim.last_dt);
  if (r.has("run.position")) {
    SectionReader p = r.section("run.position");
    const std::uint64_t stage = p.u64();
    const std::int64_t steps = p.i64();
    out += fmt::format("position: stage {} ({} steps done inside it)\n", stage + 1, steps);
  }
  std::size_t wet = 0, active = 0;
  for (std::size_t c = 0; c < sim.contacts.size(); ++c)
    if (sim.contacts.exists[c]) {
      active += sim.contacts.active[c];
      wet += sim.contacts.model[c] == ModelKind::Hill && sim.contacts.moisture[c] == Moisture::Wet;
    }
  out += fmt::format("bodies: {} balls, {} walls; contacts: {} ({} active, {} wet), {} neighbour rows\n", sim.balls.size(),
                     sim.walls.size(), sim.contact_count(), active, wet, sim.contacts.size());
  out += "sections:";
  for (const std::string& n : r.names()) out += fmt::format(" {} ({} B)", n, r.section_size(n));
  out += "\n";
  if (ball) {
    const long i = sim.balls.find(*ball);
    if (i < 0) throw InputError(path + ": no ball with id " + std::to_string(*ball) + " in this checkpoint");
    const BallStore& b = sim.balls;
    const auto k = static_cast<std::size_t>(i);
    out += fmt::format("ball {}: radius {:.6g} m, mass {:.6g} kg, fixity {:#x}\n  position {} m\n  velocity {} m/s\n  spin {} rad/s\n"
                       "  contact force {} N\n  contact moment {} N m\n  its contacts:\n",
                       b.id[k], b.radius[k], b.mass[k], b.fixity[k], vec_text(b.position[k]), vec_text(b.velocity[k]),
                       vec_text(b.spin[k]), vec_text(b.contact_force[k]), vec_text(b.contact_moment[k]));
    out += ball_contacts_text(sim, k, SIZE_MAX);
  }
  return out;
}

}  // namespace hilldem
