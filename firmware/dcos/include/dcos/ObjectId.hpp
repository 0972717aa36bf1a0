// Logical object identifier (dissertation section 6.4, Fig. 6.4).
//
// Every DCOS object is named by a 32-bit logical id instead of a pointer, so
// that a service request can name an object on any node and so that a forged
// or outdated id can be detected instead of dereferenced. The layout is
//
//     31            16 15  12 11          0
//     |   node id     | type |   index    |
//
// The node id sits in the high bits so that ids sort and route by node first.
#pragma once

#include <stdint.h>

namespace dcos {

/// The kind of object an id names; the 4-bit type field of an ObjectId.
///
/// Each type is managed by one system agent (chapter 7), and each agent owns
/// one object table per type. The values travel in ids over the network, so
/// they are never renumbered; new types take the reserved values.
enum class ObjectType : uint8_t {
    None = 0,              ///< No type; only the null id carries it, so id 0 never names an object.
    Task = 1,              ///< A thread of execution (task agent, 7.6).
    Process = 2,           ///< An address space holding one or more tasks (6.4).
    Timer = 3,             ///< A virtual software timer (timer agent, 7.5).
    Device = 4,            ///< A device managed by the system agent (7.3).
    BufferPool = 5,        ///< A pool of fixed-size buffers (buffer pool agent, 7.7).
    Heap = 6,              ///< A segmented heap of variable-size segments (7.8).
    MessagePort = 7,       ///< A FIFO or priority message port (7.9).
    DsmPublisher = 8,      ///< A distributed shared memory publisher (7.10).
    DsmSubscription = 9,   ///< A subscription to a DSM publisher (7.10).
    Semaphore = 10,        ///< A location transparent semaphore (7.11).
    NetworkInterface = 11, ///< A network interface under the network manager (6.4, layer 2).
    Module = 12,           ///< A binary code module loaded by the dynamic linker (6.4, layer 2).
    Reserved13 = 13,       ///< Reserved for a future object type.
    Reserved14 = 14,       ///< Reserved for a future object type.
    Reserved15 = 15,       ///< Reserved for a future object type.
};

/// A 32-bit logical object id: 16-bit node, 4-bit type, 12-bit index.
///
/// The class is a plain value: it can be copied, compared and sent over a
/// network. It carries no guarantee that the object exists; only the owning
/// agent's ObjectTable can resolve it, and rejects it when it is forged or stale.
class ObjectId {
public:
    /// Number of bits of the node field.
    static constexpr unsigned kNodeBits = 16;
    /// Number of bits of the type field.
    static constexpr unsigned kTypeBits = 4;
    /// Number of bits of the index field; an object table has at most 2^12 slots.
    static constexpr unsigned kIndexBits = 12;
    /// Largest value the index field can hold.
    static constexpr uint16_t kMaxIndex = (1u << kIndexBits) - 1;
    /// Largest value the type field can hold.
    static constexpr uint8_t kMaxType = (1u << kTypeBits) - 1;

    /// Creates the null id, which names no object on any node.
    constexpr ObjectId() : raw_(0) {}

    /// Packs the three fields into an id.
    ///
    /// The index is masked to 12 bits; callers that take the index from
    /// untrusted input use make(), which refuses an out-of-range index
    /// instead of silently naming another object.
    constexpr ObjectId(uint16_t node, ObjectType type, uint16_t index)
        : raw_((static_cast<uint32_t>(node) << (kTypeBits + kIndexBits))
               | ((static_cast<uint32_t>(type) & kMaxType) << kIndexBits)
               | (static_cast<uint32_t>(index) & kMaxIndex))
    {
    }

    /// Reinterprets a 32-bit value received from a task or the network as an id.
    static constexpr ObjectId fromRaw(uint32_t raw) { return ObjectId(raw, RawTag{}); }

    /// Returns the null id; it has type None and therefore never names an object.
    static constexpr ObjectId null() { return ObjectId(); }

    /// Whether all three fields fit; false when the index needs more than 12 bits.
    static constexpr bool fits(uint16_t index, ObjectType type)
    {
        return index <= kMaxIndex && static_cast<uint8_t>(type) <= kMaxType;
    }

    /// The 32-bit wire representation.
    constexpr uint32_t raw() const { return raw_; }
    /// The logical address of the node holding the object.
    constexpr uint16_t node() const { return static_cast<uint16_t>(raw_ >> (kTypeBits + kIndexBits)); }
    /// The object type field.
    constexpr ObjectType type() const { return static_cast<ObjectType>((raw_ >> kIndexBits) & kMaxType); }
    /// The 12-bit index field; the owning table splits it into slot and generation.
    constexpr uint16_t index() const { return static_cast<uint16_t>(raw_ & kMaxIndex); }
    /// Whether this is the null id.
    constexpr bool isNull() const { return raw_ == 0; }

    /// Ids are equal when all 32 bits are equal.
    friend constexpr bool operator==(ObjectId a, ObjectId b) { return a.raw_ == b.raw_; }

private:
    struct RawTag {};
    constexpr ObjectId(uint32_t raw, RawTag) : raw_(raw) {}

    uint32_t raw_;
};

static_assert(sizeof(ObjectId) == 4, "an ObjectId travels as exactly 32 bits");

} // namespace dcos
