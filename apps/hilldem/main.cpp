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

  try {
    for (const Command& c : commands)
      if (c.sub && *c.sub) {
#ifdef HILLDEM_MPI
        const std::string name = c.sub->get_name();
        if (g_size > 1 && name != "bench" && name != "run" && name != "resume" && name != "triaxial" && name != "t307")
          throw hilldem::InputError("'" + name + "' does not run decomposed over MPI ranks yet (only 'bench', 'run', "
                                    "'resume', 'triaxial' and 't307' do, docs/mpi.md): run it without mpirun, or with -np 1");
#endif
        return c.run();
      }
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
  return 0;
}
