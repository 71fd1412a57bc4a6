#include "hilldem/verify/verify.hpp"

#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <map>
#include <ostream>
#include <sstream>

#include "hilldem/core/error.hpp"
#include "hilldem/embedded_data.hpp"
#include "hilldem/io/runner.hpp"

namespace hilldem {

const std::vector<std::string>& verify_scenarios() {
  static const std::vector<std::string> names = {
      "examples/two_grains_linear.toml", "examples/two_grains_hill.toml",
      "examples/two_grains_shear_dashpot.toml", "examples/moisture_test.toml",
      "examples/assembly_27.toml", "examples/restitution.toml"};
  return names;
}

std::vector<ReferenceRow> parse_reference_csv(std::string_view text, const std::string& file) {
  std::vector<ReferenceRow> rows;
  std::istringstream in{std::string(text)};
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (n == 1 || line.empty()) continue;  // header
    std::vector<std::string> f;
    std::string cell;
    std::istringstream ls(line);
    while (std::getline(ls, cell, ',')) f.push_back(cell);
    if (f.size() != 6) throw InputError(fmt::format("{}: line {}: expected 6 comma-separated fields, got {}", file, n, f.size()));
    ReferenceRow r;
    r.id = f[0];
    r.quantity = f[1];
    r.unit = f[3];
    r.source = f[5];
    try {
      r.memo_value = std::stod(f[2]);
      std::size_t used = 0;
      r.tolerance = std::stod(f[4], &used);
      r.relative = f[4].find("relative", used) != std::string::npos;
      if (!r.relative && f[4].find("absolute", used) == std::string::npos) throw std::invalid_argument("kind");
    } catch (const std::exception&) {
      throw InputError(fmt::format("{}: line {}: memo_value must be a number and tolerance '<number> relative|absolute'", file, n));
    }
    rows.push_back(r);
  }
  return rows;
}

bool VerifyReport::all_pass() const {
  for (const VerifyRow& r : rows)
    if (!r.pass) return false;
  return !rows.empty();
}

std::string VerifyReport::table() const {
  std::string out = fmt::format("{:<4} {:<62} {:>12} {:>14} {:<10} {}\n", "id", "quantity", "memo", "computed",
                                "unit", "pass");
  for (const VerifyRow& r : rows) {
    std::string q = r.ref.quantity.size() > 62 ? r.ref.quantity.substr(0, 59) + "..." : r.ref.quantity;
    out += fmt::format("{:<4} {:<62} {:>12.5g} {:>14} {:<10} {}\n", r.ref.id, q, r.ref.memo_value,
                       r.produced ? fmt::format("{:.7g}", r.computed) : "-", r.ref.unit,
                       r.pass ? "PASS" : (r.produced ? "FAIL" : "FAIL (not produced)"));
  }
  std::size_t passed = 0;
  for (const VerifyRow& r : rows) passed += r.pass;
  out += fmt::format("{} of {} reference values pass\n", passed, rows.size());
  return out;
}

std::string VerifyReport::csv() const {
  std::string out = "id,quantity,memo_value,computed,unit,tolerance,pass,scenario\n";
  for (const VerifyRow& r : rows)
    out += fmt::format("{},{},{:.9g},{},{},{:g} {},{},{}\n", r.ref.id, r.ref.quantity, r.ref.memo_value,
                       r.produced ? fmt::format("{:.9g}", r.computed) : "", r.ref.unit, r.ref.tolerance,
                       r.ref.relative ? "relative" : "absolute", r.pass ? "pass" : "fail", r.scenario);
  return out;
}

VerifyReport run_verify(std::ostream& log, bool quiet) {
  std::map<std::string, std::pair<double, std::string>> computed;  // label -> (value, scenario)
  for (const std::string& name : verify_scenarios()) {
    const auto start = std::chrono::steady_clock::now();
    Scenario sc = load_scenario(std::string(embedded::find(name)), name);
    RunOptions opt;
    opt.quiet = true;
    opt.write_files = false;
    const RunResult res = run_scenario(sc, opt, log);
    for (const ProbeValue& p : res.probes) computed[p.label] = {p.value, name};
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!quiet) log << fmt::format("ran {:<42} {:>8} steps  {:6.2f} s\n", name, sc.sim.steps, secs);
  }
  VerifyReport report;
  for (const char* csv : {"data/reference-values.csv", "data/engine-checks.csv"}) {
    for (const ReferenceRow& ref : parse_reference_csv(embedded::find(csv), csv)) {
      VerifyRow row;
      row.ref = ref;
      const auto it = computed.find(ref.id);
      if (it != computed.end()) {
        row.produced = true;
        row.computed = it->second.first;
        row.scenario = it->second.second;
        const double err = std::abs(row.computed - ref.memo_value);
        const double allowed = ref.relative ? ref.tolerance * std::abs(ref.memo_value) : ref.tolerance;
        row.pass = std::isfinite(row.computed) && err <= allowed;
      }
      report.rows.push_back(row);
    }
  }
  return report;
}

}  // namespace hilldem
