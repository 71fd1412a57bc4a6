// ThreadBudget: how many OpenMP threads the passes of a simulation use, asked before every step.
//
// Why: a lab study runs its cases at once, one simulation per thread (labtests/study.hpp, --jobs).
// While every case runs, each should use one core; when fewer cases than cores are left (the last
// long case, a packing that outlasts the others), the ones left should take the idle cores. The
// thread count of a run can change between steps at no cost to reproducibility: every per-body sum
// has a fixed order, so results are bitwise the same for any thread count (test
// Threads.OneAndTwoThreadsGiveBitwiseIdenticalResults, and ThreadBudget.* for a count that changes
// while it runs).
#pragma once

namespace hilldem {

class ThreadBudget {
 public:
  virtual ~ThreadBudget() = default;
  // Threads for the next step (≥ 1).
  virtual int threads() const = 0;
};

// Install `budget` for every simulation stepped on the calling thread (nullptr: none, the OpenMP
// thread count is left as it is). The budget must outlive its use on this thread.
void set_thread_budget(const ThreadBudget* budget);
// The calling thread's budget, or nullptr.
const ThreadBudget* thread_budget();
// Before a step: set the calling thread's OpenMP thread count from its budget, if it has one.
void apply_thread_budget();

}  // namespace hilldem
