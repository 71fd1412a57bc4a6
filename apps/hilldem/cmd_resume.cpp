// hilldem resume DIR_OR_FILE: continue a run from its last checkpoint (io/runner.hpp).
#include <iostream>

#include <filesystem>
#include <fmt/format.h>

#include "commands.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/io/checkpoint.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/stop_signal.hpp"
#ifdef HILLDEM_MPI
#include "hilldem/parallel/mpi_world.hpp"
#include "hilldem/parallel/run_mpi.hpp"
#endif

namespace hilldem::cli {

std::unique_ptr<RunDecomposition> decomposed_run() {
#ifdef HILLDEM_MPI
  if (parallel::world() != MPI_COMM_NULL) return std::make_unique<parallel::RunOverRanks>(parallel::world());
#endif
  return nullptr;
}

int report_stop(int signal, std::int64_t step, double time, const std::string& checkpoint, const std::string& checkpoint_dir) {
  std::cout.flush();
  if (checkpoint.empty())
    std::cerr << fmt::format("hilldem: stopped by {} at step {} (t = {:.6g} s); no checkpoint written (checkpoints are "
                             "off), so the run cannot be resumed\n",
                             signal_name(signal), step, time);
  else
    std::cerr << fmt::format("hilldem: stopped by {} at step {} (t = {:.6g} s); checkpoint {}\n  continue with: hilldem "
                             "resume {}\n",
                             signal_name(signal), step, time, checkpoint,
                             std::filesystem::path(checkpoint_dir).parent_path().string());
  return 128 + signal;
}

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
  CLI::Option* output = cmd->add_option("-o,--output", o->output, "write the outputs here instead of the checkpoint's output folder");
  cmd->add_flag("-q,--quiet", o->quiet, "no stage lines or progress");
  return {cmd, [o, output] {
            if (output->count() > 0 && o->output.empty()) throw InputError("-o: the output folder name is empty");
            Scenario sc;
            // (Over MPI ranks every rank resumes its part of the run; rank 0 writes and prints.)
            const std::unique_ptr<RunDecomposition> ranks = decomposed_run();
            const bool root = !ranks || ranks->rank() == 0;
            const bool quiet = o->quiet || !root;
            if (!quiet) set_state_io_log(&std::cerr);
            install_stop_handlers();
            RunOptions opt;
            opt.quiet = quiet;
            opt.output_dir = o->output;
            opt.decomposition = ranks.get();
            if (!quiet) std::cout << "hilldem resume " << o->path << "\n";
            const RunResult res = resume_scenario(o->path, sc, opt, std::cout);
            if (!root) return res.stopped_by ? 128 + res.stopped_by : 0;
            if (res.stopped_by) return report_stop(res.stopped_by, sc.sim.steps, sc.sim.time, res.last_checkpoint, res.checkpoint_dir);
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
