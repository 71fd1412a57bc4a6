// The memo's checks (hilldem verify) and the lab tests (grading, genesis, triaxial, study) as
// functions returning dicts and numpy arrays.
#include <pybind11/stl.h>

#include <sstream>

#include "bindings.hpp"
#include "hilldem/verify/verify.hpp"

namespace py = pybind11;

namespace hilldem::python {

namespace {

// hilldem verify's rows: {id: {'quantity', 'unit', 'memo', 'computed', 'tolerance', 'relative', 'pass',
// 'scenario', 'produced'}}.
py::dict verify() {
  std::ostringstream log;
  VerifyReport report;
  {
    py::gil_scoped_release release;
    report = run_verify(log, true);
  }
  py::dict out;
  for (const VerifyRow& r : report.rows) {
    py::dict d;
    d["quantity"] = r.ref.quantity;
    d["unit"] = r.ref.unit;
    d["memo"] = r.ref.memo_value;
    d["computed"] = r.computed;
    d["tolerance"] = r.ref.tolerance;
    d["relative"] = r.ref.relative;
    d["pass"] = r.pass;
    d["produced"] = r.produced;
    d["scenario"] = r.scenario;
    out[py::str(r.ref.id)] = d;
  }
  return out;
}

}  // namespace

void bind_labtests(py::module_& m) {
  m.def("verify", &verify,
        R"(Run the memo's test problems (as `hilldem verify`). Returns {id: {'quantity', 'unit', 'memo',
'computed', 'tolerance', 'relative', 'pass', 'produced', 'scenario'}}, values in the row's unit.)");
}

}  // namespace hilldem::python
