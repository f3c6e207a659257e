#pragma once
/// \file
/// The hot kernel of SlabFields::update() for spheres no wider than a slab: where each sphere
/// lies and its exact partial volumes in the (at most) two slabs it touches (physics.md §4).
///
/// Kept in its own translation unit because it is compiled with -fno-trapping-math (see
/// dem/CMakeLists.txt): comparisons that cannot trap may then be evaluated on both sides of a
/// select, which is what lets the compiler vectorize the loop (4 spheres at a time in the AVX2
/// build picked at run time, core/cpu_dispatch.hpp). Nothing in the loop raises a floating-point
/// exception for positions below max_slabs dz; a larger one is computed as z = 0 and reported
/// through the return value, and so is a NaN (whose comparison raises "invalid", which only
/// matters where exceptions are trapped, as in the tests).

#include <cstddef>
#include <cstdint>

#include "core/vec3.hpp"

namespace efdem::dem {

/// Result of split_two_slabs(): one past the highest slab touched, and whether some sphere's
/// top (z + r)/dz was out of (-max_slabs, max_slabs) or NaN (its entries are then meaningless).
struct SlabSplit {
    std::uint32_t top;
    bool out_of_range;
};

/// For spheres i < n (centre x[i], radius rad[i] <= dz): first[i] = lowest slab touched,
/// count[i] = 1 or 2 slabs, w[2i], w[2i+1] = volumes in them (w[2i+1] = 0 when count[i] = 1).
/// Same results to the bit in either build (no FMA).
SlabSplit split_two_slabs(std::size_t n, const Vec3* x, const double* rad, double dz,
                          double max_slabs, std::uint32_t* first, std::uint8_t* count, double* w);

}  // namespace efdem::dem
