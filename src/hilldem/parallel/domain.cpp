#include "hilldem/parallel/domain.hpp"

#include <algorithm>
#include <cstring>
#include <iterator>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "hilldem/core/error.hpp"
#include "hilldem/engine/force_pass.hpp"

namespace hilldem::parallel {

namespace {

// Bytes of trivially copyable values, in the order put.
struct Buffer {
  std::vector<char> bytes;
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const std::size_t at = bytes.size();
    bytes.resize(at + sizeof(T));
    std::memcpy(bytes.data() + at, &v, sizeof(T));
  }
};

struct Reader {
  const char* p;
  const char* end;
  template <class T>
  T get() {
    if (p + sizeof(T) > end) throw std::runtime_error("domain exchange: a message ends early");
    T v;
    std::memcpy(&v, p, sizeof(T));
    p += sizeof(T);
    return v;
  }
};

// Ball i of `balls` (every column), with its global index and owner.
void put_ball(Buffer& out, BallStore& balls, std::size_t i, std::uint32_t global, int owner) {
  out.put(global);
  out.put(owner);
  balls.for_each_column([&](auto& col) { out.put(col[i]); });
}

void get_ball(Reader& in, BallStore& balls, std::vector<std::uint32_t>& global, std::vector<int>& owner) {
  global.push_back(in.get<std::uint32_t>());
  owner.push_back(in.get<int>());
  balls.for_each_column([&](auto& col) { col.push_back(in.get<typename std::decay_t<decltype(col)>::value_type>()); });
}

// Row c of `rows` (every column), its key `key` (in global indices).
void put_row(Buffer& out, ContactStore& rows, std::size_t c, const ContactKey& key) {
  ContactStore::zip_columns(rows, rows, [&](auto& col, auto&) {
    using T = typename std::decay_t<decltype(col)>::value_type;
    if constexpr (std::is_same_v<T, ContactKey>)
      out.put(key);
    else
      out.put(col[c]);
  });
}

void get_row(Reader& in, ContactStore& rows) {
  ContactStore::zip_columns(rows, rows, [&](auto& col, auto&) { col.push_back(in.get<typename std::decay_t<decltype(col)>::value_type>()); });
}

// Every rank's buffer for every other, exchanged (collective); the bytes from rank q are
// received[from[q] .. from[q + 1]].
struct Received {
  std::vector<char> bytes;
  std::vector<int> from;
};

Received all_to_all(MPI_Comm comm, const std::vector<Buffer>& out, std::uint64_t& sent) {
  const int size = static_cast<int>(out.size());
  std::vector<int> send_counts(size), recv_counts(size), send_at(size + 1, 0);
  for (int q = 0; q < size; ++q) {
    if (out[q].bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
      throw std::runtime_error("domain exchange: more than 2 GiB for one rank");
    send_counts[q] = static_cast<int>(out[q].bytes.size());
    send_at[q + 1] = send_at[q] + send_counts[q];
  }
  std::vector<char> send(static_cast<std::size_t>(send_at[size]));
  for (int q = 0; q < size; ++q) std::copy(out[q].bytes.begin(), out[q].bytes.end(), send.begin() + send_at[q]);
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm);
  Received r;
  r.from.assign(size + 1, 0);
  for (int q = 0; q < size; ++q) r.from[q + 1] = r.from[q] + recv_counts[q];
  r.bytes.resize(static_cast<std::size_t>(r.from[size]));
  MPI_Alltoallv(send.data(), send_counts.data(), send_at.data(), MPI_BYTE, r.bytes.data(), recv_counts.data(),
                r.from.data(), MPI_BYTE, comm);
  int self = 0;
  MPI_Comm_rank(comm, &self);
  sent += static_cast<std::uint64_t>(send_at[size] - send_counts[self]);
  return r;
}

// The local index of global index g among the sorted `global`.
std::uint32_t local_of(const std::vector<std::uint32_t>& global, std::uint32_t g) {
  const auto it = std::lower_bound(global.begin(), global.end(), g);
  if (it == global.end() || *it != g) throw std::runtime_error("domain exchange: the ball of a row or a pebble did not arrive");
  return static_cast<std::uint32_t>(it - global.begin());
}

// Balls in arrival order made into a store sorted by global index.
void sort_balls(BallStore& balls, std::vector<std::uint32_t>& global, std::vector<int>& owner) {
  std::vector<std::uint32_t> order(global.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return global[x] < global[y]; });
  balls.permute(order);  // (rebuilds the user-id index too)
  std::vector<std::uint32_t> g(global.size());
  std::vector<int> o(owner.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    g[k] = global[order[k]];
    o[k] = owner[order[k]];
  }
  for (std::size_t k = 1; k < g.size(); ++k)
    if (g[k] == g[k - 1]) throw std::runtime_error("domain exchange: a ball arrived twice");
  global = std::move(g);
  owner = std::move(o);
}

