// Options of `hilldem run` for its outputs and fault tolerance: snapshots for ParaView, checkpoints,
// blow-up detection. They override the scenario's [snapshots], [checkpoints] and
// [simulation] blowup_fraction (io/runner.hpp: OutputOverrides); the run saves them in its
// checkpoints, so `hilldem resume` continues with the same settings.
#include "commands.hpp"
#include "hilldem/io/runner.hpp"

namespace hilldem::cli {

Command add_run_output_options(CLI::App& app) {
  CLI::App* run = app.get_subcommand("run");
  OutputOverrides& o = output_overrides();
  run->add_option_function<std::int64_t>(
         "--snapshots-every", [&o](std::int64_t n) { o.snapshot_every = n; },
         "write VTK snapshots for ParaView every N steps and at stage ends (0: at stage ends only)")
      ->check(CLI::Range(std::int64_t{0}, INT64_MAX));
  run->add_option_function<std::string>(
         "--snapshot-format", [&o](const std::string& f) { o.snapshot_binary = f == "binary"; },
         "binary (default) or ascii")
      ->check(CLI::IsMember({"binary", "ascii"}));
  run->add_option_function<std::int64_t>(
         "--checkpoint-every", [&o](std::int64_t n) { o.checkpoint_every = n; },
         "write a checkpoint every N steps (also at stage ends; `hilldem resume` continues from the newest)")
      ->check(CLI::Range(std::int64_t{0}, INT64_MAX));
  run->add_option_function<double>(
         "--checkpoint-seconds", [&o](double s) { o.checkpoint_seconds = s; },
         "write a checkpoint every S seconds of wall-clock time (default 600; 0: not by time)")
      ->check(finite_range(0.0, 1e9, "s"));
  run->add_flag_function(
      "--no-checkpoints", [&o](std::int64_t) { o.no_checkpoints = true; }, "write no checkpoints");
  run->add_option_function<double>(
         "--blowup-fraction", [&o](double f) { o.blowup_fraction = f; },
         "stop when a free ball moves more than F times its radius in one step (default 0.5; 0: off)")
      ->check(finite_range(0.0, 1e9, "-"));
  return {nullptr, {}};
}

}  // namespace hilldem::cli
