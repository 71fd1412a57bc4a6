// hilldem resume DIR_OR_FILE: continue a run from its last checkpoint (io/runner.hpp).
#include <iostream>

#include "commands.hpp"
#include "hilldem/io/runner.hpp"

namespace hilldem::cli {

Command add_resume_command(CLI::App& app) {
  struct Options {
    std::string path, output;
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "resume",
      "Continue a run from its newest intact checkpoint: give the run's output folder, its checkpoints/ folder or a "
      "checkpoint file. The result is bitwise that of an uninterrupted run.");
  cmd->add_option("path", o->path, "output folder, checkpoints/ folder or checkpoint file (.hdc)")->required();
  cmd->add_option("-o,--output", o->output, "write the outputs here instead of the checkpoint's output folder");
  cmd->add_flag("-q,--quiet", o->quiet, "no stage lines or progress");
  return {cmd, [o] {
            RunOptions opt;
            opt.quiet = o->quiet;
            opt.output_dir = o->output;
            Scenario sc;
            if (!o->quiet) std::cout << "hilldem resume " << o->path << "\n";
            const RunResult res = resume_scenario(o->path, sc, opt, std::cout);
            if (!o->quiet)
              std::cout << (res.already_complete ? "the run had already finished; nothing to do\n"
                                                 : "finished at step " + std::to_string(sc.sim.steps) +
                                                       (sc.title.empty() ? "" : ": " + sc.title) + "\n");
            std::cout << probe_table(res);
            if (!res.history_path.empty()) std::cout << "history: " << res.history_path << "\n";
            return 0;
          }};
}

}  // namespace hilldem::cli
