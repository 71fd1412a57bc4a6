// How long an idle OpenMP thread spins before it sleeps (docs/performance.md, "Threads on busy cores").
//
// Each step runs several parallel regions, and at each one's end a thread that is done waits for the
// others. libgomp's default is to spin 300,000 times first (GOMP_SPINCOUNT). Where other processes hold
// the cores, the thread it waits for is often not running, and the spinner burns its time slice for
// nothing before the other gets the core: on two cores with two other busy processes, 30,000 spins ran
// the 11,200-sphere bench bed at two threads in a third of the time of 300,000, and on quiet cores as
// fast (farm-bench table in the same doc); not spinning at all (OMP_WAIT_POLICY=passive) halves the
// speed of small beds on quiet cores.
#pragma once

namespace hilldem::cli {

inline constexpr const char* kSpinCount = "30000";  // [spins]

// Unless GOMP_SPINCOUNT or OMP_WAIT_POLICY is in the environment: set GOMP_SPINCOUNT to kSpinCount and
// execute this program again with the same arguments (libgomp reads it only when it is loaded).
// Returns only when it does not re-execute. First thing in main, before MPI starts.
void set_openmp_spin(char** argv);

}  // namespace hilldem::cli
