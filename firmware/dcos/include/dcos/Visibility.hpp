// Visibility attribute of a system object (dissertation section 6.4).
#pragma once

#include <stdint.h>

namespace dcos {

/// How far an object's name is visible, and how far a name lookup reaches.
///
/// The values are ordered by reach so that a single comparison decides
/// visibility: an object is found by a lookup that asks from scope S exactly
/// when its visibility is at least S. A lookup made on the object's own node
/// asks with Local and sees everything; a lookup forwarded from another node
/// of the same intelligent controller asks with Regional; a lookup from
/// elsewhere in the factory asks with Global and sees only global objects.
enum class Visibility : uint8_t {
    Local = 0,    ///< Visible only on the node where the object resides.
    Regional = 1, ///< Visible on all nodes of the same distributed intelligent controller.
    Global = 2,   ///< Visible on every node of the factory control system.
};

/// Whether an object with visibility @p object is found by a lookup asking from @p askingScope.
constexpr bool isVisibleFrom(Visibility object, Visibility askingScope)
{
    return static_cast<uint8_t>(object) >= static_cast<uint8_t>(askingScope);
}

} // namespace dcos
