// verify: runs the memo's test problems (the example scenarios, compiled in) through the engine and
// compares every probe with the memo's reference values (data/reference-values.csv, spec §7) and the
// engine's narrative checks (data/engine-checks.csv).
#pragma once

#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace hilldem {

struct ReferenceRow {
  std::string id, quantity, unit, source;
  double memo_value = 0.0;
  double tolerance = 0.0;  // relative or absolute
  bool relative = true;
};

// Parse a reference CSV (id,quantity,memo_value,unit,tolerance,source); throws InputError.
std::vector<ReferenceRow> parse_reference_csv(std::string_view text, const std::string& file);

struct VerifyRow {
  ReferenceRow ref;
  std::string scenario;   // which example produced it ("" = none)
  double computed = 0.0;
  bool produced = false;
  bool pass = false;
};

struct VerifyReport {
  std::vector<VerifyRow> rows;
  bool all_pass() const;
  std::string table() const;  // id, quantity, memo, computed, pass
  std::string csv() const;
};

// Runs every memo scenario; progress lines go to log unless quiet.
VerifyReport run_verify(std::ostream& log, bool quiet);

// The example scenarios verify runs, in order.
const std::vector<std::string>& verify_scenarios();

}  // namespace hilldem
