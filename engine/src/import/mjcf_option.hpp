// MJCF's <option> (mjcf_reader.cpp): of MuJoCo's simulation settings, the gravity, which phiq's efforts and
// reactions need (the scene's loads.gravity); the others (timestep, integrator, ...) are not mapped.
#pragma once

#include <tinyxml2.h>

#include "import/mechanism.hpp"
#include "import/mjcf_documents.hpp"

namespace phiq::detail::mechanism {

// Reads `option`'s gravity into m.gravity and m.gravity_from (a <flag gravity="disable"> turns it off). Returns
// whether the element holds other settings, which the caller lists as not mapped. Throws SceneError "FILE:LINE:
// ..." for a gravity that is not three numbers.
bool read_mjcf_option(const tinyxml2::XMLElement* option, const MjcfDocuments& docs, Mechanism& m);

}  // namespace phiq::detail::mechanism