// Rows in arrival order (keys in global indices) made into a store sorted by key, with keys in the
// local indices of `global` (or left global: gather).
ContactStore sort_rows(ContactStore& rows, const std::vector<std::uint32_t>* global) {
  if (global)
    for (ContactKey& k : rows.key) {
      k.a = local_of(*global, k.a);
      if (k.kind == ContactKind::BallBall) k.b = local_of(*global, k.b);
    }
  std::vector<std::size_t> order(rows.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return rows.key[x] < rows.key[y]; });
  ContactStore sorted;
  for (std::size_t c : order) sorted.append_row(rows, c);
  for (std::size_t c = 1; c < sorted.size(); ++c)
    if (!(sorted.key[c - 1] < sorted.key[c])) throw std::runtime_error("domain exchange: a row arrived twice");
  return sorted;
}

// Whether `in` is at a marker (a global index of UINT32_MAX, which no ball or clump has), read past it if so.
bool at_marker(Reader& in) {
  Reader peek = in;
  if (peek.get<std::uint32_t>() != UINT32_MAX) return false;
  in = peek;
  return true;
}

// Clumps in arrival order: their columns, and their pebbles', each pebble's `clump` the arrival
// index of its clump and its `ball` its ball's global index.
struct ClumpArrivals {
  ClumpBodies bodies;
  std::vector<std::uint32_t> global, pebble_global;
  std::vector<int> owner;
};

// Clump j of `c` (every clump column) with its global index and owner, then its pebbles `list`
// (local pebble indices, in pebble order), each with its global index, its centre in the clump's
// frame, its radius and its ball's global index.
void put_clump(Buffer& out, ClumpBodies& c, std::size_t j, std::uint32_t global, int owner,
               const std::vector<std::uint32_t>& list, const std::vector<std::uint32_t>& pebble_global,
               const std::vector<std::uint32_t>& ball_global) {
  out.put(global);
  out.put(owner);
  c.for_each_clump_column([&](auto& col) { out.put(col[j]); });
  out.put(static_cast<std::uint32_t>(list.size()));
  for (std::uint32_t k : list) {
    out.put(pebble_global[k]);
    out.put(c.pebbles.body_position[k]);
    out.put(c.pebbles.radius[k]);
    out.put(ball_global[c.ball[k]]);
  }
}

void get_clump(Reader& in, ClumpArrivals& a) {
  a.global.push_back(in.get<std::uint32_t>());
  a.owner.push_back(in.get<int>());
  a.bodies.for_each_clump_column([&](auto& col) { col.push_back(in.get<typename std::decay_t<decltype(col)>::value_type>()); });
  const auto j = static_cast<std::uint32_t>(a.global.size() - 1);
  const auto n = in.get<std::uint32_t>();
  ClumpBodies& c = a.bodies;
  for (std::uint32_t k = 0; k < n; ++k) {
    a.pebble_global.push_back(in.get<std::uint32_t>());
    c.pebbles.clump.push_back(j);
    c.pebbles.body_position.push_back(in.get<Vec3>());
    c.pebbles.radius.push_back(in.get<double>());
    c.ball.push_back(in.get<std::uint32_t>());
  }
}

// Each pebble of every local clump, in pebble order, by clump.
std::vector<std::vector<std::uint32_t>> pebbles_by_clump(const ClumpBodies& c) {
  std::vector<std::vector<std::uint32_t>> of(c.size());
  for (std::size_t k = 0; k < c.pebbles.size(); ++k) of[c.pebbles.clump[k]].push_back(static_cast<std::uint32_t>(k));
  return of;
}

template <class T>
void permute_column(std::vector<T>& col, const std::vector<std::uint32_t>& order) {
  std::vector<T> from = std::move(col);
  col.resize(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) col[k] = from[order[k]];
}

std::vector<std::uint32_t> ascending(const std::vector<std::uint32_t>& key, const char* what) {
  std::vector<std::uint32_t> order(key.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return key[x] < key[y]; });
  for (std::size_t k = 1; k < order.size(); ++k)
    if (key[order[k]] == key[order[k - 1]]) throw std::runtime_error(std::string("domain exchange: ") + what + " arrived twice");
  return order;
}

