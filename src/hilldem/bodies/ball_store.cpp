#include "hilldem/bodies/ball_store.hpp"

#include <algorithm>
#include <numbers>
#include <numeric>

#include "hilldem/core/error.hpp"

namespace hilldem {

std::size_t BallStore::add(const BallInit& b) {
  id.push_back(b.id);
  radius.push_back(b.radius);
  density.push_back(b.density);
  mass.push_back(0.0);
  inertia.push_back(0.0);
  young_mod.push_back(b.young_mod);
  pois_ratio.push_back(b.pois_ratio);
  groups.push_back(b.groups);
  fixity.push_back(b.fixity);
  position.push_back(b.position);
  velocity.push_back(b.velocity);
  spin.push_back(b.spin);
  contact_force.emplace_back();
  contact_moment.emplace_back();
  applied_force.emplace_back();
  applied_moment.emplace_back();
  const std::size_t i = size() - 1;
  update_mass(i);
  index_of_[b.id] = static_cast<std::uint32_t>(i);
  return i;
}

long BallStore::find(std::int64_t user_id) const {
  const auto it = index_of_.find(user_id);
  return it == index_of_.end() ? -1 : static_cast<long>(it->second);
}

void BallStore::permute(const std::vector<std::uint32_t>& order) {
  for_each_column([&](auto& column) {
    auto old = column;
    for (std::size_t k = 0; k < order.size(); ++k) column[k] = old[order[k]];
  });
  index_of_.clear();
  for (std::size_t i = 0; i < id.size(); ++i) index_of_[id[i]] = static_cast<std::uint32_t>(i);
}

void BallStore::update_mass(std::size_t i) {
  const double r = radius[i];
  mass[i] = 4.0 / 3.0 * std::numbers::pi * r * r * r * density[i];
  inertia[i] = 0.4 * mass[i] * r * r;  // solid sphere
}

std::uint64_t GroupNames::bit(const std::string& name) {
  if (const auto b = find(name)) return b;
  if (names_.size() >= 64)
    throw InputError("too many group names (at most 64): cannot add group '" + name + "'");
  names_.push_back(name);
  return std::uint64_t{1} << (names_.size() - 1);
}

std::uint64_t GroupNames::find(const std::string& name) const {
  for (std::size_t k = 0; k < names_.size(); ++k)
    if (names_[k] == name) return std::uint64_t{1} << k;
  return 0;
}

std::string GroupNames::describe(std::uint64_t mask) const {
  std::string out;
  for (std::size_t k = 0; k < names_.size(); ++k)
    if (mask & (std::uint64_t{1} << k)) out += (out.empty() ? "" : ",") + names_[k];
  return out.empty() ? "-" : out;
}

std::vector<std::string> group_names(const GroupNames& g) {
  std::vector<std::string> names;
  for (int k = 0; k < 64; ++k) {
    const std::uint64_t bit = std::uint64_t{1} << k;
    const std::string name = g.describe(bit);
    if (g.find(name) != bit) break;
    names.push_back(name);
  }
  return names;
}

std::vector<std::uint32_t> spatial_order(const BallStore& balls) {
  const std::size_t n = balls.size();
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  if (n < 2) return order;
  Vec3 lo = balls.position[0], hi = lo;
  for (const Vec3& x : balls.position)
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], x[d]), hi[d] = std::max(hi[d], x[d]);
  const double cell = std::max(2.0 * std::accumulate(balls.radius.begin(), balls.radius.end(), 0.0) / n, 1e-12);
  auto cell_index = [&](const Vec3& x) {
    const auto c = [&](int d) { return static_cast<std::uint64_t>((x[d] - lo[d]) / cell); };
    const std::uint64_t nx = c(0) + 1;
    const std::uint64_t ny = static_cast<std::uint64_t>((hi.y - lo.y) / cell) + 1;
    const std::uint64_t mx = static_cast<std::uint64_t>((hi.x - lo.x) / cell) + 1;
    return (c(2) * ny + c(1)) * mx + (nx - 1);
  };
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t p, std::uint32_t q) {
    return cell_index(balls.position[p]) < cell_index(balls.position[q]);
  });
  return order;
}

}  // namespace hilldem
