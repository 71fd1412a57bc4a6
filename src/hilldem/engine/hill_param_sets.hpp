// HillParamSets: the distinct hill parameters of the rows and the rules, and each row's index
// into them.
//
// Why: the batched hill law reads a row's parameters (μ, γ_h, ψ: 24 bytes) on every step; a 4-byte
// set index per row instead cuts the pair loop's memory traffic. There are a few sets: the rules',
// and what make_wet and the stages gave. ContactStore::hill_params stays the record; the sets are
// made from it whenever the mappings are (at a rebuild, Simulation::refresh_mappings(), a restore).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "hilldem/contact/contact_store.hpp"
#include "hilldem/models/hill.hpp"
#include "hilldem/models/model_table.hpp"

namespace hilldem {

class HillParamSets {
 public:
  // Every set made again from the rows' and the rules' parameters, told apart by their bits (so
  // that a row's set holds exactly its parameters).
  void refresh(const ContactStore& contacts, const ModelTable& table);
  // Row c became a hill contact with the parameters `params` of rule `rule`: its set is the rule's,
  // if that set still holds them (the table may have changed since the sets were made); else the
  // sets are stale, and made again before the next pass reads them. Safe from the pass's threads.
  void new_row(std::size_t c, std::size_t rule, const HillParams& params);
  // Whether the sets must be made again before a pass over `rows` rows reads them.
  bool stale(std::size_t rows) const { return stale_ || row_set_.size() != rows; }
  const HillParams* sets() const { return sets_.data(); }
  const HillParams& set(std::uint32_t s) const { return sets_[s]; }
  // Per row, its set (valid for hill rows).
  const std::uint32_t* row_sets() const { return row_set_.data(); }

 private:
  std::vector<HillParams> sets_;
  std::vector<std::uint32_t> row_set_;   // per row
  std::vector<std::uint32_t> rule_set_;  // per assignment rule
  bool stale_ = true;  // (set by new_row from the pass's threads: std::atomic_ref)
};

}  // namespace hilldem