// Arrived clumps made into the clumps of a Simulation: clumps by global index, pebbles by global
// index (the whole run's orders), each pebble's ball row its ball's local index among the sorted
// `ball_global` (or left global: gather, where the whole run's rows are the global indices).
ClumpBodies sort_clumps(ClumpArrivals& a, const std::vector<std::uint32_t>* ball_global) {
  ClumpBodies& c = a.bodies;
  const std::vector<std::uint32_t> order = ascending(a.global, "a clump");
  c.for_each_clump_column([&](auto& col) { permute_column(col, order); });
  permute_column(a.global, order);
  permute_column(a.owner, order);
  std::vector<std::uint32_t> new_index(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) new_index[order[k]] = static_cast<std::uint32_t>(k);
  const std::vector<std::uint32_t> pebble_order = ascending(a.pebble_global, "a pebble");
  permute_column(c.pebbles.clump, pebble_order);
  permute_column(c.pebbles.body_position, pebble_order);
  permute_column(c.pebbles.radius, pebble_order);
  permute_column(c.ball, pebble_order);
  permute_column(a.pebble_global, pebble_order);
  for (std::uint32_t& j : c.pebbles.clump) j = new_index[j];
  if (ball_global)
    for (std::uint32_t& b : c.ball) b = local_of(*ball_global, b);
  return std::move(c);
}

}  // namespace

Domain::Domain(MPI_Comm comm, Simulation& sim, double min_reach) : comm_(comm), sim_(&sim), min_reach_(min_reach) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  // The cycle state of a run that has cycled (a restored checkpoint), kept below.
  CycleState cycled = sim.cycle_state();
  const bool keep_cycle = !cycled.rebuild_needed && cycled.position_at_build.size() == sim.balls.size();
  // The skin from the radii (settings.skin 0) would be each rank's own mean: the whole run's instead.
  skin_given_ = sim.settings.skin;
  if (sim.settings.skin <= 0.0) sim.settings.skin = sim.skin();
  rcb_ = std::make_unique<RcbPartition>(comm_);
  // The first cut, from every rank's share of the whole run's balls (each rank holds them all).
  {
    std::vector<Vec3> points;
    std::vector<double> weights;
    std::vector<double> rows(sim.balls.size(), 0.0);
    for (const ContactKey& k : sim.contacts.key) {
      rows[k.a] += 1.0;
      if (k.kind == ContactKind::BallBall) rows[k.b] += 1.0;
    }
    for (std::size_t i = static_cast<std::size_t>(rank_); i < sim.balls.size(); i += static_cast<std::size_t>(size_)) {
      points.push_back(sim.settings.box.wrapped(sim.balls.position[i]));
      weights.push_back(1.0 + rows[i]);
    }
    rcb_->cut(points, weights);
    ++bytes_.repartitions;
  }
  set_width(sim);
  // This rank's balls and clumps (owned or ghosts) and the rows between its balls, in the whole
  // run's order (through the messages' format, as if the whole run had sent them).
  std::vector<std::vector<int>> ball_where, clump_where;
  places(sim, ball_where, clump_where);
  BallStore balls;
  ContactStore rows;
  std::vector<bool> here(sim.balls.size(), false);
  Buffer b;
  for (std::size_t i = 0; i < sim.balls.size(); ++i) {
    const std::vector<int>& w = ball_where[i];
    if (std::find(w.begin(), w.end(), rank_) == w.end()) continue;
    here[i] = true;
    put_ball(b, sim.balls, i, static_cast<std::uint32_t>(i), w.front());
  }
  std::vector<std::uint32_t> identity(std::max(sim.balls.size(), sim.clumps.pebbles.size()));
  std::iota(identity.begin(), identity.end(), 0u);
  const std::vector<std::vector<std::uint32_t>> pebbles_of = pebbles_by_clump(sim.clumps);
  Buffer cb;
  for (std::size_t j = 0; j < sim.clumps.size(); ++j) {
    const std::vector<int>& w = clump_where[j];
    if (std::find(w.begin(), w.end(), rank_) == w.end()) continue;
    put_clump(cb, sim.clumps, j, static_cast<std::uint32_t>(j), w.front(), pebbles_of[j], identity, identity);
  }
  for (std::size_t c = 0; c < sim.contacts.size(); ++c) {
    const ContactKey& k = sim.contacts.key[c];
    if (!here[k.a] || (k.kind == ContactKind::BallBall && !here[k.b])) continue;
    Buffer rb;
    put_row(rb, sim.contacts, c, k);
    Reader in{rb.bytes.data(), rb.bytes.data() + rb.bytes.size()};
    get_row(in, rows);
  }
  for (Reader in{b.bytes.data(), b.bytes.data() + b.bytes.size()}; in.p < in.end;) get_ball(in, balls, global_, owner_);
  ClumpArrivals clumps;
  for (Reader in{cb.bytes.data(), cb.bytes.data() + cb.bytes.size()}; in.p < in.end;) get_clump(in, clumps);
  sort_balls(balls, global_, owner_);  // (in order already: this makes the user-id index)
  sim.contacts = sort_rows(rows, &global_);
  sim.balls = std::move(balls);
  sim.clumps = sort_clumps(clumps, &global_);
  clump_global_ = std::move(clumps.global);
  clump_owner_ = std::move(clumps.owner);
  pebble_global_ = std::move(clumps.pebble_global);
  make_lists(sim);
  sim.domain = this;  // (unless kept below, the list no longer fits the balls: the next force pass detects afresh)
  if (keep_cycle) {
    // The rows here are every row of the owned balls (all of a ball's rows were between balls within
    // the ghost width), so the local list is complete for them, and the next rebuild comes when some
    // ball, on some rank, has travelled half the skin since the whole run's last one.
    std::vector<Vec3> at(global_.size());
    for (std::size_t i = 0; i < global_.size(); ++i) at[i] = cycled.position_at_build[global_[i]];
    cycled.position_at_build = std::move(at);
    cycled.rows_complete = true;
    sim.restore_cycle_state(std::move(cycled));
  }
}

