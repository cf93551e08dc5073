// The bytes of a scene file, read so that no file can hang or fool the loader: what load_scene() parses. Its own
// file because it is about the operating system (descriptors, file types, FIFOs), not about YAML.
#pragma once

#include <string>

#include "phiq/scene.hpp"  // SceneLimits, SceneError

namespace phiq::detail::scene {

// Opens the scene without waiting (a FIFO with no writer would block open() for ever), then looks at what it is:
// a regular file or a pipe (a FIFO, `<(…)`) is read; anything else (a directory, a device, a socket) is refused.
// Reads are bounded by the limit whatever the file claims (/proc files report size 0, a file may grow).
// Throws SceneError "PATH: REASON": the OS's reason (strerror) when it cannot be opened or read, "is a directory,
// not a scene file" (and devices, sockets), a FIFO with nothing written to it within 5 s, a size over the limit.
std::string read_scene_file(const std::string& path, const SceneLimits& limits);

}  // namespace phiq::detail::scene
