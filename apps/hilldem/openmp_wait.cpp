#include "openmp_wait.hpp"

#include <cstdlib>

#include <unistd.h>

namespace hilldem::cli {

void set_openmp_spin(char** argv) {
  // A user's own choice stands (and, once set here, the process is the re-executed one).
  if (std::getenv("GOMP_SPINCOUNT") || std::getenv("OMP_WAIT_POLICY")) return;
  if (::setenv("GOMP_SPINCOUNT", kSpinCount, 0) != 0) return;
  // libgomp reads its environment when it is loaded, before main: only a new image of this program
  // sees the setting. If exec fails, the run goes on with libgomp's default (slower on busy cores,
  // the same results).
  ::execv("/proc/self/exe", argv);
}

}  // namespace hilldem::cli
