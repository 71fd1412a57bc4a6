// hilldem command-line interface: parse options, hand over to the chosen command, map errors to
// exit statuses:
//   0 success · 1 a run failed (no equilibrium, blow-up) or verify found a mismatch · 2 bad input
#include <iostream>

#include "commands.hpp"
#include "hilldem/core/error.hpp"

int main(int argc, char** argv) {
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
      if (c.sub && *c.sub) return c.run();
  } catch (const hilldem::InputError& e) {
    std::cerr << "hilldem: error: " << e.what() << "\n";
    return 2;
  } catch (const hilldem::RunError& e) {
    std::cerr << "hilldem: run failed: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "hilldem: error: out of memory (outside the phases that report their size)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "hilldem: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
