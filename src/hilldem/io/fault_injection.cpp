#include "hilldem/io/fault_injection.hpp"

#include <csignal>
#include <cstdlib>
#include <string>

#include "hilldem/core/error.hpp"

namespace hilldem {

namespace {
[[noreturn]] void die() {
  std::raise(SIGKILL);
  std::abort();  // not reached
}
}  // namespace

void FaultInjection::on_step(std::int64_t step) const {
  if (kill_after_step_ >= 0 && step == kill_after_step_) die();
}

void FaultInjection::on_checkpoint_half_written() {
  ++checkpoints_;
  if (kill_in_checkpoint_ > 0 && checkpoints_ == kill_in_checkpoint_) die();
}

FaultInjection FaultInjection::parse(const char* spec) {
  FaultInjection f;
  if (!spec) return f;
  const std::string s(spec);
  std::size_t pos = 0;
  while (pos < s.size()) {
    std::size_t comma = s.find(',', pos);
    if (comma == std::string::npos) comma = s.size();
    const std::string item = s.substr(pos, comma - pos);
    pos = comma + 1;
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    const std::string key = item.substr(0, eq);
    std::int64_t value = -1;
    try {
      std::size_t used = 0;
      if (eq == std::string::npos) throw std::invalid_argument("no value");
      value = std::stoll(item.substr(eq + 1), &used);
      if (used != item.size() - eq - 1 || value < 0) throw std::invalid_argument("bad value");
    } catch (const std::exception&) {
      throw InputError("HILLDEM_FAULT_INJECTION: '" + item + "' must be key=N with N >= 0");
    }
    if (key == "kill-after-step") f.kill_after_step_ = value;
    else if (key == "kill-in-checkpoint") f.kill_in_checkpoint_ = value;
    else throw InputError("HILLDEM_FAULT_INJECTION: unknown fault '" + key + "'; known: kill-after-step, kill-in-checkpoint");
  }
  return f;
}

FaultInjection& fault_injection() {
  static FaultInjection instance = FaultInjection::parse(std::getenv("HILLDEM_FAULT_INJECTION"));
  return instance;
}

}  // namespace hilldem
