#include "hilldem/engine/neighbour_list.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "hilldem/bodies/clump_pebbles.hpp"
#include "hilldem/core/error.hpp"

namespace hilldem {

namespace {
// A ball with a non-finite position (a blow-up: Δt too large, or a state that cannot be integrated)
// has no cell: stop with the ball and the step, as the force pass does for a non-finite force
// (which would come only after the list). Every list is made here, and a non-finite travel always
// asks for one.
void check_finite(const BallStore& balls, std::int64_t step) {
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const Vec3& x = balls.position[i];
    if (!std::isfinite(norm2(x) + balls.radius[i]))  // (|x|² overflows too: no distance is finite then)
      throw RunError("ball " + std::to_string(balls.id[i]) + " has a non-finite position at step " +
                     std::to_string(step) + " (" + std::to_string(x.x) + ", " + std::to_string(x.y) + ", " +
                     std::to_string(x.z) + " m): the run is unstable; reduce the time step");
  }
}

void wrap_positions(BallStore& balls, const PeriodicBox& box) {
  if (!box.any()) return;
  for (Vec3& x : balls.position) x = box.wrapped(x);
}

using Candidates = std::vector<std::pair<ContactKey, ImageCode>>;

void sort_by_key(Candidates& all) {
  std::sort(all.begin(), all.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
}

// The ball-ball pairs within reach [m] of balls at `position` [m], with their periodic image; none
// between two pebbles of one clump (clump_of: per ball its clump, empty without clumps).
void add_pair_candidates(Candidates& all, const std::vector<Vec3>& position, const BallStore& balls,
                         const PeriodicBox& box, double reach, const std::vector<std::uint32_t>& clump_of) {
  const std::vector<PairCandidate> pairs = find_pair_candidates(position, balls.radius, reach, box);
  all.reserve(all.size() + pairs.size());
  const bool clumps = !clump_of.empty();
  for (const PairCandidate& p : pairs) {
    if (clumps && clump_of[p.i] != kNoClump && clump_of[p.i] == clump_of[p.j]) continue;  // one rigid body
    all.push_back({{p.i, ContactKind::BallBall, p.j}, p.image});
  }
}

// The candidate pairs within reach [m], sorted by key (ball-ball with their periodic image).
Candidates candidates(const BallStore& balls, const WallStore& walls, const PeriodicBox& box, double reach,
                      const std::vector<std::uint32_t>& clump_of) {
  Candidates all;
  add_pair_candidates(all, balls.position, balls, box, reach, clump_of);
  for (std::uint32_t w = 0; w < walls.size(); ++w)
    for (std::uint32_t i = 0; i < balls.size(); ++i) {
      const auto touch = wall_touch(walls.walls[w], balls.position[i], balls.radius[i]);
      if (touch && touch->gap <= reach) all.push_back({{i, ContactKind::BallWall, w}, kNoImage});
    }
  sort_by_key(all);
  return all;
}

// A candidate that is not a row yet: a new row with its assignment rule's model and parameters, or,
// if no rule matches, counted in `unassigned`.
void append_candidate(ContactStore& next, const ContactKey& key, ImageCode image, const BallStore& balls,
                      const WallStore& walls, const ModelTable& table, const NeighbourList::MapRow& map_row,
                      std::size_t& unassigned) {
  const std::uint64_t groups2 = key.kind == ContactKind::BallBall ? balls.groups[key.b] : walls.walls[key.b].groups;
  const int r = table.match(key.kind, balls.groups[key.a], groups2);
  if (r < 0) {
    ++unassigned;
    return;
  }
  const ModelRule& rule = table.rules[r];
  next.append_new(key, image, r, rule.model, rule.linear, rule.hill, Vec3{0, 0, 1});
  map_row(next, next.size() - 1);
}
}  // namespace

void NeighbourList::rebuild(ContactStore& contacts, BallStore& balls, const WallStore& walls, const ModelTable& table,
                            const PeriodicBox& box, double reach, std::int64_t step, const MapRow& map_row,
                            const std::vector<std::uint32_t>& clump_of) {
  check_finite(balls, step);  // (before the wrap: the message gives the position the run reached)
  wrap_positions(balls, box);
  const std::vector<std::pair<ContactKey, ImageCode>> all = candidates(balls, walls, box, reach, clump_of);
  // Merge with the existing rows (also sorted): history survives.
  ContactStore next;
  next.key.reserve(all.size());
  unassigned_pairs_ = 0;
  std::size_t o = 0;
  auto keep_old_if_needed = [&](std::size_t i) {
    if (contacts.exists[i] && contacts.model[i] == ModelKind::Hill && contacts.moisture[i] == Moisture::Wet) {
      next.append_row(contacts, i);
      const ContactKey& k = contacts.key[i];
      if (k.kind == ContactKind::BallBall)
        next.image.back() = nearest_image(balls.position[k.a], balls.position[k.b], box);
    }
  };
  for (const auto& [key, image] : all) {
    while (o < contacts.size() && contacts.key[o] < key) keep_old_if_needed(o++);
    if (o < contacts.size() && contacts.key[o] == key) {
      next.append_row(contacts, o++);
      next.image.back() = image;
      continue;
    }
    append_candidate(next, key, image, balls, walls, table, map_row, unassigned_pairs_);
  }
  while (o < contacts.size()) keep_old_if_needed(o++);
  contacts = std::move(next);
}

void NeighbourList::restore_rows(ContactStore& contacts, const BallStore& balls, const WallStore& walls,
                                 const ModelTable& table, const PeriodicBox& box, double reach,
                                 const MapRow& map_row, const std::vector<std::uint32_t>& clump_of) const {
  // The last rebuild's candidates are those at its positions (wrapped into the box then), found by
  // the same search; the saved rows (every contact, every wall row) stay as they were saved, and
  // the other ball-ball candidates become rows as the rebuild made them (a new row's columns are
  // those a contact forming on it resets: create_contact).
  Candidates pairs;
  add_pair_candidates(pairs, position_at_build_, balls, box, reach, clump_of);
  sort_by_key(pairs);
  ContactStore next;
  next.key.reserve(contacts.size() + pairs.size());
  std::size_t unassigned = 0;  // (the saved count is the rebuild's, walls included)
  std::size_t o = 0;
  for (const auto& [key, image] : pairs) {
    while (o < contacts.size() && contacts.key[o] < key) next.append_row(contacts, o++);
    if (o < contacts.size() && contacts.key[o] == key) {
      next.append_row(contacts, o++);
      continue;
    }
    append_candidate(next, key, image, balls, walls, table, map_row, unassigned);
  }
  while (o < contacts.size()) next.append_row(contacts, o++);
  contacts = std::move(next);
}

void NeighbourList::build_row_lists(const ContactStore& contacts, std::size_t n) {
  const std::size_t rows = contacts.size();
  if (rows > static_cast<std::size_t>(std::numeric_limits<std::uint32_t>::max()))
    throw RunError("too many neighbour pairs (" + std::to_string(rows) + ") for one process");
  first_rows_.assign(n + 1, 0);
  late_rows_start_.assign(n + 1, 0);
  wall_rows_start_.assign(n + 1, 0);
  wall_rows_.clear();
  row_span_ = 0;
  for (std::size_t c = 0; c < rows; ++c) {
    const ContactKey& k = contacts.key[c];
    if (k.kind == ContactKind::BallBall) {
      if (k.b > k.a) row_span_ = std::max<std::size_t>(row_span_, k.b - k.a);
      ++first_rows_[k.a + 1];
      ++late_rows_start_[k.b + 1];
    } else {
      wall_rows_.push_back(static_cast<std::uint32_t>(c));  // (sorted by ball: keys by kind, then a)
      ++wall_rows_start_[k.a + 1];
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    first_rows_[i + 1] += first_rows_[i];
    late_rows_start_[i + 1] += late_rows_start_[i];
    wall_rows_start_[i + 1] += wall_rows_start_[i];
  }
  late_rows_.assign(late_rows_start_[n], 0);
  std::vector<std::uint32_t> late_fill(late_rows_start_.begin(), late_rows_start_.end() - 1);
  for (std::size_t c = 0; c < rows; ++c) {
    const ContactKey& k = contacts.key[c];
    if (k.kind == ContactKind::BallBall) late_rows_[late_fill[k.b]++] = static_cast<std::uint32_t>(c);
  }
}

void NeighbourList::add_wall_motion(const Wall& w, double dt) {
  double reach = 0.0;  // the farthest a wall point is from the centre it spins about [m]
  if (w.shape == WallShape::Facet)
    for (const Vec3& v : w.vertex) reach = std::max(reach, norm(v - w.rotation_center));
  else if (w.shape == WallShape::Plane && norm2(w.spin) > 0.0)
    reach = std::numeric_limits<double>::infinity();
  if (norm2(w.spin) > 0.0) add_wall_travel(norm(w.spin) * dt * reach);
  add_wall_travel((norm(w.velocity) + std::abs(w.radial_velocity)) * dt);
}

}  // namespace hilldem
