// The boundary between the engine and its SDF module, libphiq_sdf.so (sdf_reader.cpp with libsdformat 12).
//
// Why a module: libsdformat 12 and ignition-math 6 compile a std::regex in the static initialiser of every file that
// includes ignition/math/Helpers.hh, and load 40 ms of libraries with them. Linked into the engine, every `phiq`
// process paid that at start (79 ms for `phiq --version`, 0.43 s under AddressSanitizer) whether it read an SDF
// file or not. The engine loads the module with dlopen() on the first SDF file instead (sdf_module.cpp).
//
// The module is built by the same build as the engine (one compiler, one standard library), so the boundary passes
// C++ objects; the module checks the ABI version and the size of Mechanism, and reports a refusal as text instead of
// throwing across the boundary.
#pragma once

#include <cstddef>
#include <string>

#include "import/mechanism.hpp"

namespace phiq::detail::mechanism {

/// Raise when Mechanism or this boundary changes.
inline constexpr int kSdfModuleAbi = 2;

/// Reads the SDF `text` (named `path` in messages) into `out` and the count of joints that close loops into
/// `loops`; false with `error` (one line "PATH:LINE: what") when the file is refused.
using ReadSdf = bool (*)(const std::string& text, const std::string& path, Mechanism& out, int& loops,
                         std::string& error);

}  // namespace phiq::detail::mechanism

/// The module's one exported symbol: its reader, or null when the module was built for another engine (another
/// `abi` or another size of Mechanism).
extern "C" phiq::detail::mechanism::ReadSdf phiq_sdf_reader(int abi, std::size_t mechanism_bytes);
