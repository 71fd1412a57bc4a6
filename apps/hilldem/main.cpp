// hilldem command-line interface: parse options, hand over to the chosen command, map errors to
// exit statuses:
//   0 success · 1 a run failed (no equilibrium, blow-up) or verify found a mismatch · 2 bad input
#include <iostream>

#include "commands.hpp"
#include "openmp_wait.hpp"
#include "hilldem/core/error.hpp"
#ifdef HILLDEM_MPI
#include "hilldem/parallel/mpi_world.hpp"
#endif

namespace {
#ifdef HILLDEM_MPI
// Under mpirun every rank runs the command; messages come from rank 0 (input errors are the same on
// every rank: each reads the same files), a run error from the rank that met it, named, and then
// ends every rank (the others may wait on it in a collective).
int g_rank = 0, g_size = 1;
bool quiet_rank() { return g_rank != 0; }
std::string rank_tag() { return g_size > 1 ? " (rank " + std::to_string(g_rank) + ")" : ""; }
int run_failed(int status) {
  if (g_size > 1) MPI_Abort(MPI_COMM_WORLD, status);
  return status;
}
#else
bool quiet_rank() { return false; }
std::string rank_tag() { return ""; }
int run_failed(int status) { return status; }
#endif
}  // namespace

namespace {
// The command's status, its errors reported (input errors once, from rank 0).
int dispatch(const hilldem::cli::Command& c);
}  // namespace

int main(int argc, char** argv) {
  hilldem::cli::set_openmp_spin(argv);
#ifdef HILLDEM_MPI
  hilldem::parallel::MpiSession mpi(argc, argv);
  g_rank = mpi.rank();
  g_size = mpi.size();
#endif
  CLI::App app{"hilldem: discrete-element engine for unsaturated granular materials (PFC 6 hill contact model)"};
  app.require_subcommand(1);

  using namespace hilldem::cli;
  std::vector<Command> commands = add_scenario_commands(app);
  commands.push_back(add_verify_command(app));
  commands.push_back(add_bench_command(app));
  commands.push_back(add_resume_command(app));
  commands.push_back(add_inspect_command(app));
  commands.push_back(add_run_output_options(app));
  commands.push_back(add_triaxial_command(app));
  commands.push_back(add_t307_command(app));

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

  for (const Command& c : commands)
    if (c.sub && *c.sub) {
#ifdef HILLDEM_MPI
      // The commands that are not decomposed (check, contacts, quantities, verify, inspect: small or
      // reading one file) run on rank 0 alone; the other ranks wait for it and end with its status.
      const std::string name = c.sub->get_name();
      const bool decomposed = name == "bench" || name == "run" || name == "resume" || name == "triaxial" || name == "t307";
      if (g_size > 1 && !decomposed) {
        int status = g_rank == 0 ? dispatch(c) : 0;
        MPI_Bcast(&status, 1, MPI_INT, 0, hilldem::parallel::world());
        return status;
      }
#endif
      return dispatch(c);
    }
  return 0;
}

namespace {

int dispatch(const hilldem::cli::Command& c) {
  try {
    return c.run();
  } catch (const hilldem::InputError& e) {
    if (!quiet_rank()) std::cerr << "hilldem: error: " << e.what() << "\n";
    return 2;
  } catch (const hilldem::RunError& e) {
    std::cerr << "hilldem: run failed" << rank_tag() << ": " << e.what() << "\n";
    return run_failed(1);
  } catch (const std::bad_alloc&) {
    std::cerr << "hilldem: error" << rank_tag() << ": out of memory (outside the phases that report their size)\n";
    return run_failed(1);
  } catch (const std::exception& e) {
    std::cerr << "hilldem: error" << rank_tag() << ": " << e.what() << "\n";
    return run_failed(1);
  }
}

}  // namespace
