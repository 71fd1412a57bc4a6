// hilldem verify: the memo's test problems against its reference values.
#include <filesystem>
#include <fstream>
#include <iostream>

#include "commands.hpp"
#include "hilldem/verify/verify.hpp"

namespace hilldem::cli {

Command add_verify_command(CLI::App& app) {
  struct Options {
    std::string csv;
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  auto* verify = app.add_subcommand("verify", "Run the memo's test problems and compare with its reference values");
  verify->add_option("--csv", o->csv, "also write the comparison as CSV to this file");
  verify->add_flag("-q,--quiet", o->quiet, "only the table");
  return {verify, [o] {
            const VerifyReport report = run_verify(std::cout, o->quiet);
            std::cout << report.table();
            if (!o->csv.empty()) {
              const auto parent = std::filesystem::path(o->csv).parent_path();
              if (!parent.empty()) std::filesystem::create_directories(parent);
              std::ofstream(o->csv) << report.csv();
              std::cout << "report: " << o->csv << "\n";
            }
            return report.all_pass() ? 0 : 1;
          }};
}

}  // namespace hilldem::cli
