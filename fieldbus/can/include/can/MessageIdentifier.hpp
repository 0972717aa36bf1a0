// The 29-bit identifier of every DCOS frame (docs/protocols/can.md, "Identifier layout").
//
//     28      24 23            16 15            8 7             0
//     | priority |  message type  |  destination  |    source     |
//       5 bits        8 bits           8 bits          8 bits
//
// Seed 6.4 maps the priority of the requesting task onto the network
// priority, and seed 7.13 lets the network schedule transmissions globally
// by it. On CAN that is arbitration: the lowest identifier wins, bit by bit
// from the most significant. So the task priority (0 = most urgent .. 31)
// goes unchanged into the five most significant bits, and a frame of a more
// urgent task wins against every frame of a less urgent one, whatever the
// other fields hold, on every node of the bus at once.
//
// The message type comes next, so that at equal priority it decides (see
// MessageType). The destination and source CAN node numbers fill the rest:
// they are the physical addresses of seed 7.13 (logical node -> network
// address -> CAN node number). Carrying the source makes the identifier of
// every node's frames different, which CAN requires: two nodes sending the
// same identifier with different data at the same time would both win
// arbitration and then destroy each other's frame with bit errors.
// Destination 255 is the broadcast address. A source cannot be 255, but
// in the configuration protocol (docs/protocols/config.md, "Scanning"):
// there every node a scan's probe matches answers with the same frame from
// source 255, on purpose, so that any number of them are one frame, and
// the selected node answers from 255 as the one node the broadcast
// address stands for.
#pragma once

#include <can/CanFrame.hpp>
#include <can/LinkResult.hpp>
#include <can/MessageType.hpp>

#include <stdint.h>

namespace can {

class MessageIdentifier {
public:
    /// Width of the priority field: DCOS task priorities 0..31 (firmware/dcos TaskAgent.hpp).
    static constexpr unsigned kPriorityBits = 5;
    /// Width of the message type field.
    static constexpr unsigned kTypeBits = 8;
    /// Width of each CAN node number field.
    static constexpr unsigned kNodeBits = 8;

    static constexpr unsigned kSourceShift = 0;
    static constexpr unsigned kDestinationShift = kSourceShift + kNodeBits;
    static constexpr unsigned kTypeShift = kDestinationShift + kNodeBits;
    static constexpr unsigned kPriorityShift = kTypeShift + kTypeBits;

    /// The most urgent task priority; encodes as field value 0.
    static constexpr uint8_t kHighestPriority = 0;
    /// The least urgent task priority.
    static constexpr uint8_t kLowestPriority = (1u << kPriorityBits) - 1;
    /// The destination node number every node receives.
    static constexpr uint8_t kBroadcast = (1u << kNodeBits) - 1;
    /// The largest node number a node can have (and send from).
    static constexpr uint8_t kMaxNodeNumber = kBroadcast - 1;

    static constexpr uint32_t kFieldMask8 = 0xFF;
    static constexpr uint32_t kPriorityMask = (1u << kPriorityBits) - 1;

    static_assert(kPriorityShift + kPriorityBits == 29, "the fields fill exactly the 29 bits of an extended identifier");
    static_assert(kTypeBits == 8 && kNodeBits == 8, "the type and node fields are whole bytes");

    /// Priority 0, type TimeSync, node 0 to node 0; only a placeholder for LinkResult.
    constexpr MessageIdentifier() = default;

    /// Checks and packs the four fields.
    static constexpr LinkResult<MessageIdentifier> make(uint8_t priority, MessageType type, uint8_t destination,
                                                        uint8_t source)
    {
        if (priority > kLowestPriority) {
            return LinkError::InvalidPriority;
        }
        if (!isAssignedMessageType(static_cast<uint8_t>(type))) {
            return LinkError::UnassignedMessageType;
        }
        if (source == kBroadcast && type != MessageType::Configuration) {
            return LinkError::InvalidNodeNumber;
        }
        return MessageIdentifier(priority, type, destination, source);
    }

    /// Unpacks and checks a raw 29-bit identifier.
    static constexpr LinkResult<MessageIdentifier> decode(uint32_t raw)
    {
        if (raw > CanFrame::kMaxExtendedId) {
            return LinkError::InvalidIdentifier;
        }
        return make(priorityOf(raw), static_cast<MessageType>((raw >> kTypeShift) & kFieldMask8),
                    static_cast<uint8_t>((raw >> kDestinationShift) & kFieldMask8),
                    static_cast<uint8_t>((raw >> kSourceShift) & kFieldMask8));
    }

