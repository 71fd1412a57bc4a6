// The memo's test problems (spec §5, §7) as regression tests: every reference value of
// data/reference-values.csv is produced by the example scenarios and matches to the printed digits.
#include <gtest/gtest.h>

#include <set>
#include <sstream>

#include "hilldem/embedded_data.hpp"
#include "hilldem/verify/verify.hpp"

namespace hilldem {
namespace {

TEST(MemoReferenceValues, AllProducedAndWithinTolerance) {
  std::ostringstream log;
  const VerifyReport report = run_verify(log, true);
  for (const VerifyRow& row : report.rows) {
    EXPECT_TRUE(row.produced) << row.ref.id << " was not produced by any example scenario";
    EXPECT_TRUE(row.pass) << row.ref.id << " " << row.ref.quantity << ": memo " << row.ref.memo_value << ", computed "
                          << row.computed;
  }
  EXPECT_TRUE(report.all_pass()) << report.table();
}

// The ids the issue requires: L1-L5, H1-H8, D2-D7, A1, M1-M3 (and T1).
TEST(MemoReferenceValues, CoversTheRequiredIds) {
  std::set<std::string> ids;
  for (const auto& r : parse_reference_csv(embedded::find("data/reference-values.csv"), "reference-values.csv"))
    ids.insert(r.id);
  for (const char* id : {"L1", "L2", "L3", "L4", "L5", "H1", "H2", "H3", "H4", "H5", "H6", "H7", "H8", "D2", "D3",
                         "D4", "D5", "D6", "D7", "A1", "M1", "M2", "M3", "T1"})
    EXPECT_TRUE(ids.count(id)) << id;
}

TEST(ReferenceCsv, RejectsMalformedRows) {
  EXPECT_THROW(parse_reference_csv("h\nX1,q,abc,N,5e-5 relative,src\n", "x.csv"), std::exception);
  EXPECT_THROW(parse_reference_csv("h\nX1,q,1.0,N\n", "x.csv"), std::exception);
  EXPECT_THROW(parse_reference_csv("h\nX1,q,1.0,N,5e-5 sideways,src\n", "x.csv"), std::exception);
}

}  // namespace
}  // namespace hilldem
