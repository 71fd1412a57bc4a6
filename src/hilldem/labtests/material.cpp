#include "hilldem/labtests/material.hpp"

#include <algorithm>

namespace hilldem {

const char* to_string(GrainModel m) { return m == GrainModel::Hill ? "hill" : "linear"; }

std::string Class5Material::name(const std::string& grading) const {
  return grading + (model == GrainModel::Hill ? "_Hill" : "_Linear");
}

namespace {
ModelRule wall_rule(Simulation& sim, const WallContact& walls) {
  ModelRule r;
  r.name = "grain-vessel";
  r.kind = ContactKind::BallWall;
  r.groups1 = sim.groups.bit(kGrainGroup);
  r.groups2 = sim.groups.bit(kVesselGroup);
  r.groups1_text = kGrainGroup;
  r.groups2_text = kVesselGroup;
  r.model = ModelKind::Linear;
  r.linear = LinearParams{walls.emod, walls.kratio, walls.fric};
  return r;
}
ModelRule grain_rule(Simulation& sim, const std::string& name) {
  ModelRule r;
  r.name = name;
  r.kind = ContactKind::BallBall;
  r.groups1 = r.groups2 = sim.groups.bit(kGrainGroup);
  r.groups1_text = r.groups2_text = kGrainGroup;
  return r;
}
}  // namespace

ModelTable packing_table(Simulation& sim, const PackingContact& grains, const WallContact& walls) {
  ModelTable t;
  ModelRule g = grain_rule(sim, grains.model == GrainModel::Hill ? "grain-grain packing hill" : "grain-grain packing linear");
  if (grains.model == GrainModel::Hill) {
    g.model = ModelKind::Hill;
    g.hill = HillParams{grains.fric, grains.damp_con, 0.0};  // dry: no suction acts during packing
  } else {
    g.model = ModelKind::Linear;
    g.linear = LinearParams{grains.emod, grains.kratio, grains.fric};
  }
  t.rules.push_back(g);
  WallContact w = walls;
  w.fric = 0.0;  // frictionless walls during genesis [practice]
  t.rules.push_back(wall_rule(sim, w));
  return t;
}

ModelTable material_table(Simulation& sim, const Class5Material& m, const WallContact& walls) {
  ModelTable t;
  ModelRule g = grain_rule(sim, m.model == GrainModel::Hill ? "grain-grain hill" : "grain-grain linear");
  if (m.model == GrainModel::Hill) {
    g.model = ModelKind::Hill;
    g.hill = HillParams{m.fric, m.damp_con, m.suction};
  } else {
    g.model = ModelKind::Linear;
    g.linear = LinearParams{m.linear_emod, m.linear_kratio, m.fric};
  }
  t.rules.push_back(g);
  t.rules.push_back(wall_rule(sim, walls));
  return t;
}

void install_table(Simulation& sim, ModelTable table) {
  sim.table = std::move(table);
  sim.contacts.clear();
  sim.invalidate_forces();
}

void apply_grain_properties(Simulation& sim, const Class5Material& m) {
  ClumpBodies& c = sim.clumps;
  if (!c.empty()) {
    // A clump's mass and inertia scale with its density (same union volume); L_b with them, so that
    // its spin is kept. Its pebbles' mass and inertia columns are the clump's (clump_bodies.hpp).
    std::vector<double> factor(c.size(), 0.0);
    for (std::size_t k = 0; k < c.pebbles.size(); ++k) {
      const std::uint32_t i = c.pebbles.clump[k];
      if (factor[i] == 0.0) factor[i] = m.density / sim.balls.density[c.ball[k]];
    }
    for (std::size_t i = 0; i < c.size(); ++i) {
      c.state.mass[i] *= factor[i];
      c.state.principal_inertia[i] *= factor[i];
      c.state.body_momentum[i] *= factor[i];
    }
    for (std::size_t k = 0; k < c.pebbles.size(); ++k) {
      const std::uint32_t b = c.ball[k], i = c.pebbles.clump[k];
      sim.balls.density[b] = m.density;
      sim.balls.young_mod[b] = m.young_mod;
      sim.balls.pois_ratio[b] = m.pois_ratio;
      const Vec3& in = c.state.principal_inertia[i];
      sim.balls.mass[b] = c.state.mass[i];
      sim.balls.inertia[b] = std::min(in.x, std::min(in.y, in.z));
    }
  }
  const std::vector<std::uint32_t> of = c.clump_of_balls(sim.balls.size());
  for (std::size_t i = 0; i < sim.balls.size(); ++i) {
    if (!of.empty() && of[i] != kNoClump) continue;
    sim.balls.density[i] = m.density;
    sim.balls.young_mod[i] = m.young_mod;
    sim.balls.pois_ratio[i] = m.pois_ratio;
    sim.balls.update_mass(i);
  }
  sim.refresh_mappings();
}

}  // namespace hilldem
