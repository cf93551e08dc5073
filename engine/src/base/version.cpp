// phiq::version(): the version compiled into the library (version.hpp), not the one a program's headers say.
#include "phiq/version.hpp"

namespace phiq {

const char* version() { return kVersion; }

}  // namespace phiq