    /// The identifier of a received frame; refuses standard and remote frames,
    /// which other protocols sharing the bus may send but DCOS never does.
    static LinkResult<MessageIdentifier> fromFrame(const CanFrame& frame);

    /// The priority field of a raw identifier, without checking the rest:
    /// what a receive interrupt needs to queue a frame by priority (seed 6.4).
    static constexpr uint8_t priorityOf(uint32_t raw)
    {
        return static_cast<uint8_t>((raw >> kPriorityShift) & kPriorityMask);
    }

    /// The raw 29-bit identifier.
    constexpr uint32_t encode() const
    {
        return (static_cast<uint32_t>(priority_) << kPriorityShift)
               | (static_cast<uint32_t>(type_) << kTypeShift)
               | (static_cast<uint32_t>(destination_) << kDestinationShift)
               | (static_cast<uint32_t>(source_) << kSourceShift);
    }

    /// The identifier of the answer: same priority and type, source and
    /// destination swapped (the ISO-TP flow control of a transfer, a reply).
    /// Refused for a broadcast, which has no single node to answer.
    constexpr LinkResult<MessageIdentifier> reversed() const { return make(priority_, type_, source_, destination_); }

    constexpr uint8_t priority() const { return priority_; }
    constexpr MessageType type() const { return type_; }
    constexpr uint8_t destination() const { return destination_; }
    constexpr uint8_t source() const { return source_; }
    constexpr bool isBroadcast() const { return destination_ == kBroadcast; }

    friend constexpr bool operator==(const MessageIdentifier& a, const MessageIdentifier& b)
    {
        return a.encode() == b.encode();
    }

private:
    constexpr MessageIdentifier(uint8_t priority, MessageType type, uint8_t destination, uint8_t source)
        : priority_(priority), type_(type), destination_(destination), source_(source)
    {
    }

    uint8_t priority_ = kHighestPriority;
    MessageType type_ = MessageType::TimeSync;
    uint8_t destination_ = 0;
    uint8_t source_ = 0;
};

// The layout proves itself to the compiler: the most urgent frame any node
// can send of a less urgent priority still loses to the least urgent frame of
// a more urgent one, and every field survives a round trip.
static_assert(MessageIdentifier::kLowestPriority == 31, "DCOS has 32 task priorities");
static_assert(MessageIdentifier::make(0, MessageType::Flashing, MessageIdentifier::kBroadcast, 254).value().encode()
                  < MessageIdentifier::make(1, MessageType::TimeSync, 0, 0).value().encode(),
              "a more urgent priority wins arbitration whatever the other fields hold");
static_assert(MessageIdentifier::make(30, MessageType::Flashing, MessageIdentifier::kBroadcast, 254).value().encode()
                  < MessageIdentifier::make(31, MessageType::TimeSync, 0, 0).value().encode(),
              "priority order holds down to the least urgent priority");
static_assert(MessageIdentifier::make(31, MessageType::Flashing, 255, 254).value().encode() <= CanFrame::kMaxExtendedId,
              "the largest identifier fits 29 bits");
static_assert(MessageIdentifier::make(7, MessageType::RemoteReply, 0x12, 0x34).value().encode() == 0x07101234,
              "fields sit at their documented bit positions");
static_assert(MessageIdentifier::decode(0x07101234).value().priority() == 7
                  && MessageIdentifier::decode(0x07101234).value().type() == MessageType::RemoteReply
                  && MessageIdentifier::decode(0x07101234).value().destination() == 0x12
                  && MessageIdentifier::decode(0x07101234).value().source() == 0x34,
              "decode inverts encode");
static_assert(MessageIdentifier::make(3, MessageType::RemoteReply, 1, 2).value().encode()
                  < MessageIdentifier::make(3, MessageType::RemoteRequest, 1, 2).value().encode(),
              "at equal priority a reply wins over a request");
static_assert(MessageIdentifier::make(32, MessageType::TimeSync, 0, 0).error() == LinkError::InvalidPriority,
              "priorities above 31 are refused");
static_assert(MessageIdentifier::make(0, MessageType::TimeSync, 0, MessageIdentifier::kBroadcast).error()
                  == LinkError::InvalidNodeNumber,
              "broadcast is not a source");
static_assert(MessageIdentifier::decode(0x00000000).error() == LinkError::UnassignedMessageType,
              "type 0 is not assigned");

} // namespace can
