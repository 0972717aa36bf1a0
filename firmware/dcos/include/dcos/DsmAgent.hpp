// The distributed shared memory agent's application interface (seed 7.10).
//
// Despite its name, distributed shared memory is a publisher-subscriber
// mechanism: a task creates a publisher, a 16-byte page it alone writes,
// and other tasks open subscriptions to it and read the latest page. Each
// Write gives the page a new data identifier; a reader passes the
// identifier it saw last and gets the page only when it has changed, at
// once, or after waiting for the next Write. The model is multiple readers,
// single writer, strictly consistent: a Read returns exactly the page of
// one Write, never parts of two, and always the latest one.
//
// Every primitive takes logical ids. A publisher of Global visibility is
// also published over the network at every Write, and a task of another
// node opens a subscription to it by its id and reads it with the same
// calls (docs/protocols/publications.md); the other primitives given
// another node's id answer Status::Remote.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos {

/// Bytes in a publisher's page (seed 7.10: sixteen).
constexpr size_t kDsmPageSize = 16;

/// One page of published data.
struct DsmPage {
    uint8_t bytes[kDsmPageSize];
};

static_assert(sizeof(DsmPage) == kDsmPageSize, "a page is exactly sixteen bytes");

/// The data identifier of a publisher that has not been written yet. Write
/// never hands it out, so a reader passing it waits for the first Write.
constexpr uint32_t kNoDsmData = 0;

/// The distributed shared memory agent interface object.
class DsmAgent {
public:
    /// Creates a publisher owned, and written, by the caller. Its page is
    /// all zero and carries kNoDsmData until the first Write.
    ///
    /// Fails with InvalidArgument (name longer than 15 characters), TableFull
    /// (see AddObjects) or InInterrupt. Cost O(1).
    static Result<ObjectId> Create(const char* name, Visibility visibility);

    /// Deletes a publisher the caller owns (a super user may delete any).
    ///
    /// Readers waiting in Read are woken with Status::Deleted, and every
    /// subscription to it is invalidated: Read on one then fails with
    /// Deleted, and only Close is left to do. Cost O(1) plus O(1) per
    /// waiting reader.
    static Status Delete(ObjectId publisher);

    /// Publishes @p page with a new data identifier, which it returns.
    ///
    /// Only the owner writes (NotOwner otherwise, even for a super user),
    /// which makes the publisher single-writer. An interrupt handler may
    /// write too: handlers are installed by super users and act for the
    /// system, typically for the driver that produces the data. Every reader
    /// waiting for newer data receives this page and is woken. Cost O(1)
    /// plus O(1) per waiting reader.
    static Result<uint32_t> Write(ObjectId publisher, const DsmPage& page);

    /// Opens a subscription to @p publisher for the caller, which owns it.
    ///
    /// Any task may subscribe to any publisher it has the id of. Fails with
    /// TableFull (see AddSubscribers), InInterrupt and the id errors. Cost O(1).
    ///
    /// Another node's publisher is asked for over the network first: it must
    /// be Global (NotPermitted otherwise), and its node sends its latest page
    /// at once. TableFull also when DCOS_CONFIG_REMOTE_PUBLISHERS other
    /// nodes' publishers are read already; the remote transaction's own
    /// errors (Unreachable, Busy, Remote without a network). Cost: one
    /// remote transaction and O(DCOS_CONFIG_REMOTE_PUBLISHERS).
    static Result<ObjectId> Open(ObjectId publisher);

    /// Closes a subscription the caller owns; only its owner may, so no
    /// reader can be waiting through it meanwhile. A subscription whose
    /// publisher was deleted is closed the same way. Cost O(1).
    static Status Close(ObjectId subscription);

    /// Reads the page through @p subscription when its data identifier
    /// differs from @p lastSeenDataId, and returns the new identifier.
    ///
    /// Data identifiers grow by one per Write (wrapping past 2^32 without
    /// taking kNoDsmData), so any identifier other than the last one seen is
    /// newer. When there is no newer data, kPoll fails with WouldBlock and
    /// any other @p timeoutNs waits for the next Write (Timeout when it does
    /// not come; kWaitForever for no limit). Only the subscription's owner
    /// reads (NotOwner); Deleted when the publisher is gone; InInterrupt for
    /// a wait in an interrupt handler. Cost O(1).
    static Result<uint32_t> Read(ObjectId subscription, uint32_t lastSeenDataId, DsmPage& page, uint64_t timeoutNs);

    /// Finds a publisher by name among local publishers. Fails with NotFound. Cost O(N).
    static Result<ObjectId> NameToObject(const char* name);

    /// Activates @p count more publisher slots, a multiple of eight
    /// (privileged configuration service). Cost O(count).
    static Status AddObjects(size_t count);

    /// Activates @p count more subscription slots, a multiple of eight
    /// (privileged configuration service). Cost O(count).
    static Status AddSubscribers(size_t count);

    /// Hands a publisher or a subscription the caller owns to another local
    /// task (or to the system, with the null id), which then writes or reads
    /// it and owns it for resource recovery. Only the owner may give an
    /// object away. Cost O(1).
    static Status XferOwnership(ObjectId object, ObjectId newOwner);
};

inline constexpr DsmAgent dsmAgent{};

} // namespace dcos
