#include "hilldem/engine/hill_param_sets.hpp"

#include <array>
#include <atomic>
#include <bit>
#include <map>

namespace hilldem {

namespace {
// Hill parameters by their bits.
std::array<std::uint64_t, 3> param_bits(const HillParams& p) {
  return {std::bit_cast<std::uint64_t>(p.fric_coef), std::bit_cast<std::uint64_t>(p.damp_con),
          std::bit_cast<std::uint64_t>(p.suction)};
}
bool same_bits(const HillParams& x, const HillParams& y) { return param_bits(x) == param_bits(y); }
}  // namespace

void HillParamSets::refresh(const ContactStore& contacts, const ModelTable& table) {
  // Rows mostly share their neighbour's set: one comparison, and a map lookup only when the
  // parameters change along the rows.
  std::map<std::array<std::uint64_t, 3>, std::uint32_t> index;
  sets_.clear();
  auto intern = [&](const HillParams& p) {
    const auto [it, added] = index.try_emplace(param_bits(p), static_cast<std::uint32_t>(sets_.size()));
    if (added) sets_.push_back(p);
    return it->second;
  };
  rule_set_.resize(table.rules.size());
  for (std::size_t r = 0; r < table.rules.size(); ++r) rule_set_[r] = intern(table.rules[r].hill);
  const std::size_t rows = contacts.size();
  row_set_.assign(rows, 0);
  if (sets_.empty()) sets_.push_back(HillParams{});  // (no rules: every row's index is valid)
  std::uint32_t last = 0;
  for (std::size_t c = 0; c < rows; ++c) {
    if (contacts.model[c] != ModelKind::Hill) continue;
    const HillParams& p = contacts.hill_params[c];
    if (!same_bits(sets_[last], p)) last = intern(p);
    row_set_[c] = last;
  }
  stale_ = false;
}

void HillParamSets::new_row(std::size_t c, std::size_t rule, const HillParams& params) {
  if (c < row_set_.size() && rule < rule_set_.size() && same_bits(sets_[rule_set_[rule]], params))
    row_set_[c] = rule_set_[rule];
  else
    std::atomic_ref<bool>(stale_).store(true, std::memory_order_relaxed);
}

}  // namespace hilldem
