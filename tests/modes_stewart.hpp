// A general Stewart–Gough platform as a scene (the modes tests' and bench/bench_modes.cpp's; base and platform
// points in general position: no two legs meeting, neither hexagon planar): one body in x, y, z and e0 … e3,
// six legs (distances from ground points to platform points). Its system's total degree is 8192; lowered, 432 paths.
#pragma once

namespace phiq::test {

inline constexpr const char* kModesStewartScene =
    "phiq: 1\nname: stewart_gough\ndimension: 3\n"
    "coordinates: {x: 0.1, y: 0.05, z: 1.0, e0: 1, e1: 0.05, e2: 0.02, e3: 0.1}\n"
    "bodies: {platform: [x, y, z, e0, e1, e2, e3]}\n"
    "constraints:\n"
    "  - {name: leg1, type: distance, between: [{body: ground, at: [1.0, 0.1, 0.05]}, {body: platform, at: [0.5, 0.3, "
    "0.02]}], length: 1.3}\n"
    "  - {name: leg2, type: distance, between: [{body: ground, at: [0.3, 0.9, -0.1]}, {body: platform, at: [-0.2, 0.6, "
    "0.1]}], length: 1.1}\n"
    "  - {name: leg3, type: distance, between: [{body: ground, at: [-0.7, 0.6, 0.08]}, {body: platform, at: [-0.5, "
    "0.1, -0.05]}], length: 1.25}\n"
    "  - {name: leg4, type: distance, between: [{body: ground, at: [-0.8, -0.4, 0.02]}, {body: platform, at: [-0.3, "
    "-0.5, 0.07]}], length: 1.2}\n"
    "  - {name: leg5, type: distance, between: [{body: ground, at: [0.1, -1.0, -0.06]}, {body: platform, at: [0.2, "
    "-0.6, -0.03]}], length: 1.05}\n"
    "  - {name: leg6, type: distance, between: [{body: ground, at: [0.9, -0.5, 0.12]}, {body: platform, at: [0.6, "
    "-0.2, 0.04]}], length: 1.15}\n"
    "time: {start: 0, end: 1, steps: 1}\n";

}  // namespace phiq::test
