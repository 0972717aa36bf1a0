// The remote agent: remote transactions (seed 6.4, Fig. 6.3).
//
// The requesting side. A primitive whose id names another node's object
// reaches forward() through forwardRemote (RemoteForward.hpp). It resolves
// the node with the network interfaces manager, takes one of kRemoteCalls
// call slots, sends the request at the calling task's priority (the bus
// priority, docs/protocols/can.md) and blocks the caller on the slot. The
// watchdog wakes it every kRemoteWatchdogMs: with no word from the peer in
// that period the request is sent again, with the same transaction number;
// after kRemoteSilentPeriods silent periods in a row the caller gets
// Unreachable. A pending reply (the peer has the request and works on it,
// e.g. an Acquire that waits) counts as a word, so a long wait is kept
// alive while the peer lives and cut short when it dies.
//
// The serving side. A receiver task, the most urgent task of the node,
// takes every message from the attached links. It only sorts them: a reply
// wakes its caller, a request joins the queue of requests. It never runs
// a primitive, so an incoming request preempts a local task only through
// the worker that serves it: kRemoteWorkers worker tasks take the most
// urgent queued request, run at the requester's priority (which they
// inherit from the message, so a local task more urgent than the request
// is not preempted by it), perform it on their own stack with the agents'
// ordinary services, and reply. The served table remembers the last
// kRemoteServed requests by (interface, source, transaction number), so a
// retransmitted request is answered from it (pending, or the stored reply)
// and never executed twice. A request that waits (an Acquire with a
// time-out) is watched from this side too: its requester retransmits every
// watchdog period, and when it has not been heard for kRemoteSilentPeriods
// periods the worker stops waiting for it, so a requester that dies cannot
// hold a worker for ever.
#pragma once

#include <dcos/DsmAgent.hpp>
#include <dcos/NetworkLink.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>
#include <dcos/internal/RemoteMessage.hpp>

#include <stdint.h>