Domain::~Domain() = default;

std::size_t Domain::owned() const {
  return static_cast<std::size_t>(std::count(owner_.begin(), owner_.end(), rank_));
}

std::size_t Domain::owned_clumps() const {
  return static_cast<std::size_t>(std::count(clump_owner_.begin(), clump_owner_.end(), rank_));
}

std::int64_t Domain::local_of(std::uint32_t global) const {
  const auto it = std::lower_bound(global_.begin(), global_.end(), global);
  return it != global_.end() && *it == global ? it - global_.begin() : -1;
}

void Domain::set_width(const Simulation& sim) {
  // The largest radius, the largest gap [m] of an existing ball-ball row (wet contacts outlive the
  // reach: the rebuild's merge keeps them, spec §2.7, and the owner of a row's first ball must hold
  // its second to go on computing it), and the largest pebble offset from its centre of mass.
  double r[3] = {0.0, std::max(sim.settings.proximity, min_reach_), 0.0};
  for (double x : sim.balls.radius) r[0] = std::max(r[0], x);
  for (std::size_t c = 0; c < sim.contacts.size(); ++c)
    if (sim.contacts.exists[c] && sim.contacts.key[c].kind == ContactKind::BallBall) {
      const ContactGeometry g = sim.geometry(c);
      if (g.valid) r[1] = std::max(r[1], g.gap);
    }
  for (const Vec3& p : sim.clumps.pebbles.body_position) r[2] = std::max(r[2], norm(p));
  MPI_Allreduce(MPI_IN_PLACE, r, 3, MPI_DOUBLE, MPI_MAX, comm_);
  // A ball owned here has its partners within reach + skin + its radius and theirs; a pebble of a
  // clump owned here lies up to the extent outside the sub-domain.
  extent_ = r[2];
  width_ = r[1] + sim.skin() + 2.0 * r[0] + extent_;
}

void Domain::ranks_of(const Vec3& x, double width, std::vector<int>& out) const {
  const Vec3 w = sim_->settings.box.wrapped(x);
  const int owner = rcb_->owner(w);
  out.push_back(owner);
  rcb_->near(w, width, sim_->settings.box, owner, out);
}

void Domain::places(const Simulation& sim, std::vector<std::vector<int>>& balls,
                    std::vector<std::vector<int>>& clumps) const {
  const std::size_t n = sim.balls.size();
  clumps.assign(sim.clumps.size(), {});
  for (std::size_t j = 0; j < sim.clumps.size(); ++j) ranks_of(sim.clumps.state.position[j], width_ + extent_, clumps[j]);
  const std::vector<std::uint32_t> clump_of = sim.clumps.clump_of_balls(n);
  balls.assign(n, {});
  for (std::size_t i = 0; i < n; ++i) {
    if (!clump_of.empty() && clump_of[i] != kNoClump)
      balls[i] = clumps[clump_of[i]];  // (whole: a pebble goes where its clump goes)
    else
      ranks_of(sim.balls.position[i], width_, balls[i]);
  }
}

