#include "hilldem/labtests/vessel.hpp"

#include "hilldem/core/error.hpp"

namespace hilldem {

Servo Vessel::radial_servo(const ServoSettings& settings) const {
  const Vessel v = *this;
  return Servo(Servo::Mode::Radial, {lateral}, Vec3{}, settings, [v](const Simulation& s) { return v.lateral_area(s); });
}

Servo Vessel::platen_servo(bool top_platen, const ServoSettings& settings) const {
  const Vessel v = *this;
  return Servo(Servo::Mode::Axial, {top_platen ? top : bottom}, Vec3{0, 0, top_platen ? 1.0 : -1.0}, settings,
               [v](const Simulation& s) { return v.platen_area(s); });
}

void Vessel::stop(Simulation& s) const {
  for (std::size_t w : {lateral, bottom, top}) {
    s.walls.walls[w].velocity = Vec3{};
    s.walls.walls[w].radial_velocity = 0.0;
  }
}

Vessel add_vessel(Simulation& sim, double radius, double height, std::uint64_t groups) {
  Vessel v;
  Wall lateral;
  lateral.name = "vessel.lateral";
  lateral.groups = groups;
  lateral.shape = WallShape::Cylinder;
  lateral.axis = 2;
  lateral.point = Vec3{0, 0, 0};
  lateral.radius = radius;  // infinite extent: the platens close the vessel
  v.lateral = sim.walls.add(lateral);

  Wall bottom;
  bottom.name = "vessel.bottom";
  bottom.groups = groups;
  bottom.shape = WallShape::Plane;
  bottom.point = Vec3{0, 0, 0};
  bottom.normal = Vec3{0, 0, 1};
  bottom.rotation_center = bottom.point;
  v.bottom = sim.walls.add(bottom);

  Wall top = bottom;
  top.name = "vessel.top";
  top.point = Vec3{0, 0, height};
  top.normal = Vec3{0, 0, -1};
  top.rotation_center = top.point;
  v.top = sim.walls.add(top);
  return v;
}

Vessel find_vessel(const Simulation& sim) {
  const long l = sim.walls.find("vessel.lateral"), b = sim.walls.find("vessel.bottom"), t = sim.walls.find("vessel.top");
  if (l < 0 || b < 0 || t < 0) throw InputError("no material vessel (walls vessel.lateral, vessel.bottom, vessel.top)");
  return {static_cast<std::size_t>(l), static_cast<std::size_t>(b), static_cast<std::size_t>(t)};
}

}  // namespace hilldem
