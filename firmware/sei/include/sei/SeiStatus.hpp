// The status byte of every reply of the configuration protocol
// (docs/protocols/config.md, "Messages"). The values travel on the bus and
// are never renumbered; new reasons take new values.
#pragma once

#include <stdint.h>

namespace sei {

enum class SeiStatus : uint8_t {
    Ok = 0,
    Malformed = 1,       ///< The request is shorter or longer than its command's layout, or a field is out of range.
    UnknownCommand = 2,  ///< No such command.
    NoChallenge = 3,     ///< A command that needs a MAC came with no challenge outstanding.
    StaleChallenge = 4,  ///< The challenge is older than 30 s (and is used up).
    BadMac = 5,          ///< The MAC is wrong: wrong key, altered or replayed request.
    LockedOut = 6,       ///< Three wrong MACs in a row: refused for the configured time; the reply carries the seconds left.
    NoKey = 7,           ///< The node holds no configuration key: nothing can be changed over the bus.
    InvalidArgument = 8, ///< A node id outside 1 to 254, a bit rate the controller cannot make exactly.
    CardError = 9,       ///< The card could not be read or written; nothing changed.
    NotPermitted = 10,   ///< A query that needs a MAC on this node (closed queries) came without one.
    KernelRefused = 11,  ///< The kernel refused the command; the reply carries its dcos::Status.
};

/// The largest status value: a reply with a greater one does not decode.
constexpr SeiStatus kSeiLastStatus = SeiStatus::KernelRefused;

/// One line for an engineer.
const char* seiStatusText(SeiStatus status);

} // namespace sei