void Domain::make_lists(const Simulation& sim) {
  std::vector<std::vector<int>> ball_where, clump_where;
  places(sim, ball_where, clump_where);
  // (A pebble's motion goes as its clump's state: not in the balls' lists.)
  const std::vector<std::uint32_t> clump_of = sim.clumps.clump_of_balls(sim.balls.size());
  auto lists = [&](const std::vector<int>& owner, const std::vector<std::vector<int>>& where, const std::vector<std::uint32_t>& skip,
                   std::vector<std::vector<std::uint32_t>>& send, std::vector<std::vector<std::uint32_t>>& recv) {
    send.assign(static_cast<std::size_t>(size_), {});
    recv.assign(static_cast<std::size_t>(size_), {});
    for (std::size_t i = 0; i < owner.size(); ++i) {
      if (!skip.empty() && skip[i] != kNoClump) continue;
      if (owner[i] != rank_) {
        recv[static_cast<std::size_t>(owner[i])].push_back(static_cast<std::uint32_t>(i));
        continue;
      }
      for (std::size_t k = 1; k < where[i].size(); ++k) send[static_cast<std::size_t>(where[i][k])].push_back(static_cast<std::uint32_t>(i));
    }
  };
  lists(owner_, ball_where, clump_of, send_, recv_);
  lists(clump_owner_, clump_where, {}, clump_send_, clump_recv_);
  pebbles_of_ = pebbles_by_clump(sim.clumps);
}

void Domain::after_motion(Simulation& sim) {
  // Position, velocity and spin: what the force pass and the next motion read of a ball that can
  // change within a step (9 doubles a ghost); then a ghost clump's state (16 doubles: centre of mass,
  // velocity, orientation, spin, body-frame momentum), from which its pebbles are placed here as
  // its owner placed them: every copy of a clump and of its pebbles is its owner's, bitwise.
  constexpr int kDoubles = 9, kClumpDoubles = 16;
  ClumpState& cs = sim.clumps.state;
  std::vector<std::vector<double>> out(static_cast<std::size_t>(size_)), in(static_cast<std::size_t>(size_));
  std::vector<MPI_Request> requests;
  for (int q = 0; q < size_; ++q) {
    const std::size_t count = recv_[static_cast<std::size_t>(q)].size() * kDoubles +
                              clump_recv_[static_cast<std::size_t>(q)].size() * kClumpDoubles;
    if (count == 0) continue;
    in[q].resize(count);
    requests.emplace_back();
    MPI_Irecv(in[q].data(), static_cast<int>(in[q].size()), MPI_DOUBLE, q, 7, comm_, &requests.back());
  }
  auto put3 = [](std::vector<double>& o, const Vec3& v) {
    o.push_back(v.x);
    o.push_back(v.y);
    o.push_back(v.z);
  };
  for (int q = 0; q < size_; ++q) {
    const auto& list = send_[static_cast<std::size_t>(q)];
    const auto& clumps = clump_send_[static_cast<std::size_t>(q)];
    if (list.empty() && clumps.empty()) continue;
    std::vector<double>& o = out[q];
    o.reserve(list.size() * kDoubles + clumps.size() * kClumpDoubles);
    for (std::uint32_t i : list)
      for (const Vec3* v : {&sim.balls.position[i], &sim.balls.velocity[i], &sim.balls.spin[i]}) put3(o, *v);
    for (std::uint32_t j : clumps) {
      put3(o, cs.position[j]);
      put3(o, cs.velocity[j]);
      const Quat& r = cs.orientation[j];
      for (double x : {r.w, r.x, r.y, r.z}) o.push_back(x);
      put3(o, cs.spin[j]);
      put3(o, cs.body_momentum[j]);
    }
    requests.emplace_back();
    MPI_Isend(o.data(), static_cast<int>(o.size()), MPI_DOUBLE, q, 7, comm_, &requests.back());
    bytes_.ghost += o.size() * sizeof(double);
  }
  MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  for (int q = 0; q < size_; ++q) {
    const double* p = in[q].data();
    auto get3 = [&p]() {
      const Vec3 v{p[0], p[1], p[2]};
      p += 3;
      return v;
    };
    for (std::uint32_t i : recv_[static_cast<std::size_t>(q)])
      for (Vec3* v : {&sim.balls.position[i], &sim.balls.velocity[i], &sim.balls.spin[i]}) *v = get3();
    for (std::uint32_t j : clump_recv_[static_cast<std::size_t>(q)]) {
      cs.position[j] = get3();
      cs.velocity[j] = get3();
      cs.orientation[j] = {p[0], p[1], p[2], p[3]};
      p += 4;
      cs.spin[j] = get3();
      cs.body_momentum[j] = get3();
      for (std::uint32_t k : pebbles_of_[j]) sim.clumps.place_pebble(sim.balls, k);
    }
  }
  ++bytes_.steps;
}

