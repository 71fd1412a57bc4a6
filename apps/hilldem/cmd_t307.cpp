// hilldem t307: the AASHTO T 307 resilient-modulus protocol (conditioning + 15 sequences of haversine
// pulses, time-scaled) on a Class 5 specimen, packed here or loaded, with the universal-model fit
// (docs/t307.md).
#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>

#include <omp.h>

#include "commands.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/io/output_folder.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/stop_signal.hpp"
#include "hilldem/labtests/specimen_io.hpp"
#include "hilldem/labtests/study.hpp"
#include "hilldem/labtests/t307.hpp"

namespace hilldem::cli {

namespace {

namespace fs = std::filesystem;

constexpr double kMemoRadius = kMemoVesselRadius, kMemoHeight = kMemoVesselHeight;  // the memo's vessel [m]

struct Options {
  std::string grading = "C5b";
  std::string material = "hill";
  bool wet = false;
  std::string specimen;
  std::string output = "out/t307";
  double scale = 0.3;
  std::int64_t seed = 10000;
  double packing_pressure = 150e3;  // P_m [Pa]
  double suction = 20e3;            // [Pa]
  double moisture_gap = 3e-3;       // [m]
  double finalize_ratio = EquilibriumSettings{}.ratio;
  T307Timing timing;
  std::vector<int> sequences;       // empty: 0..15
  double max_permanent_strain = 5.0;  // [%]
  int threads = 1;
  bool no_plot = false;
  bool quiet = false;
};

struct Plan {
  StudySettings study;
  CaseSpec c;
  T307Settings test;
};

// Every check that can fail, before any work.
Plan build(const Options& o) {
  Plan p;
  if (!(o.scale > 0 && o.scale <= 4) || !std::isfinite(o.scale))
    throw InputError(fmt::format("--scale must be in (0, 4], got {:g}", o.scale));
  StudySettings& s = p.study;
  s.genesis.vessel_radius = kMemoRadius * o.scale;
  s.genesis.vessel_height = kMemoHeight * o.scale;
  s.min_grains = 0;  // --scale is the specimen's size, not scaled up for a grain count
  if (o.seed < 0) throw InputError(fmt::format("--seed must be >= 0, got {}", o.seed));
  s.genesis.packing.seed = static_cast<std::uint64_t>(o.seed);
  if (!(o.packing_pressure > 0) || !std::isfinite(o.packing_pressure))
    throw InputError(fmt::format("--packing-pressure must be a finite number > 0 Pa, got {:g}", o.packing_pressure));
  s.genesis.packing.equilibrium.pressure = o.packing_pressure;
  s.finalize = s.genesis.packing.equilibrium;
  s.finalize.ratio = o.finalize_ratio;
  s.suction = o.suction;
  s.moisture_gap = o.moisture_gap;
  s.specimen_file = o.specimen;
  s.output_dir = o.output;
  s.jobs = 1;
  const std::string m = lower(o.material);
  if (m != "hill" && m != "linear") throw InputError("unknown material '" + o.material + "': choose linear or hill");
  std::string grading = o.grading;
  if (!o.specimen.empty()) {  // the specimen's own grading, when it is a built-in one
    const std::string g = lower(load_packed_specimen(o.specimen).grading);
    if (g == "c5n" || g == "c5b") grading = g == "c5n" ? "C5n" : "C5b";
  }
  p.c = {grading, m == "hill" ? GrainModel::Hill : GrainModel::Linear, o.wet};
  validate(s, {p.c});
  p.test.timing = o.timing;
  if (!o.sequences.empty()) {
    const auto all = t307_base_sequences();
    std::set<int> seen;
    p.test.sequences.clear();
    for (int n : o.sequences) {
      if (n < 0 || n > 15) throw InputError(fmt::format("--sequences: each must be in [0, 15], got {}", n));
      if (!seen.insert(n).second) throw InputError(fmt::format("--sequences: {} given twice", n));
      p.test.sequences.push_back(all[static_cast<std::size_t>(n)]);
    }
  }
  if (!(o.max_permanent_strain > 0 && o.max_permanent_strain <= 50))
    throw InputError(fmt::format("--max-permanent-strain must be in (0, 50] %, got {:g}", o.max_permanent_strain));
  p.test.max_permanent_strain = o.max_permanent_strain / 100.0;
  validate(p.test);
  return p;
}

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream f(path);
  f << text;
  if (!f) throw RunError("cannot write " + path.string());
}

int run_locked(const Options& o, const Plan& plan, std::ostream* log);

int run(const Options& o) {
  // Under mpirun every rank runs the test on its part of the specimen; rank 0 logs and writes
  // (docs/mpi.md, "The lab tests over ranks").
  const std::unique_ptr<RunDecomposition> ranks = decomposed_run();
  const bool root = !ranks || ranks->rank() == 0;
  Plan plan = build(o);  // throws InputError (exit 2) before anything is written
  plan.study.genesis.ranks = ranks.get();
  if (o.threads > 0) omp_set_num_threads(o.threads);
  std::ostream* log = o.quiet || !root ? nullptr : &std::cout;
  // The folder is this process's while it runs (io/output_folder.hpp); an unwritable one is bad input.
  const OutputLock lock = lab_output_lock(o.output, ranks.get());
  plan.study.genesis.interrupt = lab_stop_check(ranks.get());
  try {
    return run_locked(o, plan, log);
  } catch (const Interrupted& e) {
    return root ? report_lab_stop(e, o.output, "t307") : 128 + stop_requested();
  }
}

int run_locked(const Options& o, const Plan& plan, std::ostream* log) {
  const fs::path out = o.output;
  PackedResult packed = make_packed(plan.study, plan.c.grading, plan.c.model, o.specimen.empty(), log);
  Specimen s = std::move(packed.specimen);  // (over ranks: the whole specimen on every rank)
  const std::size_t grains = s.sim.balls.size();
  const RanksScope on_ranks(s, plan.c.wet ? plan.study.moisture_gap : 0.0);  // (the ghosts cover make_wet's gap)
  Class5Material m = plan.study.material;
  m.model = plan.c.model;
  finalize(s, m, plan.study.test_walls, plan.study.finalize, log);
  if (plan.c.wet) make_specimen_wet(s, plan.study.suction, plan.study.moisture_gap, plan.study.finalize, log);
  const SpecimenState start = measure(s);
  const T307Result r = run_t307(s, plan.test, log);
  if (!is_root(s)) return 0;

  write_file(out / "t307_sequences.csv", r.sequences_csv());
  write_file(out / "t307_cycles.csv", r.cycles_csv());
  if (r.fitted) write_file(out / "t307_fit.csv", r.fit.csv());
  const T307Timing& tm = plan.test.timing;
  std::string summary = fmt::format(
      "hilldem t307: {} ({}), {} grains, vessel {:.1f} mm x {:.1f} mm, porosity {:.4f} at the start\n"
      "time-scaled AASHTO T 307: pulse {:g} s, rest {:g} s, settle {:g} s, {} cycles per sequence ({} conditioning), "
      "M_r and nu from the last {}; time step {:.3g} s; {} steps, {:.0f} s\n",
      plan.c.name(), packed.file.empty() ? "packed here" : packed.file, grains, 2e3 * r.radius0, 1e3 * r.height0,
      start.porosity, tm.pulse_duration, tm.rest_duration, tm.settle_duration, tm.cycles, tm.conditioning_cycles,
      tm.averaged_cycles, r.timestep, r.steps, r.seconds);
  summary += r.text();
  write_file(out / "t307_summary.txt", summary);
  std::cout << "\n" << summary;
  std::cout << fmt::format("outputs: {}/t307_sequences.csv, t307_cycles.csv, {}t307_summary.txt\n", out.string(),
                           r.fitted ? "t307_fit.csv, " : "");
  if (!o.no_plot) run_plot_script("scripts/plot_t307.py", out.string(), "figure");
  return 0;
}

}  // namespace

