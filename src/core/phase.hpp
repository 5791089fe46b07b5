// The phase word of a dynamic particle: which kind of matter it is and which group (body, sheet)
// it belongs to. The solver writes it (physics), the renderer and the app read it.
#pragma once
#include <cstdint>

#include "core/hd.hpp"

namespace seamless {

// Phase word of a dynamic particle (Macklin 2014, section 4.3): a group id in the low 24 bits
// (rigid body id, cloth id) and flags above. Static scene particles live in their own arrays.
namespace phase {
constexpr std::uint32_t kGroupMask = 0x00FFFFFFu;
constexpr std::uint32_t kFluid = 1u << 24;
constexpr std::uint32_t kRigid = 1u << 25;
constexpr std::uint32_t kCloth = 1u << 26;
constexpr std::uint32_t kSelfCollide = 1u << 27;
constexpr std::uint32_t kStatic = 1u << 28;
SEAMLESS_HD inline std::uint32_t group(std::uint32_t ph) { return ph & kGroupMask; }
SEAMLESS_HD inline bool is(std::uint32_t ph, std::uint32_t flag) { return (ph & flag) != 0u; }
}  // namespace phase

}  // namespace seamless
