// Progress of a long run: steps, simulated time, stage progress, the mean unbalanced-force ratio and
// an ETA. On a terminal one line is rewritten in place (at most a few times a second); otherwise a
// plain line is printed every `interval` seconds, so logs stay readable. Short stages print nothing.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>

namespace hilldem {

class Simulation;

enum class ProgressMode { Auto, InPlace, Lines, Off };

struct ProgressStage {
  std::size_t index = 0, count = 0;  // 1-based stage number and the number of stages
  std::string type, name;
  std::int64_t total_steps = -1;     // known length (cycle, translate, rotate), or -1
  double target_ratio = 0.0;         // solve: the ratio to reach (> 0), else 0
  std::int64_t max_steps = 0;        // solve: the step limit
};

class Progress {
 public:
  using Clock = std::function<double()>;  // seconds, monotonic
  // mode Auto: InPlace when `is_terminal`, else Lines. `interval` [s] between plain lines.
  Progress(std::ostream& out, ProgressMode mode, bool is_terminal, double interval = 10.0, Clock clock = {});

  void begin_stage(const ProgressStage& stage, std::int64_t steps_done);
  // After a cycle: `steps_done` inside the stage. Cheap unless an update is due; `ratio` (solve) is
  // the current mean unbalanced-force ratio when the caller has it (< 0: computed here when needed).
  void tick(const Simulation& sim, std::int64_t steps_done, double ratio = -1.0);
  // Remove the in-place line before other output is written to the terminal.
  void clear();
  bool enabled() const { return mode_ != ProgressMode::Off; }

  // The status text for the current state (also used by tests).
  std::string status(const Simulation& sim, std::int64_t steps_done, double ratio, double now);

 private:
  std::ostream& out_;
  ProgressMode mode_;
  double interval_;
  Clock clock_;
  ProgressStage stage_;
  double stage_start_ = 0.0, last_print_ = 0.0;
  std::int64_t start_steps_ = 0;
  bool line_shown_ = false;
  std::size_t line_width_ = 0;
  // Solve: the ratio at the stage start and its log-rate of decrease, for the ETA.
  double first_ratio_ = -1.0, first_ratio_time_ = 0.0;
};

// "0:01:05", "2:03:04:05" (days), "?" for unknown or absurd values.
std::string format_duration(double seconds);

}  // namespace hilldem
