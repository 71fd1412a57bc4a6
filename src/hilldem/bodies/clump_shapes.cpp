#include "hilldem/bodies/clump_shapes.hpp"

#include <string>

#include "hilldem/bodies/clump_mesh.hpp"
#include "hilldem/core/error.hpp"

namespace hilldem {

Pebbles named_shape_fill(const std::string& name, const FillParams& params) {
  if (name == "ellipsoid") return fill_shape(EllipsoidShape(1.5, 1.2, 1.0), params).pebbles;
  return fill_shape(MeshShape(aggregate_polyhedron(name)), params).pebbles;
}

ClumpTemplate named_template(const std::string& name, double density) {
  Pebbles p;
  if (name == "sphere") {
    p.position = {{0.0, 0.0, 0.0}};
  } else if (name == "elongated2") {
    p.position = {{-0.5, 0.0, 0.0}, {0.5, 0.0, 0.0}};
  } else if (name == "elongated3") {
    p.position = {{-1.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}};
  } else if (name == "ellipsoid" || name == "cube" || name == "prism" || name == "slab" || name == "rock") {
    return make_template(named_shape_fill(name), density);
  } else {
    throw InputError("unknown clump template '" + name + "'; known: " + kNamedTemplates);
  }
  p.radius.assign(p.position.size(), 1.0);
  return make_template(p, density);
}

}  // namespace hilldem
