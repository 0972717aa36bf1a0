// Status codes returned by every DCOS service.
//
// DCOS reports errors as values, never as exceptions: the firmware is built
// with -fno-exceptions, and a control task must be able to react to a refused
// request in bounded time. Every primitive returns a Status (or a Result<T>,
// which pairs a Status with a value), and callers compare against
// Status::Ok. The numeric values are part of the wire protocol of later
// network and trap interfaces, so existing codes are never renumbered.
#pragma once

#include <stdint.h>

namespace dcos {

/// [[nodiscard]]: a refused request that nobody looks at is a fault nobody
/// handles, so the compiler reports every call whose Status is dropped; write
/// (void) before a call whose failure truly does not matter, and say why.
enum class [[nodiscard]] Status : uint8_t {
    Ok = 0,
    InvalidId = 1,        ///< The id does not name an object: bad type, index or node.
    StaleId = 2,          ///< The id named an object that has since been deleted.
    WrongType = 3,        ///< The id names an object of another type than the service needs.
    TableFull = 4,        ///< No free slot in the object table of that type.
    NoMemory = 5,         ///< A memory area (stack, buffer, heap) is exhausted.
    InvalidArgument = 6,  ///< An argument is out of its documented range.
    Timeout = 7,          ///< A wait ended because its time-out expired.
    WouldBlock = 8,       ///< A poll found the resource unavailable.
    NotOwner = 9,         ///< The caller does not own the object.
    NotPermitted = 10,    ///< The service needs super-user privilege.
    InInterrupt = 11,     ///< A blocking service was called from an interrupt handler.
    Busy = 12,            ///< The resource is in use and cannot be changed now.
    NotFound = 13,        ///< No object carries the requested name.
    AlreadyExists = 14,   ///< The name or resource is already taken.
    Corrupted = 15,       ///< An internal consistency check failed; the object is disabled.
    Deleted = 16,         ///< The object was deleted while the caller waited on it.
    Deadlock = 17,        ///< The request would deadlock the caller (e.g. re-acquiring).
    NotSupported = 18,    ///< The device or object does not implement the request.
    Remote = 19,          ///< The id names an object on another node and no network is up.
    NotOpen = 20,         ///< The device must be opened first (Read, Write, Control, Close).
    Abandoned = 21,       ///< The task holding the resource ended while the caller waited.
    Unreachable = 22,     ///< No interface or route of the network interfaces manager leads to the node.
};

/// The highest Status value assigned; a status received from another node
/// above it is refused (the values are part of the wire protocols).
constexpr uint8_t kLastStatusValue = static_cast<uint8_t>(Status::Unreachable);

/// Returns a short, stable English name for a status, for logs and the shell.
constexpr const char* statusName(Status status)
{
    switch (status) {
    case Status::Ok: return "ok";
    case Status::InvalidId: return "invalid id";
    case Status::StaleId: return "stale id";
    case Status::WrongType: return "wrong object type";
    case Status::TableFull: return "object table full";
    case Status::NoMemory: return "out of memory";
    case Status::InvalidArgument: return "invalid argument";
    case Status::Timeout: return "timed out";
    case Status::WouldBlock: return "would block";
    case Status::NotOwner: return "not owner";
    case Status::NotPermitted: return "not permitted";
    case Status::InInterrupt: return "called from interrupt";
    case Status::Busy: return "busy";
    case Status::NotFound: return "not found";
    case Status::AlreadyExists: return "already exists";
    case Status::Corrupted: return "corrupted";
    case Status::Deleted: return "deleted";
    case Status::Deadlock: return "would deadlock";
    case Status::NotSupported: return "not supported";
    case Status::Remote: return "remote object unreachable";
    case Status::Abandoned: return "holder ended";
    case Status::NotOpen: return "device not open";
    case Status::Unreachable: return "node unreachable";
    }
    return "unknown status";
}

/// A value or the Status that explains why there is none.
template <typename T>
class [[nodiscard]] Result {
public:
    constexpr Result(T value) : value_(value), status_(Status::Ok) {}
    constexpr Result(Status status) : value_(), status_(status) {}

    constexpr bool ok() const { return status_ == Status::Ok; }
    constexpr Status status() const { return status_; }
    /// The value; only meaningful when ok() is true.
    constexpr const T& value() const { return value_; }

private:
    T value_;
    Status status_;
};

} // namespace dcos
