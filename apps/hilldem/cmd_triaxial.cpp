// hilldem triaxial: material genesis and servo-controlled triaxial tests of the memo's Class 5
// materials, one case or the whole study (docs/lab-tests.md).
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdlib>
#include <utility>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <omp.h>

#include "commands.hpp"
#include "hilldem/bodies/clump_shapes.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/io/output_folder.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/stop_signal.hpp"
#include "hilldem/labtests/specimen_io.hpp"
#include "hilldem/labtests/study.hpp"

namespace hilldem::cli {

namespace {

// The vessels and the default study's scale and grain count are the library's (labtests/study.hpp):
// the CLI's default study is StudySettings{}'s.
constexpr double kMemoRadius = kMemoVesselRadius, kMemoHeight = kMemoVesselHeight;
constexpr double kT307Radius = kT307VesselRadius, kT307Height = kT307VesselHeight;
constexpr double kDefaultScale = kDefaultVesselScale;

struct Options {
  bool study = false;
  std::string grading = "C5b";
  std::string material = "hill";
  bool wet = false;
  std::string output;
  bool full = false;
  double scale = kDefaultScale;
  std::string vessel = "memo";
  int min_grains = -1;  // -1: kDefaultMinGrains unless --scale or --full
  std::int64_t seed = 10000;
  double packing_pressure = 150e3;  // P_m [Pa]
  std::vector<double> confinements{150e3};  // σ_c [Pa]; more than one: a sweep
  bool pack_linear = false;
  std::vector<double> cycles{0.02, 0.05};  // [%]
  double final_strain = 1.0;                // [%]
  double strain_rate = TriaxialSettings{}.strain_rate;              // [1/s]
  double final_strain_rate = TriaxialSettings{}.final_strain_rate;  // [1/s]
  double density_scaling = 0.0;                                     // F [-]
  double unload_to = 0.1;
  double suction = 20e3;
  double moisture_gap = 3e-3;
  double d_mult = 1.0;
  double finalize_ratio = EquilibriumSettings{}.ratio;
  std::string specimen;
  std::string clump_template;             // "" : balls
  std::string clump_size = "equal-volume";
  bool no_plot = false;
  bool pack_only = false;
  bool grading_given = false;  // --grading on the command line
  bool scale_given = false;    // --scale on the command line
  int threads = 1;
  int jobs = 0;  // 0: the number of cores
  bool quiet = false;
};

// Options -> settings and cases; every check that can fail does so here, before any work.
std::pair<StudySettings, std::vector<CaseSpec>> build(const Options& o) {
  StudySettings s;
  if (o.full && o.scale_given) throw InputError("give either --full or --scale, not both");
  const double scale = o.full ? 1.0 : o.scale;
  if (!(scale > 0 && scale <= 4)) throw InputError(fmt::format("--scale must be in (0, 4], got {:g}", scale));
  const std::string vessel = lower(o.vessel);
  if (vessel != "memo" && vessel != "t307")
    throw InputError("unknown vessel '" + o.vessel + "': choose memo (170 mm x 240 mm) or t307 (152 mm x 305 mm, H/D = 2)");
  s.genesis.vessel_radius = (vessel == "memo" ? kMemoRadius : kT307Radius) * scale;
  s.genesis.vessel_height = (vessel == "memo" ? kMemoHeight : kT307Height) * scale;
  s.min_grains = o.min_grains >= 0 ? o.min_grains : (o.full || o.scale_given ? 0 : kDefaultMinGrains);
  s.genesis.d_mult = o.d_mult;
  if (o.seed < 0) throw InputError(fmt::format("--seed must be >= 0, got {}", o.seed));
  s.genesis.packing.seed = static_cast<std::uint64_t>(o.seed);
  std::vector<std::pair<const char*, double>> pressures{{"--packing-pressure", o.packing_pressure}};
  for (double c : o.confinements) pressures.emplace_back("--confinement", c);
  if (o.confinements.empty()) throw InputError("--confinement needs at least one value [Pa]");
  for (const auto& [name, value] : pressures)
    if (!(value > 0) || !std::isfinite(value))
      throw InputError(fmt::format("{} must be a finite number > 0 Pa, got {:g}", name, value));
  for (std::size_t i = 1; i < o.confinements.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (o.confinements[i] == o.confinements[j])
        throw InputError(fmt::format("--confinement lists {:g} Pa twice", o.confinements[i]));
  s.genesis.packing.equilibrium.pressure = o.packing_pressure;
  s.finalize = s.genesis.packing.equilibrium;
  s.finalize.ratio = o.finalize_ratio;  // validated with the rest
  s.triaxial.confinement = o.confinements.front();
  s.pack_linear = o.pack_linear;
  s.triaxial.cycle_strains.clear();
  for (double c : o.cycles) s.triaxial.cycle_strains.push_back(c / 100.0);
  s.triaxial.final_strain = o.final_strain / 100.0;
  if (!(o.strain_rate > 0)) throw InputError(fmt::format("--strain-rate must be > 0 1/s, got {:g}", o.strain_rate));
  if (!(o.final_strain_rate > 0))
    throw InputError(fmt::format("--final-strain-rate must be > 0 1/s, got {:g}", o.final_strain_rate));
  s.triaxial.strain_rate = o.strain_rate;
  s.triaxial.final_strain_rate = o.final_strain_rate;
  s.triaxial.density_scaling = o.density_scaling;  // validated with the rest
  s.triaxial.unload_fraction = o.unload_to;
  s.suction = o.suction;
  s.moisture_gap = o.moisture_gap;
  s.specimen_file = o.specimen;
  s.genesis.clump_mix = parse_clump_mix(o.clump_template, "--clump-template");
  check_clump_mix(s.genesis.clump_mix, "--clump-template");
  const std::string size = lower(o.clump_size);
  if (size != "equal-volume" && size != "enclosing")
    throw InputError("--clump-size must be equal-volume or enclosing, got '" + o.clump_size + "'");
  if (o.clump_template.empty() && size != "equal-volume") throw InputError("--clump-size needs --clump-template");
  s.genesis.clump_size = size == "enclosing" ? SizeMeasure::EnclosingDiameter : SizeMeasure::EqualVolumeDiameter;
  s.jobs = o.jobs;  // validated with the rest
  std::vector<CaseSpec> cases;
  if (o.study) {
    if (o.wet) throw InputError("--wet and --study: the study already has its wet case");
    if (!o.specimen.empty()) throw InputError("--specimen and --study: the study packs one specimen per grading");
  }
  if (o.pack_only && !o.specimen.empty()) throw InputError("--pack-only and --specimen: nothing to pack");
  if (o.study) {
    cases = memo_cases();
    s.output_dir = o.output.empty() ? "out/study" : o.output;
  } else {
    std::string grading = o.grading;
    if (!o.specimen.empty() && !o.grading_given) {
      // The specimen's own grading, when it is a built-in one (a file's grading needs --grading FILE).
      const std::string g = lower(load_packed_specimen(o.specimen).grading);
      if (g == "c5n" || g == "c5b") grading = g == "c5n" ? "C5n" : "C5b";
    }
    const std::string m = lower(o.material);
    if (m != "hill" && m != "linear") throw InputError("unknown material '" + o.material + "': choose linear or hill");
    cases.push_back({grading, m == "hill" ? GrainModel::Hill : GrainModel::Linear, o.wet});
    s.output_dir = o.output.empty() ? "out/triaxial" : o.output;
  }
  if (o.confinements.size() > 1) cases = sweep_confinements(cases, o.confinements);
  validate(s, cases);
  return {s, cases};
}

int run_locked(const Options& o, const StudySettings& settings, const std::vector<CaseSpec>& cases, bool root);

int run(const Options& o) {
  // Under mpirun every rank runs every case on its part of the specimen, one case at a time; rank 0
  // logs and writes (docs/mpi.md, "The lab tests over ranks").
  const std::unique_ptr<RunDecomposition> ranks = decomposed_run();
  const bool root = !ranks || ranks->rank() == 0;
  auto [settings, cases] = build(o);  // throws InputError (exit 2) before anything is written
  settings.genesis.ranks = ranks.get();
  // The folder is this process's while it runs (io/output_folder.hpp); an unwritable one is bad input.
  const OutputLock lock = lab_output_lock(settings.output_dir, ranks.get());
  settings.genesis.interrupt = lab_stop_check(ranks.get());
  try {
    return run_locked(o, settings, cases, root);
  } catch (const Interrupted& e) {
    return root ? report_lab_stop(e, settings.output_dir, "triaxial") : 128 + stop_requested();
  }
}

int run_locked(const Options& o, const StudySettings& settings, const std::vector<CaseSpec>& cases, bool root) {
  if (o.threads > 0) omp_set_num_threads(o.threads);  // 0: OpenMP's default (OMP_NUM_THREADS or all cores)
  std::ostream* log = o.quiet || !root ? nullptr : &std::cout;
  if (log)
    *log << fmt::format("hilldem triaxial: {} case{} in a {:.0f} mm x {:.0f} mm vessel{}{}; output {}\n", cases.size(),
                        cases.size() > 1 ? "s" : "", 2e3 * settings.genesis.vessel_radius, 1e3 * settings.genesis.vessel_height,
                        o.full || (o.scale_given && o.scale == 1.0)
                            ? fmt::format(" (full size, {})", lower(o.vessel) == "t307" ? "T 307's" : "the memo's")
                            : fmt::format(" (scaled by {:g}; --full for the full size)", o.scale),
                        settings.min_grains > 0
                            ? fmt::format(", each grading's scaled up to hold {} grains (--min-grains)", settings.min_grains)
                            : std::string(),
                        settings.output_dir);
  if (log && !settings.genesis.clump_mix.empty())
    *log << fmt::format("grains: clumps of {} ({}), {}turned at random from the seed\n", clump_mix_words(settings.genesis.clump_mix),
                        to_string(settings.genesis.clump_size),
                        settings.genesis.clump_mix.size() > 1 ? "each grain's template drawn from the seed, " : "");
  if (o.pack_only) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    const std::vector<PackedResult> packed = make_all_packed(settings, cases, true, log);
    if (!root) return 0;
    std::cout << "\n" << packing_table(packed);
    std::cout << "\nconverged when " << criterion_text(settings.genesis.packing.equilibrium) << "\n";
    std::cout << fmt::format("\nspecimens: {}/specimens/; {:.0f} s wall, {:.0f} s CPU\n", settings.output_dir,
                             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                             static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
    return 0;
  }
  const StudyResult result = run_study(settings, cases, log);
  if (!root) return 0;
  std::cout << "\n" << result.summary_markdown();
  std::cout << fmt::format("\nsummary: {}/summary.csv, {}/summary.md; {:.0f} s wall, {:.0f} s CPU in all\n", settings.output_dir,
                           settings.output_dir, result.seconds, result.cpu_seconds);
  if (!o.no_plot) run_plot_script("scripts/plot_triaxial.py", settings.output_dir, "figures");
  return 0;
}

}  // namespace

Command add_triaxial_command(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "triaxial",
      "Material genesis (grading, boundary-contraction packing, finalization, wetting) and a servo-controlled triaxial "
      "test with load-unload cycles; --study runs the memo's five Class 5 cases");
  cmd->add_flag("--study", o->study, "the memo's study: C5n/C5b x linear/hill, plus C5b hill wet, with a summary and figures");
  CLI::Option* grading = cmd->add_option(
      "--grading", o->grading,
      "C5n, C5b, or a CSV file of d_lower_mm,d_upper_mm,fraction rows (default C5b, or the --specimen's grading)");
  cmd->add_option("--material", o->material, "grain-grain model: linear or hill (default hill)");
  cmd->add_flag("--wet", o->wet, "make_wet(suction, moisture gap) at the end of genesis (hill only)");
  cmd->add_option("-o,--output", o->output, "output folder (default out/triaxial, or out/study with --study)");
  cmd->add_flag("--full", o->full, "the full-size vessel (--vessel: the memo's 170 mm x 240 mm by default); every grading in it");
  CLI::Option* scale = cmd->add_option(
      "--scale", o->scale,
      "vessel size relative to the full one (default 0.5, each grading's scaled up to hold --min-grains); every grading in it")
      ->check(finite_number());
  cmd->add_option("--vessel", o->vessel,
                  "vessel shape at full size: memo (170 mm x 240 mm, the default) or t307 (AASHTO T 307's 152 mm x 305 mm, H/D = 2)");
  cmd->add_option("--min-grains", o->min_grains,
                  "scale each grading's vessel up (never down) until it holds this many grains (default 500 without --scale "
                  "or --full, else 0 = off)")
      ->check(CLI::Range(0, 1000000));
  cmd->add_option("--seed", o->seed, "random seed of the grain cloud (default 10000, Table 7)");
  cmd->add_option("--packing-pressure", o->packing_pressure,
                  "packing pressure P_m [Pa]: packing, finalization and wetting (default 150e3, Table 7)");
  cmd->add_option("--confinement", o->confinements,
                  "confining pressure sigma_c of the triaxial test [Pa] (default 150e3); when it differs from P_m the "
                  "specimen is first brought to it on every wall; a comma list (50e3,100e3,150e3) runs every case at each")
      ->delimiter(',');
  cmd->add_flag("--pack-linear", o->pack_linear,
                "pack every material with frictionless linear contacts, one packing per grading shared "
                "by both materials (a deviation from the memo, which packs each material with its own model)");
  cmd->add_option("--cycles", o->cycles, "axial strains [%] at which load-unload cycles reverse, increasing (default 0.02,0.05)")
      ->delimiter(',')->check(finite_number());
  cmd->add_option("--final-strain", o->final_strain, "final axial strain [%] (default 1)")->check(finite_number());
  cmd->add_option("--strain-rate", o->strain_rate, "axial strain rate during the cycles [1/s] (default 0.02)")->check(finite_number());
  cmd->add_option("--final-strain-rate", o->final_strain_rate, "axial strain rate after the cycles [1/s] (default 0.1)")->check(finite_number());
  cmd->add_option("--density-scaling", o->density_scaling,
                  "triaxial tests with a fixed time step F times the automatic one and density scaling: F times "
                  "fewer steps (0 = off, the default; or 1 to 50)")->check(finite_number());
  cmd->add_option("--unload-to", o->unload_to, "unload until q falls to this fraction of q at the reversal (default 0.1)")->check(finite_number());
  cmd->add_option("--suction", o->suction, "suction of make_wet [Pa] (default 20e3)")->check(finite_number());
  cmd->add_option("--moisture-gap", o->moisture_gap, "moisture gap of make_wet [m] (default 3e-3)")->check(finite_number());
  cmd->add_option("--d-mult", o->d_mult, "diameter multiplier D_mult (default 1)")->check(finite_number());
  cmd->add_option("--finalize-ratio", o->finalize_ratio, "equilibrium ratio after finalization and wetting (default 8e-3)")->check(finite_number());
  cmd->add_option("--specimen", o->specimen, "start from a saved packed specimen (out/.../specimens/<grading>_packed.csv)");
  cmd->add_option("--clump-template", o->clump_template,
                  std::string("grains as clumps of this template (") + kNamedTemplates +
                      "), or of a mix by solid volume fraction, NAME:FRACTION,... summing to 1 (elongated2:0.6,sphere:0.4); "
                      "each scaled to its drawn size and turned at random from the seed (docs/clumps.md); default: balls");
  cmd->add_option("--clump-size", o->clump_size,
                  "what a clump's drawn size is: equal-volume (the diameter of the sphere of equal volume, the default) or "
                  "enclosing (the diameter of the smallest sphere about its centre of mass that holds it)");
  cmd->add_flag("--pack-only", o->pack_only,
                "genesis only: pack the specimen(s) and save them to <output>/specimens/ for later --specimen runs");
  cmd->add_flag("--no-plot", o->no_plot, "do not run scripts/plot_triaxial.py");
  cmd->add_option("--threads", o->threads,
                  "OpenMP threads per case (default 1: lab specimens are small and gain little; 0: OpenMP's default)")
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--jobs", o->jobs,
                  "cases (and packings) run at once, each on its own thread (default 0: the number of cores); "
                  "when fewer are left than cores, the ones running take the idle cores; results do not depend on it")
      ->check(CLI::Range(0, 1024));
  cmd->add_flag("-q,--quiet", o->quiet, "only the summary");
  return {cmd, [o, grading, scale] {
            o->grading_given = grading->count() > 0;
            o->scale_given = scale->count() > 0;
            return run(*o);
          }};
}

}  // namespace hilldem::cli
