// libFuzzer target: the scenario reader (TOML text -> validated Scenario), as `hilldem check` runs it.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_common.hpp"
#include "hilldem/io/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  hilldem::ScenarioLimits limits;
  limits.max_balls = 20'000;  // keeps each input fast; the limit's check itself is exercised
  hilldem::fuzz::expect_clean_refusal("fuzz.toml", [&] { hilldem::load_scenario(text, "fuzz.toml", limits); });
  return 0;
}