bool Domain::rebuild_anywhere(bool here) {
  int any = here ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_LOR, comm_);
  return any != 0;
}

void Domain::before_rebuild(Simulation& sim) {
  const std::size_t n = sim.balls.size();
  ContactStore& rows = sim.contacts;
  // Rows per owned ball (integers: the sums are exact in any order); a new cut when out of balance.
  std::vector<double> load(n, 1.0);
  for (const ContactKey& k : rows.key) {
    load[k.a] += 1.0;
    if (k.kind == ContactKind::BallBall) load[k.b] += 1.0;
  }
  long long mine = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (owner_[i] == rank_) mine += static_cast<long long>(load[i]);
  long long most = mine, all = mine;
  MPI_Allreduce(MPI_IN_PLACE, &most, 1, MPI_LONG_LONG, MPI_MAX, comm_);
  MPI_Allreduce(MPI_IN_PLACE, &all, 1, MPI_LONG_LONG, MPI_SUM, comm_);
  if (size_ > 1 && static_cast<double>(most) > kImbalance * static_cast<double>(all) / size_) {
    std::vector<Vec3> points;
    std::vector<double> weights;
    for (std::size_t i = 0; i < n; ++i)
      if (owner_[i] == rank_) {
        points.push_back(sim.settings.box.wrapped(sim.balls.position[i]));
        weights.push_back(load[i]);
      }
    rcb_->cut(points, weights);
    ++bytes_.repartitions;
  }
  set_width(sim);
  // Where each local ball and clump is to be: its new owner, then its ghost ranks (sorted).
  std::vector<std::vector<int>> where, clump_where;
  places(sim, where, clump_where);
  std::vector<Buffer> out(static_cast<std::size_t>(size_));
  // Balls and clumps from their old owner to every rank that is to hold them; rows from the old
  // owner of their first ball to every rank that is to hold both balls. Balls, a marker, clumps, a
  // marker, then rows.
  std::vector<std::vector<std::uint32_t>> row_lists(static_cast<std::size_t>(size_));
  for (std::size_t i = 0; i < n; ++i) {
    if (owner_[i] != rank_) continue;
    for (int q : where[i]) put_ball(out[static_cast<std::size_t>(q)], sim.balls, i, global_[i], where[i].front());
  }
  for (Buffer& b : out) b.put(std::uint32_t{UINT32_MAX});  // (no global index is this: the end of the balls)
  const std::vector<std::vector<std::uint32_t>> pebbles_of = pebbles_by_clump(sim.clumps);
  for (std::size_t j = 0; j < sim.clumps.size(); ++j) {
    if (clump_owner_[j] != rank_) continue;
    for (int q : clump_where[j])
      put_clump(out[static_cast<std::size_t>(q)], sim.clumps, j, clump_global_[j], clump_where[j].front(), pebbles_of[j],
                pebble_global_, global_);
  }
  std::vector<int> both;
  auto sorted = [](std::vector<int> v) {  // (the owner first, the others sorted: all sorted)
    std::sort(v.begin(), v.end());
    return v;
  };
  for (std::size_t c = 0; c < rows.size(); ++c) {
    const ContactKey& k = rows.key[c];
    if (owner_[k.a] != rank_) continue;
    both.clear();
    if (k.kind == ContactKind::BallBall) {
      const std::vector<int> wa = sorted(where[k.a]), wb = sorted(where[k.b]);
      std::set_intersection(wa.begin(), wa.end(), wb.begin(), wb.end(), std::back_inserter(both));
    } else
      both = where[k.a];
    for (int q : both) row_lists[static_cast<std::size_t>(q)].push_back(static_cast<std::uint32_t>(c));
  }
  for (int q = 0; q < size_; ++q) {
    Buffer& b = out[static_cast<std::size_t>(q)];
    b.put(std::uint32_t{UINT32_MAX});  // (the end of the clumps)
    for (std::uint32_t c : row_lists[static_cast<std::size_t>(q)]) {
      ContactKey g = rows.key[c];
      g.a = global_[g.a];
      if (g.kind == ContactKind::BallBall) g.b = global_[g.b];
      put_row(b, rows, c, g);
    }
  }
  const Received got = all_to_all(comm_, out, bytes_.migration);
  BallStore balls;
  ContactStore arrived;
  ClumpArrivals clumps;
  std::vector<std::uint32_t> global;
  std::vector<int> owner;
  for (int q = 0; q < size_; ++q) {
    Reader in{got.bytes.data() + got.from[q], got.bytes.data() + got.from[q + 1]};
    while (!at_marker(in)) get_ball(in, balls, global, owner);
    while (!at_marker(in)) get_clump(in, clumps);
    while (in.p < in.end) get_row(in, arrived);
  }
  sort_balls(balls, global, owner);
  sim.contacts = sort_rows(arrived, &global);
  sim.balls = std::move(balls);
  sim.clumps = sort_clumps(clumps, &global);
  global_ = std::move(global);
  owner_ = std::move(owner);
  clump_global_ = std::move(clumps.global);
  clump_owner_ = std::move(clumps.owner);
  pebble_global_ = std::move(clumps.pebble_global);
  make_lists(sim);
  ++bytes_.rebuilds;
}

