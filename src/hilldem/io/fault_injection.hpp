// Fault injection for the crash-recovery tests: the environment variable HILLDEM_FAULT_INJECTION
// makes a run kill itself with SIGKILL (no clean-up, like `kill -9` or a node failure) at a chosen
// point, so that tests can check that `hilldem resume` recovers. Unset (always, outside tests), it
// does nothing. Forms, comma-separated:
//   kill-after-step=N        SIGKILL right after cycle N (after any checkpoint due at that step)
//   kill-in-checkpoint=K     SIGKILL halfway through writing the K-th checkpoint file of this process
#pragma once

#include <cstdint>

namespace hilldem {

class FaultInjection {
 public:
  // Called by the runner after every cycle.
  void on_step(std::int64_t step) const;
  // Called by the checkpoint writer with the temporary file half written.
  void on_checkpoint_half_written();
  bool active() const { return kill_after_step_ >= 0 || kill_in_checkpoint_ > 0; }

  // Parse a specification (the variable's value); throws InputError when malformed.
  static FaultInjection parse(const char* spec);

 private:
  std::int64_t kill_after_step_ = -1;
  std::int64_t kill_in_checkpoint_ = -1;
  std::int64_t checkpoints_ = 0;
};

// The process-wide instance, read from HILLDEM_FAULT_INJECTION on first use.
FaultInjection& fault_injection();

}  // namespace hilldem
