#include "hilldem/bench/bed_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <fmt/format.h>
#include <omp.h>

#include "hilldem/bodies/clump_shapes.hpp"
#include "hilldem/core/error.hpp"
#include "hilldem/io/state_io.hpp"

namespace hilldem {

#ifndef HILLDEM_BUILD_KIND
#define HILLDEM_BUILD_KIND "plain"  // (set by CMakeLists.txt: pgo, pgo-instrumented or plain)
#endif

std::string BedBenchResult::line() const {
  return fmt::format("particles={} steps={} wall_s={:.3f} particle_steps_per_s={:.4g} contacts_per_particle={:.3f} "
                     "threads={} rebuilds={} build={}{}{}",
                     particles, steps, wall_seconds, particle_steps_per_second, contacts_per_particle, threads, rebuilds,
                     HILLDEM_BUILD_KIND, clumps > 0 ? fmt::format(" clumps={}", clumps) : "",
                     digest.empty() ? "" : " digest=" + digest);
}

Simulation make_bed(const Packing& packing) {
  Simulation sim;
  std::int64_t id = 1;
  for (const ImportedBall& b : packing.balls) {
    BallInit init;
    init.id = id++;
    init.position = b.position;
    init.radius = b.radius;
    init.density = b.density > 0.0 ? b.density : 2650.0;
    init.young_mod = 29e9;
    init.pois_ratio = 0.15;
    sim.balls.add(init);
  }
  sim.settings.box.periodic[0] = sim.settings.box.periodic[1] = true;
  sim.settings.box.lo = packing.box_lo;
  sim.settings.box.hi = packing.box_hi;
  sim.settings.gravity = {0, 0, -9.81};
  sim.settings.auto_timestep = false;
  sim.settings.timestep = 1e-6;
  sim.settings.skin = 1e-3;  // as the LAMMPS deck (0.1 mean diameter)

  ModelRule grains;
  grains.name = "grain-grain hill";
  grains.kind = ContactKind::BallBall;
  grains.model = ModelKind::Hill;
  grains.hill = {0.4, 0.07, 0.0};
  sim.table.rules.push_back(grains);
  ModelRule floor_rule;
  floor_rule.name = "grain-floor linear";
  floor_rule.kind = ContactKind::BallWall;
  floor_rule.model = ModelKind::Linear;
  floor_rule.linear = {29e9, 1.0, 0.4};
  sim.table.rules.push_back(floor_rule);
  Wall floor;
  floor.name = "floor";
  floor.shape = WallShape::Plane;
  floor.point = {0, 0, 0};
  floor.normal = {0, 0, 1};
  sim.walls.add(floor);
  sim.sort_balls_spatially();
  return sim;
}

Simulation make_clump_bed(const Packing& packing, const ClumpTemplate& unit, std::uint64_t seed) {
  const Simulation spheres = make_bed(packing);  // (in its spatial order: clumps, and so pebbles, follow it)
  Simulation sim;
  sim.settings = spheres.settings;
  sim.settings.box = PeriodicBox{};
  sim.table = spheres.table;
  sim.walls = spheres.walls;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::int64_t id = 1;
  for (std::size_t i = 0; i < spheres.balls.size(); ++i) {
    // A uniformly random rotation (Shoemake, Graphics Gems III, 1992).
    const double u1 = u(rng), u2 = 2.0 * std::numbers::pi * u(rng), u3 = 2.0 * std::numbers::pi * u(rng);
    const Quat q{std::sqrt(1.0 - u1) * std::sin(u2), std::sqrt(1.0 - u1) * std::cos(u2), std::sqrt(u1) * std::sin(u3),
                 std::sqrt(u1) * std::cos(u3)};
    ClumpInit c;
    c.first_ball_id = id;
    c.position = spheres.balls.position[i];
    c.orientation = normalized(q);
    c.young_mod = spheres.balls.young_mod[i];
    c.pois_ratio = spheres.balls.pois_ratio[i];
    const ClumpTemplate t = unit.scaled(2.0 * spheres.balls.radius[i], SizeMeasure::EnclosingDiameter);
    // (about the template's centre of mass: the pebbles stay inside the sphere, whose centre it is)
    sim.clumps.add(sim.balls, t, c);
    id += static_cast<std::int64_t>(t.pebbles.size());
  }
  sim.invalidate_forces();
  return sim;
}

Simulation make_pair_bed(const Packing& packing) {
  Simulation spheres = make_bed(packing);
  spheres.cycle(1);  // the settled bed's contacts
  const std::size_t n = spheres.balls.size();
  // Per ball, its touching partners (overlap, partner), from the active ball-ball rows; a pair across
  // a periodic boundary is left out (the clump bed is not periodic).
  std::vector<std::vector<std::pair<double, std::uint32_t>>> partners(n);
  for (std::size_t c = 0; c < spheres.contacts.size(); ++c) {
    const ContactKey& k = spheres.contacts.key[c];
    if (!spheres.contacts.active[c] || k.kind != ContactKind::BallBall) continue;
    const double d = norm(spheres.balls.position[k.a] - spheres.balls.position[k.b]);
    const double overlap = spheres.balls.radius[k.a] + spheres.balls.radius[k.b] - d;
    if (overlap < 0.0 || overlap > 0.5 * std::min(spheres.balls.radius[k.a], spheres.balls.radius[k.b])) continue;
    partners[k.a].emplace_back(overlap, static_cast<std::uint32_t>(k.b));
    partners[k.b].emplace_back(overlap, static_cast<std::uint32_t>(k.a));
  }
  // Greedy matching in bed order: each ball not yet taken takes its free partner of largest overlap
  // (ties: the lower row), or stays alone (a one-pebble clump).
  std::vector<std::int64_t> mate(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (mate[i] >= 0) continue;
    std::sort(partners[i].begin(), partners[i].end(),
              [](const auto& x, const auto& y) { return x.first != y.first ? x.first > y.first : x.second < y.second; });
    for (const auto& [overlap, j] : partners[i])
      if (mate[j] < 0 && j != i) {
        mate[i] = j;
        mate[j] = static_cast<std::int64_t>(i);
        break;
      }
  }
  Simulation sim;
  sim.settings = spheres.settings;
  sim.settings.box = PeriodicBox{};
  sim.table = spheres.table;
  sim.walls = spheres.walls;
  std::int64_t id = 1;
  for (std::size_t i = 0; i < n; ++i) {
    if (mate[i] >= 0 && static_cast<std::size_t>(mate[i]) < i) continue;  // (made with its mate)
    Pebbles p;
    p.position.push_back(spheres.balls.position[i]);
    p.radius.push_back(spheres.balls.radius[i]);
    if (mate[i] >= 0) {
      p.position.push_back(spheres.balls.position[mate[i]]);
      p.radius.push_back(spheres.balls.radius[mate[i]]);
    }
    // Exact mass properties (one or two pebbles); the clump placed where its pebbles were given.
    const ClumpTemplate t = make_template(p, spheres.balls.density[i]);
    ClumpInit c;
    c.first_ball_id = id;
    c.position = t.centre_of_mass;
    // (orientation: identity; add_clump turns the principal frame by the template's own)
    c.young_mod = spheres.balls.young_mod[i];
    c.pois_ratio = spheres.balls.pois_ratio[i];
    sim.clumps.add(sim.balls, t, c);
    id += static_cast<std::int64_t>(p.size());
  }
  sim.invalidate_forces();
  return sim;
}

std::int64_t settle_bed(const std::string& in, const std::string& out, double ratio) {
  Packing packing = read_packing(in, PackingFormat::Lammps);
  Simulation sim = make_bed(packing);
  sim.settings.local_damping = 0.7;
  const std::int64_t steps = sim.solve(ratio, 200000);
  if (steps < 0) throw RunError("the bed did not settle within 200000 steps");
  packing.balls.clear();
  for (std::size_t i = 0; i < sim.balls.size(); ++i)
    packing.balls.push_back({sim.balls.position[i], sim.balls.radius[i], sim.balls.density[i]});
  write_lammps_data(out, packing,
                    fmt::format("hilldem settled bed: {} spheres, local damping 0.7 to ratio {:g} in {} steps",
                                sim.balls.size(), ratio, steps));
  return steps;
}

BedBenchResult run_bed_bench(const BedBenchOptions& o, const BenchDecomposition* dec) {
  if (o.threads > 0) omp_set_num_threads(o.threads);
  Packing packing = read_packing(o.data, PackingFormat::Lammps);
  const int rep[3] = {o.replicate, o.replicate, 1};
  replicate(packing, rep);
  Simulation sim = o.clumps.empty()    ? make_bed(packing)
                   : o.clumps == "pairs" ? make_pair_bed(packing)
                                         : make_clump_bed(packing, named_template(o.clumps, 2650.0), 10000);
  if (o.block > 0) sim.balls_per_block = o.block;
  const std::size_t clumps = sim.clumps.size();  // (the whole bed's: a rank holds its part once attached)
  if (dec) dec->attach(sim);
  sim.cycle(o.warmup);
  const std::int64_t rebuilds0 = sim.rebuilds();
  BedBenchResult r;
  r.particles = dec ? dec->particles(sim) : sim.balls.size();
  r.clumps = clumps;
  r.steps = o.steps;
  const double particles = static_cast<double>(r.particles);
  if (dec) dec->barrier();
  const auto start = std::chrono::steady_clock::now();
  sim.cycle(o.steps);
  if (dec) dec->barrier();
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.particle_steps_per_second = particles * static_cast<double>(o.steps) / r.wall_seconds;
  std::size_t ball_contacts = 0;
  if (dec) {
    ball_contacts = dec->ball_contacts(sim);
  } else {
    for (std::size_t c = 0; c < sim.contacts.size(); ++c)
      ball_contacts += sim.contacts.active[c] && sim.contacts.key[c].kind == ContactKind::BallBall;
  }
  r.contacts_per_particle = 2.0 * static_cast<double>(ball_contacts) / static_cast<double>(r.particles);
  r.threads = omp_get_max_threads();
  r.rebuilds = sim.rebuilds() - rebuilds0;
  if (o.digest) r.digest = dec ? dec->digest(sim) : state_digest(sim);
  return r;
}

}  // namespace hilldem
