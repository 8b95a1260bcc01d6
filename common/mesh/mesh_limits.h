// The largest body a scene may build, in nodes and in tetrahedra, whatever describes it (a
// mesh or surface file, a box, a lattice, a grid). Checked before anything of that size is
// allocated, so a hostile or mistaken scene (one that came with a recording, say) fails
// with a message instead of taking gigabytes. The finest shipped meshes hold about 10^4
// nodes; a linear elastic body of kMaxBodyNodes nodes already needs gigabytes to factorise.
#pragma once

#include <cstdint>

namespace cohaptic {

inline constexpr std::int64_t kMaxBodyNodes = 250'000;
inline constexpr std::int64_t kMaxBodyTetrahedra = 1'500'000;

}  // namespace cohaptic
