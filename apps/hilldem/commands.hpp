// Each CLI subcommand lives in its own cmd_*.cpp: it registers its options on the app and returns
// the action to run when it is chosen. main.cpp only parses and maps errors to exit statuses.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <vector>

namespace hilldem::cli {

struct Command {
  CLI::App* sub = nullptr;
  std::function<int()> run;  // returns the exit status
};

// Options live as long as the app: each add_* keeps its state in a shared_ptr captured by `run`.
std::vector<Command> add_scenario_commands(CLI::App& app);  // run, check, contacts, quantities
Command add_verify_command(CLI::App& app);
Command add_bench_command(CLI::App& app);
Command add_resume_command(CLI::App& app);   // continue a run from a checkpoint
Command add_inspect_command(CLI::App& app);  // describe a checkpoint
Command add_run_output_options(CLI::App& app);  // snapshot/checkpoint options of `run` (after add_scenario_commands)
Command add_triaxial_command(CLI::App& app);  // material genesis and triaxial tests (labtests/)
Command add_t307_command(CLI::App& app);  // AASHTO T 307 resilient modulus (labtests/t307)

}  // namespace hilldem::cli