void Domain::after_forces(Simulation& sim) {
  if (sim.walls.walls.empty()) return;
  // One active wall row of an owned ball: its key in global indices and its share (72 bytes).
  struct Share {
    std::uint32_t ball, wall;
    WallShare share;
  };
  static_assert(std::is_trivially_copyable_v<Share>);
  std::vector<Share> mine;
  const ContactStore& rows = sim.contacts;
  for (std::size_t c = 0; c < rows.size(); ++c) {
    const ContactKey& k = rows.key[c];
    if (k.kind != ContactKind::BallWall || !rows.active[c] || owner_[k.a] != rank_) continue;
    mine.push_back({global_[k.a], k.b,
                    wall_row_share(sim.walls.walls[k.b], rows, c, sim.balls.position[k.a], sim.balls.radius[k.a])});
  }
  const int bytes = static_cast<int>(mine.size() * sizeof(Share));
  std::vector<int> counts(static_cast<std::size_t>(size_)), at(static_cast<std::size_t>(size_) + 1, 0);
  MPI_Allgather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
  for (int q = 0; q < size_; ++q) at[q + 1] = at[q] + counts[q];
  wall_in_.resize(static_cast<std::size_t>(at[size_]));
  MPI_Allgatherv(mine.data(), bytes, MPI_BYTE, wall_in_.data(), counts.data(), at.data(), MPI_BYTE, comm_);
  bytes_.walls += static_cast<std::uint64_t>(bytes) * static_cast<std::uint64_t>(size_ - 1);
  std::vector<Share> all(wall_in_.size() / sizeof(Share));
  std::memcpy(all.data(), wall_in_.data(), wall_in_.size());
  // The whole run's row order (ContactKey: kind, then ball, then wall), from zero.
  std::sort(all.begin(), all.end(), [](const Share& x, const Share& y) { return x.ball != y.ball ? x.ball < y.ball : x.wall < y.wall; });
  for (Wall& w : sim.walls.walls) clear_wall_sums(w);
  for (const Share& s : all) add_wall_share(sim.walls.walls[s.wall], s.share);
}

double Domain::min_over_ranks(double x) {
  // A ghost's stiffness sums are over part of its rows, each term ≥ 0, so never above its owner's
  // (rounding is monotonic): its m/k is never below, and the minimum over the ranks is that over
  // the owned balls, the whole run's.
  MPI_Allreduce(MPI_IN_PLACE, &x, 1, MPI_DOUBLE, MPI_MIN, comm_);
  return x;
}

