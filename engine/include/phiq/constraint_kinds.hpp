/// @file
/// Every constraint kind of phiq, planar and spatial, as plain data: one header per kind in kinds/, listed by
/// kinds/registry.hpp. Every kind states its equation Φ(q, t) = 0 in a comment and supplies, for the rows it owns:
///   residual(q, t, phi)        Φ
///   jacobian(q, t, sink)       Φq as (row, slot, value) entries through `sink`, always in the same order and with the
///                              same set of entries (the set may depend on which slots are constants, never on values),
///                              so that one pass in pattern mode fixes the sparsity pattern of the model
///   phi_t(q, t, out)           ∂Φ/∂t (only called when depends_on_time())
///   gamma(q, qd, t, out)       γ = −(Φq q̇)q q̇ − 2 Φqt q̇ − Φtt, the right-hand side of Φq q̈ = γ
///   prepare(q0)                the checks of its data, and what it derives from the placement when added
///   joint_count()              what it counts for in the Grübler–Kutzbach formula
///   sketch(sk)                 the lines that draw it
///   kScene                     how scenes write it
/// plus the unit of each row and, through for_each_slot, the unit of each coordinate it reads. The solver never
/// needs to know which kind it is evaluating (see constraint_block.hpp). The contract of these functions is
/// documented once, on DistanceSpec; the other kinds refer to it and say where they differ.
///
/// Covers the four coordinate families of the notes: natural coordinates (distance, fixed point through Pin with a
/// constant side, point on line, constant angle), reference-point coordinates (revolute Pin between body frames,
/// prismatic), relative coordinates (loop closure), mixes (segment angle, polar), general equations, couplers and
/// drivers; in space, Euler parameters, natural vectors and the joints (constraint_kinds_3d.hpp).
#pragma once

#include "phiq/kinds/registry.hpp"