namespace dcos::internal {

/// The instructions of the last remote transaction on each side, counted
/// with the image's instruction counter (arch_x86/InstructionCounter.hpp;
/// the remote bench's counting image, docs/performance.md "Remote
/// transactions"). All 0 in an image without a counter, and until a
/// transaction has been completed or served.
struct RemoteInstructions {
    // The requesting side: the last transaction this node completed with a final reply.
    /// From the remote agent's start of the transaction (the primitive's
    /// forward to another node) to its request handed to the link, every
    /// frame of it (the first send only, when the watchdog sent it again).
    uint32_t callRequest = 0;
    /// From the start of the receive interrupt that took the final reply to
    /// the remote agent's return to the primitive.
    uint32_t callReply = 0;
    /// From the same start to the same return: the caller's whole span, the
    /// wait for the bus included. Under -icount the halted processor's
    /// time counts one per nanosecond, so this is mostly time, not work.
    uint64_t callSpan = 0;
    // The serving side: the last request this node answered.
    /// From the start of the receive interrupt that took the request's last
    /// frame to its reply handed to the link: the interrupt, the receiver
    /// task, the worker's wake, the primitive and the reply. For a request
    /// of several frames the earlier frames' interrupts and their handling
    /// by the receiver are added (see servePartsBefore).
    uint32_t serve = 0;
    /// Of serve, what the earlier frames of a request of several frames
    /// cost: each one's interrupt and the receiver's handling of it, to the
    /// end of that handling. 0 for a request of one frame.
    uint32_t servePartsBefore = 0;
};

/// What the remote agent has done since boot, for the console and the tests.
struct RemoteStatistics {
    // The requesting side.
    uint32_t requests = 0;        ///< Transactions begun.
    uint32_t retransmissions = 0; ///< Requests sent again after a silent watchdog period.
    uint32_t replies = 0;         ///< Final replies that completed a transaction.
    uint32_t pendingReplies = 0;  ///< Pending replies received (keep-alives).
    uint32_t strayReplies = 0;    ///< Replies for no waiting transaction (late, duplicated or foreign).
    uint32_t unreachable = 0;     ///< Transactions given up after the watchdog's silent periods.
    uint32_t noCallSlot = 0;      ///< Requests refused because every call slot was in use.
    // The serving side.
    uint32_t served = 0;          ///< Requests executed.
    uint32_t duplicates = 0;      ///< Retransmitted requests answered without executing them again.
    uint32_t refusedBusy = 0;     ///< Requests refused because every served entry was in use.
    uint32_t abandoned = 0;       ///< Waits ended because their requester went silent (gave up or died).
    uint32_t malformed = 0;       ///< Messages that did not decode (see RemoteMessageError).
    uint32_t sendFailures = 0;    ///< Messages a link did not take (its queue full).
    // Publications (docs/protocols/publications.md).
    uint32_t publicationsSent = 0; ///< Publications and withdrawals queued whole, counted once per link.
    uint32_t publicationParts = 0; ///< Publication frames received and decoded.
    uint32_t unknownSenders = 0;   ///< Publication frames from a physical address the tables map to no node.
    // Names (docs/protocols/remote-transactions.md, "Names").
    uint32_t namesNotFound = 0;    ///< Name queries no node answered.
    // Gateways (docs/protocols/remote-transactions.md, "Gateways").
    uint32_t routedRequests = 0;   ///< Transactions begun with a node behind a gateway, through it.
    uint32_t forwarded = 0;        ///< Routed requests this node served for another node, as a gateway.
    uint32_t unrouted = 0;         ///< Routed request or relayed publication frames dropped: their header was not heard.
    uint32_t publicationsRelayed = 0; ///< Publication frames this node passed on to another bus, as a gateway.
    // Timers owned by tasks of other nodes (docs/protocols/remote-transactions.md, "Timers").
    uint32_t alarmsNotified = 0;   ///< Alarms told to their owner on another node.
    uint32_t alarmOwnersLost = 0;  ///< Alarms whose owner was gone: the timer was deleted.
    uint32_t alarmsDropped = 0;    ///< Alarms not told: the notifier's queue was full, or no call slot was free.
    // Nodes that started again (docs/protocols/remote-transactions.md, "A node that starts again").
    uint32_t nodesStarted = 0;     ///< Other nodes' announcements that they started, heard on any interface.
    uint32_t holdsFreed = 0;       ///< Binary semaphores freed because their holder's node started again.
    uint32_t timersOfRestarted = 0; ///< Timers deleted because their owner's node started again.
    // Pools and heaps lent to nodes that share this node's memory (docs/protocols/remote-transactions.md).
    uint32_t memoryLent = 0;       ///< Buffers and segments handed to other nodes' tasks.
    uint32_t memoryReturned = 0;   ///< Of those, returned by their node.
    uint32_t memoryReclaimed = 0;  ///< Of those, returned because their node started again.
    // The flash protocol (docs/protocols/flash.md, "On CAN").
    uint32_t noFlashService = 0;   ///< Flashing frames received by an image without the flash service.
    // The instruction counts of the last transaction (the remote bench).
    RemoteInstructions instructions{};
};

/// Counters since boot. O(1).
RemoteStatistics remoteStatistics();

/// Whether the remote agent's tasks are running.
bool remoteAgentStarted();

/// One call slot's transaction, for the console's listing.
struct RemoteCallInfo {
    bool inUse = false;
    ObjectId caller;
    RemoteService service = RemoteService::SemaphoreAcquire;
    uint8_t transaction = 0;
    uint8_t interface = 0;
    uint32_t peer = 0;
};

/// The call slot @p slot (0 to kRemoteCalls - 1). O(1).
RemoteCallInfo remoteCall(size_t slot);

/// Publishes @p page, the Write of @p publisher with data identifier
/// @p dataId, on every attached link its visibility reaches (Global: all;
/// Regional: the controller's own, the shared-memory links), at bus
/// priority @p priority. Nothing when the remote agent has not started.
/// Task context; the link only queues the frames.
void sendPublication(ObjectId publisher, Visibility visibility, uint32_t dataId, const DsmPage& page,
                     uint8_t priority);
/// Tells the same links that @p publisher is deleted.
void sendWithdrawal(ObjectId publisher, Visibility visibility, uint8_t priority);
/// Asks the receiver task to publish what interrupt handlers wrote
/// (DsmManager::publishDeferred). Interrupt context.
void requestDeferredPublications();

/// Sends @p message over @p interface's link as it is (its type, priority,
/// destination, data and echo request); false when the interface has no
/// link or the link refused it (counted as a send failure). Task context.
/// The global time base sends its messages so (GlobalTime.cpp).
bool sendOnLink(uint8_t interface, const SystemMessage& message);

/// Detaches the link of @p interface if it has one; for RemoveInterface,
/// under nothing (task context).
void detachRemoteLink(uint8_t interface);

} // namespace dcos::internal
