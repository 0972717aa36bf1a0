// The dual-Pentium board's shared-memory network as a link of the network
// interfaces manager (seed 9.2, 7.13): nodes 2 and 3 reach each other
// through two rings in memory both processors see and an inter-processor
// interrupt per message, so the remote primitives run between them as they
// run over CAN, and node 2 can route node 3's traffic onward.
//
// Each message of the manager goes into one slot of the ring towards the
// other node (bsp/SharedMemoryRing.hpp), and the sender raises line 2 on
// the other processor; that node's line 2 routine posts its remote agent's
// receiver task the event the manager gave at Start, and the task takes the
// messages. Physical addresses are the processors: 0 for node 2, 1 for
// node 3 (InterfaceKind::SharedMemory). docs/protocols/shared-memory.md
// says the layout.
#pragma once

#include <bsp/SharedMemoryRing.hpp>

#include <dcos/NetworkLink.hpp>

#include <stddef.h>
#include <stdint.h>

namespace bsp {

/// The memory both nodes see: 64 KiB at 15 MiB, between node 2's image and
/// node 3's half. Node 2 lays it out before node 3 starts.
struct SharedMemoryArea {
    static constexpr uintptr_t kAddress = 0x00F0'0000u;
    static constexpr uint32_t kMagic = 0x44534D4Eu; // "NMSD": laid out
    static constexpr uint32_t kVersion = 2;
    uint32_t magic;
    uint32_t version;
    SharedMemoryRing toNode3;
    SharedMemoryRing toNode2;
    /// The low half of the time-stamp counter as each node last raised the
    /// other's interrupt, written by the sender just before it does (index:
    /// the sending processor). The receiver's routine reads it to measure
    /// the inter-processor interrupt's latency, modulo 2^32: 32 bits are
    /// written in one store, where a 64-bit stamp could be read half new.
    /// Both processors' counters start at the board's reset and count the
    /// same clock.
    volatile uint32_t signalledAt[2];

    /// The area at kAddress.
    static SharedMemoryArea& at() { return *reinterpret_cast<SharedMemoryArea*>(kAddress); }
    /// Empties both rings and marks the area laid out; node 2 only, before node 3 starts.
    void layOut();
    bool laidOut() const { return magic == kMagic && version == kVersion; }
};
static_assert(sizeof(SharedMemoryArea) <= 0x1'0000, "the area fits its 64 KiB");
static_assert(offsetof(SharedMemoryArea, toNode2) == 1296 && offsetof(SharedMemoryArea, signalledAt) == 2584,
              "the layout docs/protocols/shared-memory.md gives");

/// What a link counted since it started.
struct SharedMemoryLinkStatistics {
    uint32_t sent = 0;
    uint32_t received = 0;
    uint32_t ringFull = 0;     ///< Sends refused: the other node took nothing for 64 messages.
    uint32_t notSignalled = 0; ///< Messages whose interrupt the local APIC did not deliver (the reader finds them at its next one).
    uint32_t corrupted = 0;    ///< Receives that found the ring's indices overwritten.
    /// Inter-processor interrupts taken, and their latency from the
    /// sender's stamp to this node's routine, in counts of the time-stamp
    /// counter (one per processor clock; one per emulated nanosecond under
    /// the lab's -icount): the last one, the least and the most.
    uint32_t interrupts = 0;
    uint32_t latencyLast = 0;
    uint32_t latencyMin = 0;
    uint32_t latencyMax = 0;
};

class SharedMemoryLink final : public dcos::NetworkLink {
public:
    constexpr SharedMemoryLink() = default;

    bool started() const { return started_; }
    SharedMemoryLinkStatistics statistics() const { return statistics_; }

    /// NotFound when the board's other node does not run or the area is not
    /// laid out; InvalidArgument when @p ownPhysical is not this node's
    /// processor; InstallISR's status for line 2.
    dcos::Status Start(dcos::ObjectId receiver, uint32_t receiveEvent, uint32_t ownPhysical) override;
    void Stop() override;
    /// Busy when the ring towards the other node is full or the link has
    /// not started; NotSupported for an echo; InvalidArgument for a
    /// destination that is neither the other processor nor broadcast.
    dcos::Status Send(const dcos::SystemMessage& message) override;
    /// Corrupted when the ring's indices were overwritten (nothing is taken).
    dcos::Result<bool> Receive(dcos::SystemMessage& message) override;

private:
    static void onSignal(void* context);

    dcos::ObjectId receiver_{};
    uint32_t receiveEvent_ = 0;
    uint32_t ownPhysical_ = 0;
    bool started_ = false;
    SharedMemoryLinkStatistics statistics_{};
};

/// The link the board's network runs on (SharedMemoryNetwork.cpp), for its counts.
const SharedMemoryLink& boardSharedMemoryLink();

} // namespace bsp
