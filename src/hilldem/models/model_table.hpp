// ModelTable: the contact-model assignment table (PFC's CMAT). An ordered list of rules; a new
// contact takes the first rule whose contact type and group filters match it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hilldem/models/hill.hpp"
#include "hilldem/models/linear.hpp"

namespace hilldem {

enum class ContactKind : std::uint8_t { BallBall = 0, BallWall = 1 };
// The contact models. A switch over ModelKind names every one (no default; -Werror=switch), so that a
// model added here without its law in the force pass, its reader and its checkpoint code does not
// compile.
enum class ModelKind : std::uint8_t { Linear = 0, Hill = 1, RrLinear = 2 };
inline constexpr std::uint8_t kModelCount = 3;

const char* to_string(ContactKind k);
const char* to_string(ModelKind m);

struct ModelRule {
  std::string name;
  ContactKind kind = ContactKind::BallBall;
  // Group filters (bit masks of GroupNames; 0 = any). Ball-ball: one ball in groups1 and the other in
  // groups2, either way round. Ball-wall: the ball in groups1 and the wall in groups2.
  std::uint64_t groups1 = 0, groups2 = 0;
  std::string groups1_text = "any", groups2_text = "any";  // for listings
  ModelKind model = ModelKind::Linear;
  LinearParams linear;  // linear and rrlinear (μ_r)
  HillParams hill;
};

class ModelTable {
 public:
  std::vector<ModelRule> rules;
  // Index of the first rule matching a contact of kind `kind` between pieces with group masks g1 and
  // g2 (g1 = ball 1, g2 = ball 2 or wall), or -1 when none matches (the pair then gets no contact).
  int match(ContactKind kind, std::uint64_t g1, std::uint64_t g2) const;
  // Why rule r matched, in words ("rule 2 'grain-wall': first rule for ball-wall contacts, groups any/any").
  std::string explain(int r) const;
};

}  // namespace hilldem
