// hilldem inspect FILE: what a checkpoint (or a blow-up state) holds.
#include <iostream>
#include <optional>

#include "commands.hpp"
#include "hilldem/engine/simulation.hpp"
#include "hilldem/io/checkpoint.hpp"
#include "hilldem/io/runner.hpp"
#include "hilldem/io/state_io.hpp"

namespace hilldem::cli {

Command add_inspect_command(CLI::App& app) {
  struct Options {
    std::string file;
    std::int64_t ball = 0;
    bool digest = false;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("inspect", "Describe a checkpoint or blow-up state file: clock, stage, bodies, contacts");
  cmd->add_option("file", o->file, "checkpoint file (.hdc)")->required();
  auto* ball = cmd->add_option("--ball", o->ball, "also list this ball (user id) and every contact it has");
  cmd->add_flag("--digest", o->digest, "print only the digest of the saved state (equal digests: bitwise-equal states)");
  return {cmd, [o, ball] {
            set_state_io_log(&std::cerr);  // progress on reads of large states (stderr)
            if (o->digest) {
              const CheckpointReader r = CheckpointReader::from_file(o->file);
              Simulation sim;
              read_simulation(r, sim, false);
              std::cout << state_digest(sim) << "\n";
              return 0;
            }
            std::cout << describe_checkpoint(o->file, ball->count() ? std::optional<std::int64_t>(o->ball) : std::nullopt);
            return 0;
          }};
}

}  // namespace hilldem::cli
