#include "hilldem/io/progress.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <ostream>

#include "hilldem/engine/simulation.hpp"

namespace hilldem {

namespace {
constexpr double kInPlaceFirst = 0.5;    // [s] before the first in-place update (short stages stay silent)
constexpr double kInPlacePeriod = 0.25;  // [s] between in-place updates

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string thousands(std::int64_t v) {
  const std::string digits = std::to_string(v < 0 ? -v : v);
  std::string s;
  if (v < 0) s.push_back('-');
  for (std::size_t k = 0; k < digits.size(); ++k) {
    if (k > 0 && (digits.size() - k) % 3 == 0) s.push_back(',');
    s.push_back(digits[k]);
  }
  return s;
}
}  // namespace

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0 || seconds > 1e8) return "?";
  auto s = static_cast<std::int64_t>(std::llround(seconds));
  const std::int64_t d = s / 86400;
  s %= 86400;
  const std::string hms = fmt::format("{}:{:02}:{:02}", s / 3600, s % 3600 / 60, s % 60);
  return d > 0 ? fmt::format("{}:{}", d, hms) : hms;
}

Progress::Progress(std::ostream& out, ProgressMode mode, bool is_terminal, double interval, Clock clock)
    : out_(out), mode_(mode), interval_(interval > 0.0 ? interval : 10.0), clock_(clock ? std::move(clock) : Clock(steady_seconds)) {
  if (mode_ == ProgressMode::Auto) mode_ = is_terminal ? ProgressMode::InPlace : ProgressMode::Lines;
}

void Progress::begin_stage(const ProgressStage& stage, std::int64_t steps_done) {
  if (mode_ == ProgressMode::Off) return;
  clear();
  stage_ = stage;
  stage_start_ = last_print_ = clock_();
  start_steps_ = steps_done;
  first_ratio_ = -1.0;
}

std::string Progress::status(const Simulation& sim, std::int64_t steps_done, double ratio, double now) {
  const double elapsed = std::max(now - stage_start_, 1e-9);
  const double rate = static_cast<double>(steps_done - start_steps_) / elapsed;  // [steps/s]
  std::string s = fmt::format("[{}/{}] {} '{}'  step {}  t = {:.4e} s", stage_.index, stage_.count, stage_.type,
                              stage_.name, thousands(sim.steps), sim.time);
  double eta = -1.0;
  if (stage_.total_steps > 0) {
    const double frac = std::clamp(static_cast<double>(steps_done) / static_cast<double>(stage_.total_steps), 0.0, 1.0);
    s += fmt::format("  stage {:.1f}% ({}/{} steps)", 100.0 * frac, thousands(steps_done), thousands(stage_.total_steps));
    if (rate > 0.0) eta = static_cast<double>(stage_.total_steps - steps_done) / rate;
  }
  if (ratio < 0.0) ratio = sim.mean_unbalanced_ratio();
  if (stage_.target_ratio > 0.0) {
    s += fmt::format("  ratio {:.3e} -> {:.1e}", ratio, stage_.target_ratio);
    // Progress and ETA from the log-linear trend of the ratio since the stage began (its usual decay).
    if (first_ratio_ < 0.0 && ratio > 0.0) first_ratio_ = ratio, first_ratio_time_ = now;
    if (first_ratio_ > 0.0 && ratio > 0.0 && first_ratio_ > stage_.target_ratio) {
      const double span = std::log(first_ratio_ / stage_.target_ratio);
      const double done = std::log(first_ratio_ / ratio);
      s += fmt::format("  stage ~{:.0f}%", 100.0 * std::clamp(done / span, 0.0, 1.0));
      const double dt = now - first_ratio_time_;
      if (done > 0.0 && dt > 0.0) eta = (span - done) / (done / dt);
    }
    // Never beyond the step limit.
    if (rate > 0.0) {
      const double limit = static_cast<double>(stage_.max_steps - steps_done) / rate;
      eta = eta < 0.0 ? -1.0 : std::min(eta, limit);
    }
    s += fmt::format("  (max {} steps)", thousands(stage_.max_steps));
  } else {
    s += fmt::format("  ratio {:.3e}", ratio);
  }
  s += fmt::format("  {} steps/s  ETA {}", thousands(static_cast<std::int64_t>(rate)), eta < 0.0 ? "?" : format_duration(eta));
  return s;
}

void Progress::tick(const Simulation& sim, std::int64_t steps_done, double ratio) {
  if (mode_ == ProgressMode::Off) return;
  const double now = clock_();
  if (mode_ == ProgressMode::InPlace) {
    if (now - stage_start_ < kInPlaceFirst || now - last_print_ < kInPlacePeriod) return;
    last_print_ = now;
    std::string line = status(sim, steps_done, ratio, now);
    const std::size_t width = line.size();
    if (width < line_width_) line.append(line_width_ - width, ' ');  // erase the rest of a longer line
    out_ << '\r' << line << std::flush;
    line_width_ = width;
    line_shown_ = true;
  } else {
    if (now - last_print_ < interval_) return;
    last_print_ = now;
    out_ << status(sim, steps_done, ratio, now) << '\n' << std::flush;
  }
}

void Progress::clear() {
  if (!line_shown_) return;
  out_ << '\r' << std::string(line_width_, ' ') << '\r' << std::flush;
  line_shown_ = false;
  line_width_ = 0;
}

}  // namespace hilldem
