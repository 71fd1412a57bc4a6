#include "hilldem/models/model_table.hpp"

namespace hilldem {

const char* to_string(ContactKind k) { return k == ContactKind::BallBall ? "ball-ball" : "ball-wall"; }
const char* to_string(ModelKind m) {
  switch (m) {
    case ModelKind::Linear: return "linear";
    case ModelKind::Hill: return "hill";
    case ModelKind::RrLinear: return "rrlinear";
  }
  return "unknown";
}

namespace {
bool in(std::uint64_t mask, std::uint64_t groups) { return mask == 0 || (mask & groups) != 0; }
}  // namespace

int ModelTable::match(ContactKind kind, std::uint64_t g1, std::uint64_t g2) const {
  for (std::size_t r = 0; r < rules.size(); ++r) {
    const ModelRule& rule = rules[r];
    if (rule.kind != kind) continue;
    const bool direct = in(rule.groups1, g1) && in(rule.groups2, g2);
    const bool swapped = kind == ContactKind::BallBall && in(rule.groups1, g2) && in(rule.groups2, g1);
    if (direct || swapped) return static_cast<int>(r);
  }
  return -1;
}

std::string ModelTable::explain(int r) const {
  if (r < 0) return "no rule matched";
  const ModelRule& rule = rules[r];
  return "rule " + std::to_string(r + 1) + " '" + rule.name + "': first rule for " + to_string(rule.kind) +
         " contacts with groups " + rule.groups1_text + " / " + rule.groups2_text;
}

}  // namespace hilldem
