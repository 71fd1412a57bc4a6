// hilldem command-line interface: parse options, hand over to the engine, map errors to exit codes.
//   0 success · 1 a run failed (no equilibrium, blow-up) or verify found a mismatch · 2 bad input
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "hilldem/bench/bed_bench.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/scenario.hpp"
#include "hilldem/verify/verify.hpp"

namespace {

int run_command(const std::string& file, const std::string& output, bool quiet) {
  hilldem::Scenario sc = hilldem::load_scenario_file(file);
  hilldem::RunOptions opt;
  opt.quiet = quiet;
  opt.output_dir = output;
  if (!quiet) std::cout << "hilldem run " << file << (sc.title.empty() ? "" : ": " + sc.title) << "\n";
  const hilldem::RunResult res = hilldem::run_scenario(sc, opt, std::cout);
  if (!res.probes.empty()) {
    std::cout << fmt::format("{:<12} {:<26} {:<22} {:>16} {}\n", "label", "quantity", "target", "value", "unit");
    for (const auto& p : res.probes)
      std::cout << fmt::format("{:<12} {:<26} {:<22} {:>16.8g} {}\n", p.label, p.quantity, p.target, p.value, p.unit);
  }
  if (!res.history_path.empty()) std::cout << "history: " << res.history_path << "\n";
  return 0;
}

int verify_command(const std::string& csv_path, bool quiet) {
  const hilldem::VerifyReport report = hilldem::run_verify(std::cout, quiet);
  std::cout << report.table();
  if (!csv_path.empty()) {
    const auto parent = std::filesystem::path(csv_path).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    std::ofstream(csv_path) << report.csv();
    std::cout << "report: " << csv_path << "\n";
  }
  return report.all_pass() ? 0 : 1;
}

int bench_command(hilldem::BedBenchOptions o) {
  if (o.data.empty()) {
    for (const std::string p : {std::string("bench/pack_base.data"), std::string(HILLDEM_SOURCE_DIR) + "/bench/pack_base.data"})
      if (std::filesystem::exists(p)) {
        o.data = p;
        break;
      }
    if (o.data.empty())
      throw hilldem::InputError("no bed: pass --data FILE (a LAMMPS data file from bench/lammps/in.pack)");
  }
  std::cout << hilldem::run_bed_bench(o).line() << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"hilldem: discrete-element engine for unsaturated granular materials (PFC 6 hill contact model)"};
  app.require_subcommand(1);

  std::string file, output, csv;
  bool quiet = false;

  auto* run = app.add_subcommand("run", "Run a scenario file (TOML): its stages, histories and probes");
  run->add_option("file", file, "scenario file (.toml)")->required();
  run->add_option("-o,--output", output, "output folder (overrides [output] dir)");
  run->add_flag("-q,--quiet", quiet, "no progress lines");

  auto* check = app.add_subcommand("check", "Validate a scenario file without running it");
  check->add_option("file", file, "scenario file (.toml)")->required();

  auto* contacts = app.add_subcommand("contacts", "Run a scenario and list every contact, its model and the rule that assigned it");
  contacts->add_option("file", file, "scenario file (.toml)")->required();

  auto* verify = app.add_subcommand("verify", "Run the memo's test problems and compare with its reference values");
  verify->add_option("--csv", csv, "also write the comparison as CSV to this file");
  verify->add_flag("-q,--quiet", quiet, "only the table");

  hilldem::BedBenchOptions bench_opt;
  auto* bench = app.add_subcommand("bench", "Time the dense bed of bench/ (hill model, periodic x-y, floor, gravity, dt 1e-6 s); prints one line");
  bench->add_option("--data", bench_opt.data, "LAMMPS data file of the bed (default bench/pack_base.data)");
  bench->add_option("--replicate", bench_opt.replicate, "copies in x and y (3: 100,800 spheres)")->check(CLI::Range(1, 20));
  bench->add_option("--steps", bench_opt.steps, "timed steps")->check(CLI::Range(1, 100000000));
  bench->add_option("--warmup", bench_opt.warmup, "untimed steps first")->check(CLI::Range(0, 100000000));
  bench->add_option("--threads", bench_opt.threads, "OpenMP threads (0: default)")->check(CLI::Range(0, 1024));

  auto* quantities = app.add_subcommand("quantities", "List the quantities histories and probes can record");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }

  try {
    if (*run) return run_command(file, output, quiet);
    if (*check) {
      const hilldem::Scenario sc = hilldem::load_scenario_file(file);
      std::cout << fmt::format("{}: valid ({} balls, {} walls, {} assignment rules, {} stages, {} histories)\n", file,
                               sc.sim.balls.size(), sc.sim.walls.size(), sc.sim.table.rules.size(), sc.stages.size(),
                               sc.histories.size());
      return 0;
    }
    if (*contacts) {
      hilldem::Scenario sc = hilldem::load_scenario_file(file);
      hilldem::RunOptions opt;
      opt.quiet = true;
      opt.write_files = false;
      hilldem::run_scenario(sc, opt, std::cout);
      std::cout << hilldem::contact_listing(sc.sim);
      return 0;
    }
    if (*verify) return verify_command(csv, quiet);
    if (*bench) return bench_command(bench_opt);
    if (*quantities) {
      std::cout << hilldem::quantity_catalogue() << "\n";
      return 0;
    }
  } catch (const hilldem::InputError& e) {
    std::cerr << "hilldem: error: " << e.what() << "\n";
    return 2;
  } catch (const hilldem::RunError& e) {
    std::cerr << "hilldem: run failed: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "hilldem: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
