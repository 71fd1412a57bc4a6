// Graceful stop on SIGINT, SIGTERM and SIGHUP (Ctrl-C, a batch scheduler's TERM before its time
// limit, a closed terminal). The first signal only sets a flag; the runner polls it between cycles,
// finishes the cycle, writes a checkpoint and returns (the CLI exits with 128 + the signal number,
// saying how to resume). A second signal stops the process at once (the default action).
#pragma once

namespace hilldem {

// Installs the handlers (the CLI's run and resume do; a library user may). Idempotent.
void install_stop_handlers();
// The signal received since the handlers were installed, or 0.
int stop_requested();
// "SIGINT", "SIGTERM", "SIGHUP", or "signal N".
const char* signal_name(int sig);

}  // namespace hilldem
