// What the distributed shared memory agent (seed 7.10) offers the rest of
// the kernel: counts for the on-target tests, and its network side for the
// remote agent (docs/protocols/publications.md).
#pragma once

#include <dcos/DsmAgent.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/internal/PublicationMessage.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// What the agent's network side has done since boot.
struct DsmNetworkStatistics {
    uint32_t deferred = 0;          ///< Writes by interrupt handlers handed to the network receiver to publish.
    uint32_t received = 0;          ///< Publications taken into a remote publisher.
    uint32_t duplicates = 0;        ///< Complete publications dropped as already taken (the other bus's copy).
    uint32_t torn = 0;              ///< Parts out of turn: what was gathered on that bus was dropped.
    uint32_t unsubscribed = 0;      ///< Parts of publishers nobody on this node reads.
    uint32_t withdrawals = 0;       ///< Remote publishers their node deleted.
    uint32_t noRemotePublisher = 0; ///< Opens refused because every remote publisher slot was in use.
};

/// One remote publisher slot, for the console.
struct RemotePublisherInfo {
    bool inUse = false;
    ObjectId publisher;
    uint16_t subscriptions = 0;
    bool withdrawn = false;
    uint32_t dataId = kNoDsmData; ///< This node's count of the pages taken.
};

class DsmManager {
public:
    /// Publishers that exist.
    static size_t publisherCount();
    /// Subscriptions that are open, including those whose publisher is gone.
    static size_t subscriptionCount();

    /// A part of a publication of node @p node's publisher arrived on
    /// @p interface (the network receiver task). O(kRemotePublishers) to
    /// find the remote publisher, O(1) plus O(1) per waiting reader to take it.
    static void deliverPublication(uint8_t interface, uint16_t node, const PublicationPart& part, uint64_t nowNs);
    /// A remote Open of this node's @p publisher (the worker serving it,
    /// at the requester's priority): its data identifier, after sending
    /// its latest page again. NotPermitted when its visibility does not
    /// reach the requester, the id errors otherwise.
    static Result<uint32_t> serveRemoteOpen(ObjectId publisher, bool withinController);
    /// Publishes what interrupt handlers wrote (the network receiver task).
    static void publishDeferred();

    static DsmNetworkStatistics networkStatistics();
    /// A publisher named @p name visible from @p askingScope.
    static Result<ObjectId> publisherNameToObject(const char* name, Visibility askingScope);
    /// Remote publisher slot @p slot (0 to kRemotePublishers - 1).
    static RemotePublisherInfo remotePublisher(size_t slot);
};

/// The next data identifier after @p dataId; kNoDsmData is skipped.
/// kNoDsmData is 0, which only the wrap from 0xFFFFFFFF reaches, so the
/// carry of the increment is the skip: an ADD and an ADC on Write's fast
/// path, where GCC spells the same arithmetic in C++ as a compare and a
/// branch or a SETE and a mask.
constexpr uint32_t nextDataId(uint32_t dataId)
{
    static_assert(kNoDsmData == 0, "the carry of the increment skips kNoDsmData only if it is 0");
#if defined(__i386__) || defined(__x86_64__)
    if (!__builtin_is_constant_evaluated()) {
        asm("addl $1, %0\n\tadcl $0, %0" : "+r"(dataId) : : "cc");
        return dataId;
    }
#endif
    return dataId == 0xFFFFFFFFu ? 1u : dataId + 1;
}
static_assert(nextDataId(0xFFFFFFFFu) == 1 && nextDataId(0) == 1 && nextDataId(41) == 42);

} // namespace dcos::internal