Command add_t307_command(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "t307",
      "AASHTO T 307 resilient modulus (base/subbase): conditioning and 15 sequences of haversine deviator pulses under "
      "stress control, time-scaled; M_r, Poisson's ratio, permanent strain and the k1-k3 universal-model fit");
  cmd->add_option("--grading", o->grading, "C5n, C5b, or a grading CSV file (default C5b, or the --specimen's grading)");
  cmd->add_option("--material", o->material, "grain-grain model: linear or hill (default hill)");
  cmd->add_flag("--wet", o->wet, "make_wet(suction, moisture gap) after finalization (hill only)");
  cmd->add_option("--specimen", o->specimen, "start from a saved packed specimen (<output>/specimens/*_packed.csv of `hilldem t307` or `hilldem triaxial --pack-only`)");
  cmd->add_option("-o,--output", o->output, "output folder (default out/t307)");
  cmd->add_option("--scale", o->scale, "vessel size relative to the memo's 170 mm x 240 mm, in (0, 4] (default 0.3)");
  cmd->add_option("--seed", o->seed, "random seed of the grain cloud (default 10000)");
  cmd->add_option("--packing-pressure", o->packing_pressure, "packing and finalization pressure P_m [Pa] (default 150e3)");
  cmd->add_option("--suction", o->suction, "suction of make_wet [Pa] (default 20e3)");
  cmd->add_option("--moisture-gap", o->moisture_gap, "moisture gap of make_wet [m] (default 3e-3)");
  cmd->add_option("--finalize-ratio", o->finalize_ratio, "equilibrium ratio after finalization and wetting (default 8e-3)");
  cmd->add_option("--pulse-duration", o->timing.pulse_duration, "haversine pulse [s], in [1e-5, 1] (default 2e-3; the standard: 0.1)");
  cmd->add_option("--rest-duration", o->timing.rest_duration, "rest at the contact stress after each pulse [s], in [0, 10] (default 1e-3)");
  cmd->add_option("--settle-duration", o->timing.settle_duration,
                  "hold at sigma3 and the contact stress before each sequence [s], in [0, 10] (default 2e-3)");
  cmd->add_option("--cycles", o->timing.cycles, "pulses per sequence, in [1, 100] (default 10; the standard: 100)");
  cmd->add_option("--conditioning-cycles", o->timing.conditioning_cycles,
                  "pulses of the conditioning sequence, in [0, 1000] (default 20; the standard: 500-1000)");
  cmd->add_option("--averaged-cycles", o->timing.averaged_cycles, "M_r and nu from the last this many cycles, in [1, cycles] (default 5)");
  cmd->add_option("--servo-gain", o->timing.servo_gain, "gain alpha_s of the axial and radial servos, in (0, 1] (default 0.5)");
  cmd->add_option("--sequences", o->sequences, "run only these sequences, in this order (0 = conditioning; default 0,1,...,15)")
      ->delimiter(',');
  cmd->add_option("--max-permanent-strain", o->max_permanent_strain,
                  "stop when the total permanent axial strain passes this [%], in (0, 50] (default 5, the standard's)");
  cmd->add_option("--threads", o->threads, "OpenMP threads (default 1; 0: OpenMP's default)")->check(CLI::Range(0, 1024));
  cmd->add_flag("--no-plot", o->no_plot, "do not run scripts/plot_t307.py");
  cmd->add_flag("-q,--quiet", o->quiet, "only the summary");
  return {cmd, [o] { return run(*o); }};
}

}  // namespace hilldem::cli
