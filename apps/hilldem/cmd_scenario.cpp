// hilldem run | check | contacts | quantities
#include <fmt/format.h>

#include <iostream>

#include "commands.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/scenario.hpp"

namespace hilldem::cli {

namespace {
struct Options {
  std::string file, output;
  bool quiet = false;
};

int run(const Options& o) {
  Scenario sc = load_scenario_file(o.file);
  RunOptions opt;
  opt.quiet = o.quiet;
  opt.output_dir = o.output;
  if (!o.quiet) std::cout << "hilldem run " << o.file << (sc.title.empty() ? "" : ": " + sc.title) << "\n";
  const RunResult res = run_scenario(sc, opt, std::cout);
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
  run_cmd->add_option("-o,--output", o->output, "output folder (overrides [output] dir)");
  run_cmd->add_flag("-q,--quiet", o->quiet, "no progress lines");
  out.push_back({run_cmd, [o] { return run(*o); }});

  auto* check = app.add_subcommand("check", "Validate a scenario file without running it");
  check->add_option("file", o->file, "scenario file (.toml)")->required();
  out.push_back({check, [o] {
                   const ScenarioDescription sc = read_scenario_file(o->file);  // read and validated, not built
                   std::cout << fmt::format("{}: valid ({} balls, {} walls, {} assignment rules, {} stages, {} histories)\n",
                                            o->file, sc.sim.balls.size(), sc.sim.walls.size(),
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
