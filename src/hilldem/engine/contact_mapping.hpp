// A contact's creation by proximity (its rule's properties, then its mapping: model_dispatch.hpp):
// shared by make_wet and the force pass.
#pragma once

#include <cstddef>

#include "hilldem/bodies/ball_store.hpp"
#include "hilldem/contact/contact_store.hpp"
#include "hilldem/core/vec3.hpp"
#include "hilldem/engine/hill_param_sets.hpp"
#include "hilldem/models/model_table.hpp"

namespace hilldem {

// Row c becomes a contact (created by proximity) with normal n̂_c and its assignment rule's
// properties. Safe from the force pass's threads (each row is written by one thread).
void create_contact(const ModelTable& table, const BallStore& balls, HillParamSets& sets, ContactStore& contacts,
                    std::size_t c, const Vec3& normal);

}  // namespace hilldem
