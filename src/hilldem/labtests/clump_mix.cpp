#include "hilldem/labtests/clump_mix.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "hilldem/bodies/clump_shapes.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/labtests/rng.hpp"

namespace hilldem {

namespace {
std::string trimmed(const std::string& s) {
  const auto a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}
}  // namespace

ClumpMix parse_clump_mix(const std::string& text, const std::string& what) {
  ClumpMix mix;
  if (trimmed(text).empty()) return mix;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    const std::string item = trimmed(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    const std::size_t colon = item.find(':');
    if (colon == std::string::npos) {
      // A name alone is the whole of the grains; in a list every member needs its fraction.
      if (item.empty() || comma != std::string::npos || !mix.empty())
        throw InputError(fmt::format("{}: expected NAME or NAME:FRACTION,NAME:FRACTION,... (fractions of the solid volume, "
                                     "in (0, 1], summing to 1), got '{}'",
                                     what, text));
      mix.emplace_back(item, 1.0);
      return mix;
    }
    const std::string name = trimmed(item.substr(0, colon)), number = trimmed(item.substr(colon + 1));
    char* end = nullptr;
    const double f = std::strtod(number.c_str(), &end);
    if (name.empty() || number.empty() || *end != '\0')
      throw InputError(fmt::format("{}: expected NAME:FRACTION, got '{}' in '{}'", what, item, text));
    mix.emplace_back(name, f);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return mix;
}

void check_clump_mix(const ClumpMix& mix, const std::string& what) {
  double sum = 0.0;
  for (std::size_t i = 0; i < mix.size(); ++i) {
    const auto& [name, f] = mix[i];
    try {
      named_template(name, 1000.0);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: {}", what, e.what()));  // the message lists the known names
    }
    for (std::size_t j = 0; j < i; ++j)
      if (mix[j].first == name) throw InputError(fmt::format("{}: template '{}' is named twice", what, name));
    if (!(f > 0.0 && f <= 1.0))
      throw InputError(fmt::format("{}: the fraction of {} must be in (0, 1] (of the solid volume), got {:g}", what, name, f));
    sum += f;
  }
  if (!mix.empty() && !(std::abs(sum - 1.0) <= kClumpMixSumTolerance))
    throw InputError(fmt::format("{}: the fractions must sum to 1 (within {:g}), got {:.12g}", what, kClumpMixSumTolerance, sum));
}

std::string clump_mix_text(const ClumpMix& mix) {
  if (mix.size() == 1 && mix.front().second == 1.0) return mix.front().first;
  std::string out;
  for (const auto& [name, f] : mix) out += fmt::format("{}{}:{}", out.empty() ? "" : ",", name, f);
  return out;
}

std::string clump_mix_words(const ClumpMix& mix) {
  if (mix.size() == 1 && mix.front().second == 1.0) return mix.front().first;
  std::string out = "a mix by solid volume of ";
  for (std::size_t i = 0; i < mix.size(); ++i) out += fmt::format("{}{} {:g}", i ? ", " : "", mix[i].first, mix[i].second);
  return out;
}

std::vector<std::uint32_t> assign_clump_templates(const std::vector<double>& diameters, const ClumpMix& mix,
                                                  const std::vector<double>& volume_factors, std::uint64_t seed) {
  std::vector<std::uint32_t> kind(diameters.size(), 0);
  if (mix.size() <= 1 || diameters.empty()) return kind;
  // The line is laid out in sphere volumes d³ (π/6 dropped); template t's share of it is w_t / f_t,
  // normalised, so that its clumps' union volumes f_t π d³/6 come to the fraction w_t of the solid.
  std::vector<double> upper(mix.size());
  double norm = 0.0;
  for (std::size_t t = 0; t < mix.size(); ++t) norm += mix[t].second / volume_factors[t];
  double c = 0.0;
  for (std::size_t t = 0; t < mix.size(); ++t) upper[t] = (c += mix[t].second / volume_factors[t] / norm);
  upper.back() = 1.0;
  // A stream of its own (the seed xor a constant, "clumpmix" in ASCII): the sizes, positions and
  // orientations are drawn from the seed's own stream as with one template.
  Rng rng(seed ^ 0x636c756d706d6978ULL);
  std::vector<std::size_t> order(diameters.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  for (std::size_t i = order.size(); i-- > 1;) {  // Fisher–Yates: a random order, so that size and template are unrelated
    const auto j = static_cast<std::size_t>(rng.uniform() * static_cast<double>(i + 1));
    std::swap(order[i], order[std::min(j, i)]);
  }
  const double offset = rng.uniform();
  double total = 0.0;
  for (double d : diameters) total += d * d * d;
  double before = 0.0;
  for (std::size_t i : order) {
    const double v = diameters[i] * diameters[i] * diameters[i];
    double u = (before + 0.5 * v) / total + offset;
    before += v;
    if (u >= 1.0) u -= 1.0;
    std::uint32_t t = 0;
    while (t + 1 < mix.size() && u >= upper[t]) ++t;
    kind[i] = t;
  }
  return kind;
}

}  // namespace hilldem
