// hilldem run | check | contacts | quantities
#include <fmt/format.h>

#include <iostream>

#include "commands.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/io/checkpoint.hpp"
#include "hilldem/io/output_folder.hpp"
#include "hilldem/io/stop_signal.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/scenario.hpp"

namespace hilldem::cli {

namespace {
struct Options {
  std::string file, output;
  bool output_given = false;  // -o on the command line (an empty -o is refused, not "no folder")
  bool quiet = false;
};

// The output folder a run would write: refused (InputError, exit status 2) when it cannot be one.
void check_output_folder(const std::string& file, const std::string& scenario_dir, const Options& o) {
  if (o.output_given && o.output.empty()) throw InputError("-o: the output folder name is empty");
  const std::string& dir = o.output_given ? o.output : scenario_dir;
  if (dir.empty()) return;  // no [output] dir and no -o: the run writes no files
  const std::string problem = output_folder_problem(dir);
  if (!problem.empty())
    throw InputError(o.output_given ? "-o: " + problem : file + ": key 'output.dir': " + problem);
}

int run(const Options& o) {
  Scenario sc = load_scenario_file(o.file);
  check_output_folder(o.file, sc.output_dir, o);
  // (Over MPI ranks every rank runs its part of the scenario; rank 0 writes and prints.)
  const std::unique_ptr<RunDecomposition> ranks = decomposed_run();
  const bool root = !ranks || ranks->rank() == 0;
  const bool quiet = o.quiet || !root;
  RunOptions opt;
  opt.quiet = quiet;
  opt.output_dir = o.output;
  opt.decomposition = ranks.get();
  if (!quiet) std::cout << "hilldem run " << o.file << (sc.title.empty() ? "" : ": " + sc.title) << "\n";
  if (!quiet) set_state_io_log(&std::cerr);
  install_stop_handlers();
  const RunResult res = run_scenario(sc, opt, std::cout);
  if (!root) return res.stopped_by ? 128 + res.stopped_by : 0;
  if (res.stopped_by) return report_stop(res.stopped_by, sc.sim.steps, sc.sim.time, res.last_checkpoint, res.checkpoint_dir);
  if (!res.probes.empty()) {
    std::cout << fmt::format("{:<12} {:<26} {:<22} {:>16} {}\n", "label", "quantity", "target", "value", "unit");
    for (const auto& p : res.probes)
      std::cout << fmt::format("{:<12} {:<26} {:<22} {:>16.8g} {}\n", p.label, p.quantity, p.target, p.value, p.unit);
  }
  if (!res.history_path.empty()) std::cout << "history: " << res.history_path << "\n";
  return 0;
}
}  // namespace

std::vector<Command> add_scenario_commands(CLI::App& app) {
  auto o = std::make_shared<Options>();
  std::vector<Command> out;

  auto* run_cmd = app.add_subcommand("run", "Run a scenario file (TOML): its stages, histories and probes");
  run_cmd->add_option("file", o->file, "scenario file (.toml)")->required();
  CLI::Option* output = run_cmd->add_option("-o,--output", o->output, "output folder (overrides [output] dir)");
  run_cmd->add_flag("-q,--quiet", o->quiet, "no progress lines");
  out.push_back({run_cmd, [o, output] {
                   o->output_given = output->count() > 0;
                   return run(*o);
                 }});

  auto* check = app.add_subcommand("check", "Validate a scenario file without running it");
  check->add_option("file", o->file, "scenario file (.toml)")->required();
  out.push_back({check, [o] {
                   const ScenarioDescription sc = read_scenario_file(o->file);  // read and validated, not built
                   check_output_folder(o->file, sc.output_dir, *o);
                   std::size_t pebbles = 0;
                   for (const auto& c : sc.sim.clumps) pebbles += sc.sim.clump_templates[c.tmpl].pebbles.size();
                   const std::string clumps =
                       sc.sim.clumps.empty() ? "" : fmt::format("{} clumps of {} pebbles, ", sc.sim.clumps.size(), pebbles);
                   std::cout << fmt::format("{}: valid ({} balls, {}{} walls, {} assignment rules, {} stages, {} histories)\n",
                                            o->file, sc.sim.balls.size(), clumps, sc.sim.walls.size(),
                                            sc.sim.rules.size(), sc.stages.size(), sc.histories.size());
                   return 0;
                 }});

  auto* contacts = app.add_subcommand("contacts", "Run a scenario and list every contact, its model and the rule that assigned it");
  contacts->add_option("file", o->file, "scenario file (.toml)")->required();
  out.push_back({contacts, [o] {
                   Scenario sc = load_scenario_file(o->file);
                   RunOptions opt;
                   opt.quiet = true;
                   opt.write_files = false;
                   run_scenario(sc, opt, std::cout);
                   std::cout << contact_listing(sc.sim);
                   return 0;
                 }});

  auto* quantities = app.add_subcommand("quantities", "List the quantities histories and probes can record");
  out.push_back({quantities, [] {
                   std::cout << quantity_catalogue() << "\n";
                   return 0;
                 }});
  return out;
}

}  // namespace hilldem::cli
