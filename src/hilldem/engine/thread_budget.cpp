#include "hilldem/engine/thread_budget.hpp"

#include <algorithm>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace hilldem {

namespace {
thread_local const ThreadBudget* current_budget = nullptr;
}  // namespace

void set_thread_budget(const ThreadBudget* budget) { current_budget = budget; }

const ThreadBudget* thread_budget() { return current_budget; }

void apply_thread_budget() {
  if (!current_budget) return;
#ifdef _OPENMP
  const int n = std::max(1, current_budget->threads());
  if (n != omp_get_max_threads()) omp_set_num_threads(n);  // this thread's later parallel regions
#endif
}

}  // namespace hilldem