Simulation Domain::gather(bool with_cycle) const {
  const Simulation& sim = *sim_;
  const CycleState cycle = with_cycle ? sim.cycle_state() : CycleState{};
  const bool built = with_cycle && cycle.position_at_build.size() == global_.size();
  Buffer b;
  b.put(static_cast<std::uint8_t>(built));
  auto& balls = const_cast<BallStore&>(sim.balls);  // (for_each_column is non-const; only read)
  auto& rows = const_cast<ContactStore&>(sim.contacts);
  std::uint32_t n_owned = 0;
  for (std::size_t i = 0; i < global_.size(); ++i) n_owned += owner_[i] == rank_;
  b.put(n_owned);
  for (std::size_t i = 0; i < global_.size(); ++i)
    if (owner_[i] == rank_) {
      put_ball(b, balls, i, global_[i], rank_);
      if (built) b.put(cycle.position_at_build[i]);
    }
  auto& clumps = const_cast<ClumpBodies&>(sim.clumps);
  const std::vector<std::vector<std::uint32_t>> pebbles_of = pebbles_by_clump(clumps);
  b.put(static_cast<std::uint32_t>(owned_clumps()));
  for (std::size_t j = 0; j < clumps.size(); ++j)
    if (clump_owner_[j] == rank_) put_clump(b, clumps, j, clump_global_[j], rank_, pebbles_of[j], pebble_global_, global_);
  for (std::size_t c = 0; c < rows.size(); ++c) {
    ContactKey g = rows.key[c];
    if (owner_[g.a] != rank_) continue;
    g.a = global_[g.a];
    if (g.kind == ContactKind::BallBall) g.b = global_[g.b];
    put_row(b, rows, c, g);
  }
  int count = static_cast<int>(b.bytes.size());
  std::vector<int> counts(static_cast<std::size_t>(size_)), at(static_cast<std::size_t>(size_) + 1, 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm_);
  for (int q = 0; q < size_; ++q) at[q + 1] = at[q] + counts[q];
  std::vector<char> all(rank_ == 0 ? static_cast<std::size_t>(at[size_]) : 0);
  MPI_Gatherv(b.bytes.data(), count, MPI_BYTE, all.data(), counts.data(), at.data(), MPI_BYTE, 0, comm_);
  Simulation whole;
  if (rank_ != 0) return whole;
  whole.settings = sim.settings;
  whole.settings.skin = skin_given_;
  whole.table = sim.table;
  whole.groups = sim.groups;
  whole.walls = sim.walls;
  whole.time = sim.time;
  whole.steps = sim.steps;
  whole.last_dt = sim.last_dt;
  std::vector<std::uint32_t> global;
  std::vector<int> owner;
  ContactStore arrived;
  ClumpArrivals arrived_clumps;
  bool all_built = with_cycle;
  std::vector<Vec3> at_build;  // (in arrival order, as the balls)
  for (int q = 0; q < size_; ++q) {
    Reader in{all.data() + at[q], all.data() + at[q + 1]};
    const bool built_there = in.get<std::uint8_t>() != 0;
    all_built = all_built && built_there;
    const auto balls_here = in.get<std::uint32_t>();
    for (std::uint32_t k = 0; k < balls_here; ++k) {
      get_ball(in, whole.balls, global, owner);
      if (built_there) at_build.push_back(in.get<Vec3>());
    }
    const auto clumps_here = in.get<std::uint32_t>();
    for (std::uint32_t k = 0; k < clumps_here; ++k) get_clump(in, arrived_clumps);
    while (in.p < in.end) get_row(in, arrived);
  }
  std::vector<std::uint32_t> arrival = global;  // (global indices in arrival order)
  sort_balls(whole.balls, global, owner);
  for (std::size_t k = 0; k < global.size(); ++k)
    if (global[k] != k) throw std::runtime_error("domain gather: ball " + std::to_string(k) + " is missing");
  whole.contacts = sort_rows(arrived, nullptr);
  // (The balls' rows are their global indices now: the pebbles' ball rows stay as sent.)
  whole.clumps = sort_clumps(arrived_clumps, nullptr);
  for (std::size_t k = 0; k < arrived_clumps.global.size(); ++k)
    if (arrived_clumps.global[k] != k) throw std::runtime_error("domain gather: clump " + std::to_string(k) + " is missing");
  for (std::size_t k = 0; k < arrived_clumps.pebble_global.size(); ++k)
    if (arrived_clumps.pebble_global[k] != k) throw std::runtime_error("domain gather: pebble " + std::to_string(k) + " is missing");
  // The walls' sums as the whole run's force pass makes them: every active wall row, in row order.
  for (Wall& w : whole.walls.walls) clear_wall_sums(w);
  for (std::size_t c = 0; c < whole.contacts.size(); ++c) {
    const ContactKey& k = whole.contacts.key[c];
    if (k.kind != ContactKind::BallWall || !whole.contacts.active[c]) continue;
    add_wall_row(whole.walls.walls[k.b], whole.contacts, c, whole.balls.position[k.a], whole.balls.radius[k.a]);
  }
  if (with_cycle) {
    // The rows here are every row of every ball (each from its first ball's owner, who holds them
    // all): the whole neighbour list. The counters are every rank's (all rebuild together); the
    // count of pairs no rule matched, information only, is rank 0's.
    CycleState whole_cycle = cycle;
    whole_cycle.position_at_build.clear();
    if (all_built) {
      whole_cycle.position_at_build.resize(at_build.size());
      for (std::size_t k = 0; k < arrival.size(); ++k) whole_cycle.position_at_build[arrival[k]] = at_build[k];
    } else {
      whole_cycle.rebuild_needed = true;
    }
    whole_cycle.rows_complete = true;
    whole.restore_cycle_state(std::move(whole_cycle));
  }
  return whole;
}

}  // namespace hilldem::parallel
