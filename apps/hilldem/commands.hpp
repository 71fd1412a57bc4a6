// Each CLI subcommand lives in its own cmd_*.cpp: it registers its options on the app and returns
// the action to run when it is chosen. main.cpp only parses and maps errors to exit statuses.
#pragma once

#include <CLI/CLI.hpp>
#include <cctype>
#include <cmath>
#include <fmt/format.h>
#include <functional>
#include <memory>
#include <vector>

#include "hilldem/core/error.hpp"
#include "hilldem/io/output_folder.hpp"

namespace hilldem {
class RunDecomposition;  // io/runner.hpp
}

namespace hilldem::cli {

// The run over MPI ranks when an MPI launcher started this process (docs/mpi.md; the MPI build
// only), else null: RunOptions::decomposition of 'run' and 'resume'.
std::unique_ptr<RunDecomposition> decomposed_run();

struct Command {
  CLI::App* sub = nullptr;
  std::function<int()> run;  // returns the exit status
};

// A real option's range check, as the TOML keys have: NaN and inf are refused (CLI::Range lets NaN
// through, since every comparison with NaN is false). The parse error exits with status 2.
inline CLI::Validator finite_range(double lo, double hi, const std::string& unit) {
  const bool any = lo == -HUGE_VAL && hi == HUGE_VAL;
  const std::string range = any ? std::string("finite") : fmt::format("[{:g}, {:g}] {}", lo, hi, unit);
  return CLI::Validator(
      [lo, hi, range, any](std::string& text) -> std::string {
        double v = 0.0;
        const std::string in = any ? std::string() : " in " + range;
        if (!CLI::detail::lexical_cast(text, v)) return "must be a number" + in + "; got \"" + text + "\"";
        if (!std::isfinite(v) || v < lo || v > hi) return "must be a finite number" + in + "; got " + text;
        return "";
      },
      range);
}
// An option's word in lower case, for case-insensitive choices (--material HILL, --vessel T307).
inline std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

inline CLI::Validator finite_number() { return finite_range(-HUGE_VAL, HUGE_VAL, ""); }

// The figures of a lab command: `/usr/bin/python3 SCRIPT FOLDER` (SCRIPT relative to the working
// folder, else to the source tree), a line naming `what` if the script is missing or fails (the CSV
// results stand either way). Defined in plot_script.cpp.
void run_plot_script(const std::string& script, const std::string& folder, const std::string& what);

// After a run that a signal stopped (RunResult::stopped_by): the message on stderr saying where it
// stopped and how to resume; returns the exit status, 128 + the signal number. Defined in cmd_resume.cpp.
int report_stop(int signal, std::int64_t step, double time, const std::string& checkpoint, const std::string& checkpoint_dir);

// The lab commands' graceful stop (lab_stop.cpp): lab_stop_check() installs the signal handlers and
// returns the predicate for GenesisSpec::interrupt; report_lab_stop says where the test stopped and
// which packed specimens were kept, and returns 128 + the signal number.
// Over MPI ranks (ranks not null) the predicate is every rank's answer combined, asked by every rank
// before every cycle, so that all stop at the same cycle.
std::function<bool()> lab_stop_check(RunDecomposition* ranks = nullptr);
int report_lab_stop(const Interrupted& e, const std::string& output_dir, const std::string& command);
// A lab command's output folder lock (io/output_folder.hpp), taken by rank 0 alone over MPI ranks;
// its refusal (InputError) is thrown on every rank.
OutputLock lab_output_lock(const std::string& dir, RunDecomposition* ranks);

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
