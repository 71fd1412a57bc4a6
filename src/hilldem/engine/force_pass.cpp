#include "hilldem/engine/force_pass.hpp"

#include <omp.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <thread>

#include "hilldem/core/error.hpp"
#include "hilldem/engine/contact_mapping.hpp"
#include "hilldem/engine/model_dispatch.hpp"
#include "hilldem/models/contact_kinematics.hpp"
#include "hilldem/models/hill.hpp"
#include "hilldem/models/linear.hpp"
#include "hilldem/models/rrlinear.hpp"
#include "hilldem/motion/law_of_motion.hpp"

namespace hilldem {

void ForcePass::run(const PassWorld& world, const PassOptions& options) {
  w_ = world;
  o_ = options;
  const std::size_t rows = w_.contacts->size();
  const std::size_t n = w_.balls->size();
  LiveRows& live_rows = *w_.live;
  // Blocks of balls, each with its own rows (ball-ball rows are sorted by their first ball); each
  // row writes only its own columns. Each thread takes a range of balls of equal work (WorkSplit)
  // in blocks of balls_per_block from its start, and runs the blocks from the last down
  // (run_range). Every ball's force is summed in one order whatever the ranges: its ball-ball rows
  // in descending row order, then its wall rows (NeighbourList::first_rows, force_block,
  // collect_forces). So results depend neither on the blocks (ContactBatch::pad_lanes) nor on the
  // thread count. The first failing row is found by a min-reduction, so the outcome does not depend
  // on the thread count.
  std::size_t bad_row = rows;
  std::int64_t batched = 0;
  std::unique_ptr<std::atomic<bool>[]> crossing_done;  // per thread: its crossing list is final
  std::atomic<bool> late_share{false};
#pragma omp parallel reduction(min : bad_row) reduction(+ : batched) if (n > kParallelMin)
  {
    // ≈ 60 kB: on the heap, not the thread's stack. Default-initialised (make_unique would zero it on
    // every pass): every lane value a law or the scatter uses is written before it is read.
    std::unique_ptr<BlockScratch> scratch(new BlockScratch);
#pragma omp single
    {
      const auto threads = static_cast<std::size_t>(omp_get_num_threads());
      const bool live_split = live_rows.visited() && live_rows.covers(n);
      const std::uint32_t* row_first = live_split ? live_rows.first() : w_.neighbours->first_rows().data();
      const bool resplit =
          w_.split->prepare(threads, n, rows, *o_.thread_shares, row_first, w_.neighbours->wall_rows_start().data());
      crossing_.resize(threads);
      if (resplit || crossing_floor_.size() != threads) crossing_floor_.assign(threads, kFloorUnknown);
      crossing_done.reset(new std::atomic<bool>[threads]);
      for (std::size_t u = 0; u < threads; ++u) crossing_done[u].store(false, std::memory_order_relaxed);
    }
    run_range(static_cast<std::size_t>(omp_get_thread_num()), *scratch, crossing_done.get(), late_share, bad_row, batched);
  }
  if (late_share.load()) throw RunError("internal error: a crossing share after its list was final (force_pass)");
  batched_rows_ = batched;
  if (bad_row < rows) throw_bad_row(bad_row);
  collect_forces();
}

void ForcePass::rows_changed(std::size_t rows) {
  crossing_floor_.clear();
  share_moment_.assign(rows, Vec3{});
}

void ForcePass::run_range(std::size_t t, BlockScratch& scratch, std::atomic<bool>* crossing_done,
                          std::atomic<bool>& late_share, std::size_t& bad_row, std::int64_t& batched) {
  WorkSplit& split = *w_.split;
  // Thread t's range of balls (force_pass), its crossing shares announced to the threads above as
  // soon as they are final, then the end of its balls' sums.
  const std::size_t block = std::max<std::size_t>(1, o_.balls_per_block);
  const std::size_t first = split.begin(t), last = split.end(t);
  std::vector<CrossShare>& crossing = crossing_[t];
  crossing.clear();
  // One thread needs no timing: its share is the whole.
  const bool timed = omp_get_num_threads() > 1;
  const double busy_from = timed ? omp_get_wtime() : 0.0;
  // The lowest ball of the range with a row into a later range (made once per split: the rows do
  // not change until the next). Below it the thread adds no crossing share, and from there its list
  // is final and announced (crossing_done), long before its pass ends: the blocks run from the
  // last down, and the crossing rows are those of its top layer of balls: only its top row_span balls
  // (NeighbourList::row_span) can have one, and the last range has none.
  if (crossing_floor_[t] == kFloorUnknown) crossing_floor_[t] = crossing_floor(first, last);
  const std::size_t floor = crossing_floor_[t];
  bool announced = false;
  std::size_t announced_size = 0;
  auto announce = [&] {
    crossing_done[t].store(true, std::memory_order_release);
    announced = true;
    announced_size = crossing.size();
  };
  if (floor >= last) announce();
  if (last > first)
    for (std::size_t a = first + (last - first - 1) / block * block;; a -= block) {
      force_block(a, std::min(last, a + block), last, scratch, crossing, bad_row, batched);
      if (!announced && a <= floor) announce();
      if (a == first) break;
    }
  if (!announced) announce();
  // (A share added after the list was announced would be a wrong floor: another thread may have read
  // the list already. Never seen; checked, as it costs nothing.)
  if (crossing.size() != announced_size) late_share.store(true, std::memory_order_relaxed);
  // The end of the range's force sums, by the thread itself, in their order (force_pass): the
  // crossing shares into its balls from the ranges below, the last range's first (each list once
  // its thread announced it: no wait in practice), then its balls' wall rows in row order
  // (wall_block: each row's result depends on no other row, nor on the batch it falls into).
  for (std::size_t u = t; u-- > 0;) {
    for (int spin = 0; !crossing_done[u].load(std::memory_order_acquire); ++spin)
      if (spin > 1000) std::this_thread::yield();  // (more threads than cores: let the other run)
    add_crossing(crossing_[u], first, last);
  }
  const std::size_t k0 = w_.neighbours->wall_rows_start()[first], k1 = w_.neighbours->wall_rows_start()[last];
  if (k1 > k0) {
    wall_block(k0, k1, scratch, bad_row, batched);
    add_wall_rows(k0, k1);
  }
  if (timed) split.add_busy(t, omp_get_wtime() - busy_from);  // [s]
}

std::size_t ForcePass::crossing_floor(std::size_t first, std::size_t last) const {
  const NeighbourList& neighbours = *w_.neighbours;
  std::size_t floor = last;
  if (last < w_.balls->size()) {
    const std::vector<std::uint32_t>& rows_of = neighbours.first_rows();
    for (std::size_t a = last - std::min(last - first, neighbours.row_span()); a < last && floor == last; ++a)
      if (rows_of[a + 1] > rows_of[a] && w_.contacts->key[rows_of[a + 1] - 1].b >= last) floor = a;
  }
  return floor;
}

void ForcePass::throw_bad_row(std::size_t bad_row) const {
  const ContactStore& contacts = *w_.contacts;
  const BallStore& balls = *w_.balls;
  // (The gap column is written for a row whose force is not finite: store_row.)
  const ContactKey& key = contacts.key[bad_row];
  std::ostringstream msg;
  msg << "non-finite contact force at step " << o_.step + 1 << " between ball " << balls.id[key.a] << " and "
      << (key.kind == ContactKind::BallBall ? "ball " + std::to_string(balls.id[key.b])
                                            : "wall '" + w_.walls->walls[key.b].name + "'")
      << " (gap " << contacts.gap[bad_row] << " m): the run is unstable; reduce the time step";
  throw RunError(msg.str());
}

void ForcePass::add_crossing(const std::vector<CrossShare>& list, std::size_t first, std::size_t last) {
  const bool want = want_stiffness();
  const BallStore& balls = *w_.balls;
  StiffnessSums& stiffness = *w_.stiffness;
  motion::ContactSums* __restrict sums = w_.kin->sums();
  for (const CrossShare& s : list)
    if (s.b >= first && s.b < last) {
      sums[s.b].force += motion::load(s.force);
      sums[s.b].moment += motion::load(s.moment);
      if (want) add_stiffness(s.k_tran, s.k_shear, balls.radius[s.b], s.gap, stiffness.tran[s.b], stiffness.rot[s.b]);
    }
}

void ForcePass::add_wall_rows(std::size_t k0, std::size_t k1) {
  const bool want = want_stiffness();
  const ContactStore& contacts = *w_.contacts;
  const BallStore& balls = *w_.balls;
  StiffnessSums& stiffness = *w_.stiffness;
  motion::ContactSums* __restrict sums = w_.kin->sums();
  for (std::size_t k = k0; k < k1; ++k) {
    const std::uint32_t c = w_.neighbours->wall_rows()[k];
    const std::size_t a = contacts.key[c].a;
    sums[a].force -= motion::load(contacts.force[c]);
    sums[a].moment += motion::load(share_moment_[c]);
    if (want) add_row_stiffness(contacts, c, balls.radius[a], stiffness.tran[a], stiffness.rot[a]);
  }
}

WallShare wall_row_share(const Wall& w, const ContactStore& contacts, std::size_t c, const Vec3& position, double radius) {
  const Vec3 point = position + contacts.normal[c] * (radius + 0.5 * contacts.gap[c]);
  return {contacts.force[c], cross(point - w.rotation_center, contacts.force[c]) + contacts.moment_state[c],  // (+ M_c: rrlinear)
          dot(contacts.force[c], contacts.normal[c]), wall_normal_stiffness(contacts, c)};
}

void add_wall_share(Wall& w, const WallShare& s) {
  w.force += s.force;
  w.moment += s.moment;
  w.normal_force += s.normal_force;
  w.normal_stiffness += s.normal_stiffness;
  ++w.active_contacts;
}

void add_wall_row(Wall& w, const ContactStore& contacts, std::size_t c, const Vec3& position, double radius) {
  add_wall_share(w, wall_row_share(w, contacts, c, position, radius));
}

void clear_wall_sums(Wall& w) {
  w.force = w.moment = Vec3{};
  w.normal_force = w.normal_stiffness = 0.0;
  w.active_contacts = 0;
}

void ForcePass::collect_forces() {
  const ContactStore& contacts = *w_.contacts;
  const BallStore& balls = *w_.balls;
  BallRecords& ball_kin = *w_.kin;
  // The walls' sums, each wall row in row order (the balls' sums were ended by the pass's threads).
  // Rows that are not active contacts hold zero force and moment.
  for (Wall& w : w_.walls->walls) clear_wall_sums(w);
  // Each wall row into its wall's sums, in row order.
  for (std::uint32_t c : w_.neighbours->wall_rows()) {
    const ContactKey& k = contacts.key[c];
    if (!contacts.active[c]) continue;
    add_wall_row(w_.walls->walls[k.b], contacts, c, ball_kin[k.a].position, balls.radius[k.a]);
  }
  w_.stiffness->ready = want_stiffness();
  // The BallStore's columns of the sums on the passes someone may read them after (as the reported
  // contact columns); the law of motion reads the sums themselves.
  ball_kin.end_sums();
  if (o_.write_results) ball_kin.sync_sum_columns(*w_.balls);
}

// One row, any model and kind (the general path).
RowShare ForcePass::force_row(std::size_t c, double dt) {
  ContactStore& contacts = *w_.contacts;
  const BallStore& balls = *w_.balls;
  const WallStore& walls = *w_.walls;
  const SimulationSettings& settings = *w_.settings;
  const double proximity = settings.proximity;
  const bool want_stiffness = settings.auto_timestep || settings.density_scaling;
  const PeriodicBox& box = settings.box;
  // The balls' state from their records (current in the force pass; the columns may lag behind).
  const BallKin* rec = w_.kin->data();
  const double* rad = balls.radius.data();
  const ContactKey key = contacts.key[c];
  const std::size_t a = key.a;
  const bool ball2 = key.kind == ContactKind::BallBall;
  const Vec3 x1 = rec[a].position;
  const double r1 = rad[a];

  // Geometry (spec §1.1). Neighbour pairs that are not contacts are rejected before any sqrt.
  using lanes::v3;
  Vec3 normal;
  double gap;
  if (ball2) {
    Vec3 x2 = rec[key.b].position;
    if (contacts.image[c] != kNoImage) x2 += image_shift(contacts.image[c], box);
    const Vec3 d = x2 - x1;
    if (!contacts.exists[c]) {
      const double reach = r1 + rad[key.b] + proximity;
      if (norm2(d) > reach * reach) return {};  // a neighbour pair, not a contact
    }
    const PairGeometry<double> g = ball_pair_geometry(v3(d), r1, rad[key.b], v3(contacts.normal[c]));
    normal = lanes::vec3(g.normal);
    gap = g.gap;
  } else {
    const auto touch = wall_touch(walls.walls[key.b], x1, r1);
    if (!touch && !contacts.exists[c]) return {};
    normal = touch ? touch->normal : contacts.normal[c];
    gap = touch ? touch->gap : std::numeric_limits<double>::infinity();
    if (!contacts.exists[c] && gap > proximity) return {};
  }
  if (!contacts.exists[c]) create_contact(*w_.table, balls, *w_.hill_sets, contacts, c, normal);  // created by proximity

  // Relative velocity of the material points at x_c (spec §1.2); a wall is body 2 with the arm 0
  // (r2 = −g/2) and its surface velocity at x_c = x1 + (R1 + g/2) n̂.
  RowOutcome out;
  out.normal = normal;
  out.gap = gap;
  out.r1 = r1;
  out.r2 = ball2 ? rad[key.b] : r1;  // (a wall row's second share is its ball's: wall_block)
  const double r2 = ball2 ? rad[key.b] : -0.5 * gap;
  Vec3 v2, spin2;
  if (ball2) {
    v2 = rec[key.b].velocity;
    spin2 = rec[key.b].spin;
  } else {
    v2 = wall_point_velocity(walls.walls[key.b], x1 + normal * (r1 + 0.5 * gap));
    spin2 = walls.walls[key.b].spin;
  }
  const Vec3 rel = lanes::vec3(contact_velocity(v3(normal), gap, r1, r2, v3(rec[a].velocity), v3(rec[a].spin),
                                                v3(v2), v3(spin2)));
  const ContactKinematics kin{normal, gap, rel, dt};
  const double mean_spin = 0.5 * dot(rec[a].spin + spin2, normal);  // ½(ω1 + ω2)·n̂ [rad/s] (§1.3)
  const Vec3 carried = carry_into_plane(contacts.shear_state[c], contacts.normal[c], normal, mean_spin, dt);
  out.moisture = contacts.moisture[c];
  run_row_law(contacts, c,
              RowLawInput{kin, carried, mean_spin, spin2 - rec[a].spin, r1, ball2 ? rad[key.b] : 0.0, !ball2,
                          want_stiffness},
              out);
  if (!out.active) out.force = Vec3{};
  // Accumulated shear displacement (reported, not used by the laws): rotated with the plane (and
  // cleared again by store_row if the contact is deleted).
  if (settings.track_shear_displacement)
    contacts.shear_disp[c] =
        out.active ? lanes::vec3(rotate_with_plane(v3(contacts.shear_disp[c]), v3(contacts.normal[c]), v3(normal), mean_spin, dt)) +
                         kin.shear_rate() * dt
                   : Vec3{};
  RowShare share;
  store_row(contacts, proximity, c, out, want_stiffness, true, share);
  return share;
}

void ForcePass::wall_block(std::size_t k0, std::size_t k1, BlockScratch& scratch, std::size_t& bad_row,
                           std::int64_t& batched_count) {
  ContactStore& contacts = *w_.contacts;
  const BallStore& balls = *w_.balls;
  const WallStore& walls = *w_.walls;
  const SimulationSettings& settings = *w_.settings;
  const BallRecords& ball_kin = *w_.kin;
  const double dt = o_.dt;
  // Existing linear wall contacts through a linear batch: one contact's law at a time is a chain of
  // dependent square roots and divisions (engine/contact_batch.hpp).
  const bool want_stiffness = settings.auto_timestep || settings.density_scaling;
  const bool batched = !settings.track_shear_displacement;
  using F = ContactBatch;
  ContactBatch& batch = scratch.linear;
  batch.clear();
  auto done = [&](std::size_t c, const RowShare& share) {
    share_moment_[c] = share.moment2;
    if (!share.ok) bad_row = std::min(bad_row, c);
  };
  auto flush = [&] {
    run_linear_lanes(batch, LaneStep{dt, want_stiffness, settings.proximity, /*geometry_given=*/true});
    batched_count += static_cast<std::int64_t>(batch.size());
    const double* quick = batch.col(F::kQuick);
    for (std::size_t lane = 0; lane < batch.size(); ++lane) {
      const std::size_t c = batch.row(lane);
      if (quick[lane] == 0.0) {
        RowShare share;
        store_row(contacts, settings.proximity, c, lane_outcome(contacts, batch, lane, /*wall_row=*/true), want_stiffness, true,
                  share);
        done(c, share);
        continue;
      }
      store_kept_lane(contacts, c, batch, lane, want_stiffness, true);
      share_moment_[c] = batch.get3(F::kMax, lane);  // the ball's arm (the wall's, kMbx.., is 0)
    }
    batch.clear();
  };
  for (std::size_t k = k0; k < k1; ++k) {
    const std::size_t c = w_.neighbours->wall_rows()[k];
    if (!batched || !contacts.exists[c] || batch_of(contacts.model[c]) != BatchKind::Linear) {
      done(c, force_row(c, dt));
      continue;
    }
    const std::size_t a = contacts.key[c].a;
    const Wall& w = walls.walls[contacts.key[c].b];
    const Vec3 x1 = ball_kin[a].position;  // (the records: current in the force pass)
    const double r1 = balls.radius[a];
    const auto touch = wall_touch(w, x1, r1);
    if (!touch) {  // (the contact is deleted: force_row)
      done(c, force_row(c, dt));
      continue;
    }
    if (batch.full()) flush();
    const std::size_t lane = batch.add(static_cast<std::uint32_t>(c));
    const double arm1 = r1 + 0.5 * touch->gap;
    batch.put3(F::kNx, lane, touch->normal);
    batch.col(F::kGap)[lane] = touch->gap;
    batch.col(F::kR1)[lane] = r1;
    batch.col(F::kR2)[lane] = -0.5 * touch->gap;  // the wall's arm R2 + g/2 is then exactly 0
    batch.put3(F::kVax, lane, ball_kin[a].velocity);
    batch.put3(F::kVbx, lane, wall_point_velocity(w, x1 + touch->normal * arm1));
    batch.put3(F::kWax, lane, ball_kin[a].spin);
    batch.put3(F::kWbx, lane, w.spin);
    batch.put3(F::kNox, lane, contacts.normal[c]);
    batch.put3(F::kSx, lane, contacts.shear_state[c]);
    batch.col(F::kIr)[lane] = contacts.linear_map[c].kn;
    batch.col(F::kIm)[lane] = contacts.linear_map[c].ks;
    batch.col(F::kFric)[lane] = contacts.linear_params[c].fric;
  }
  if (batch.size() > 0) flush();
}

}  // namespace hilldem
