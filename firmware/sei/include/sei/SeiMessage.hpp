// The configuration protocol's messages (docs/protocols/config.md): what a
// host tool (dcos-config) and a node's system engineering interface agent
// say to each other to find the node, read what it is, and change its
// identity and configuration. A request starts with its command code; its
// reply with the code with the top bit set, then a status byte; a request
// that cannot be read at all is answered [0xFF][status]. Every number is
// little-endian. Pure code, the same on the host and in the node.
#pragma once

#include <sei/SeiStatus.hpp>

#include <stddef.h>
#include <stdint.h>

namespace sei {

constexpr uint8_t kSeiProtocolVersion = 1;
/// The MAC a request carries: the first 16 bytes of HMAC-SHA-256.
constexpr size_t kSeiMacSize = 16;
constexpr size_t kSeiChallengeSize = 16;
/// The node's configuration key (boot::ConfigurationBlock::kConfigurationKeySize).
constexpr size_t kSeiKeySize = 32;
/// The longest text a reply carries (its length is one byte): Identify's
/// version text, GetConfiguration's command line.
constexpr size_t kSeiMaxText = 255;
/// The reply code is the request's with this bit set.
constexpr uint8_t kSeiReplyBit = 0x80;
/// The code of the reply to a request that could not be read at all.
constexpr uint8_t kSeiUnreadableCode = 0xFF;
/// The bits of a serial number, which ProbeSerial compares from the top.
constexpr uint8_t kSeiSerialBits = 32;

/// Identify's flags.
constexpr uint8_t kSeiIdentifyHasKey = 1u << 0;        ///< The node holds a configuration key.
constexpr uint8_t kSeiIdentifyQueriesClosed = 1u << 1; ///< GetConfiguration needs a MAC.
constexpr uint8_t kSeiIdentifyLockedOut = 1u << 2;     ///< Locked out now.
constexpr uint8_t kSeiIdentifySelected = 1u << 3;      ///< The selected node on the broadcast address.
/// GetConfiguration's flags.
constexpr uint8_t kSeiConfigurationQueriesClosed = 1u << 0;

/// SetConfiguration's and GetConfiguration's flags.
constexpr uint8_t kSeiConfigurationFlagsKnown = kSeiConfigurationQueriesClosed;

/// The longest object name (dcos::internal::kObjectNameCapacity - 1).
constexpr size_t kSeiMaxName = 15;
/// ListObjects: the most objects one reply lists.
constexpr size_t kSeiMaxListEntries = 8;
/// ListObjects: the reply's "next" when the list is complete.
constexpr uint16_t kSeiListEnd = 0xFFFF;
/// ObjectInfo: the most figures one reply carries.
constexpr size_t kSeiMaxValues = 10;
/// NodeStatistics: the most object tables one reply describes.
constexpr size_t kSeiMaxTables = 8;
/// Monitor: the most publications one stream samples.
constexpr size_t kSeiMaxMonitorChannels = 8;
/// Monitor's flags: bit 0, the node's console output goes to the host too.
constexpr uint8_t kSeiMonitorLog = 1u << 0;
constexpr uint8_t kSeiMonitorFlagsKnown = kSeiMonitorLog;
/// CreateObject's parameters.
constexpr size_t kSeiObjectParameters = 2;
/// CreateObject of a semaphore: parameter 0 is the initial count,
/// parameter 1 these flags (none: a binary semaphore, waiters by priority).
constexpr uint32_t kSeiSemaphoreCounting = 1u << 0;
constexpr uint32_t kSeiSemaphoreInheritance = 1u << 1;
constexpr uint32_t kSeiSemaphoreFifo = 1u << 2;
constexpr uint32_t kSeiSemaphoreFlagsKnown = kSeiSemaphoreCounting | kSeiSemaphoreInheritance | kSeiSemaphoreFifo;

/// Code and status, which every reply starts with.
constexpr size_t kSeiReplyHeaderSize = 2;
/// Identify's reply without its text: node id, CAN node number, board,
/// serial number, protocol, flags, bit rate, configured node id, text length.
constexpr size_t kSeiIdentifyReplyFixedSize = kSeiReplyHeaderSize + 2 + 1 + 1 + 4 + 1 + 1 + 4 + 2 + 1;
/// SetConfiguration's request without its text: code, node id, bit rate,
/// flags, lockout seconds, text length, and its MAC.
constexpr size_t kSeiSetConfigurationFixedSize = 1 + 2 + 4 + 1 + 2 + 1 + kSeiMacSize;
/// The largest message: SetConfiguration with the longest command line
/// (Identify's reply with the longest text is 8 bytes shorter).
constexpr size_t kSeiMaxMessage = kSeiSetConfigurationFixedSize + kSeiMaxText;
static_assert(kSeiMaxMessage >= kSeiIdentifyReplyFixedSize + kSeiMaxText, "every reply fits a message");

enum class SeiCommand : uint8_t {
    Identify = 0x01,         ///< What the node is; never needs a MAC.
    Challenge = 0x02,        ///< A new challenge for the next MAC.
    GetConfiguration = 0x03, ///< The card's configuration; a MAC when the node's queries are closed.
    SetNodeId = 0x10,        ///< Writes the configured node id (MAC).
    SetBitRate = 0x11,       ///< Writes the configured CAN bit rate (MAC).
    Restart = 0x12,          ///< Restarts the node once the reply is sent (MAC).
    ProbeSerial = 0x20,      ///< Scanning: does any node's serial number begin so?
    Select = 0x21,           ///< Scanning: the node with this serial number answers on the broadcast address.
    Deselect = 0x22,         ///< Scanning: no node does any more.
    ActivateBitRate = 0x23,  ///< Scanning class: every node switches to its configured bit rate after a delay.

    // Queries of the node's objects (seed 7.14); a MAC when queries are closed.
    ListObjects = 0x04,      ///< The objects of one type, a page at a time.
    FindObject = 0x05,       ///< The id of the object of one type with this name.
    ObjectInfo = 0x06,       ///< An object's owner, name, state and figures.
    NodeStatistics = 0x07,   ///< Uptime, task switches, free stack memory, the tables' use.
    Monitor = 0x08,          ///< Start, renew or stop the stream of samples and console output to the host.

    // Changes (MAC).
    SetConfiguration = 0x13, ///< Writes the whole configuration record but its keys and serial number.
    CreateTask = 0x30,       ///< A task running an entry point the image declares.
    StartTask = 0x31,        ///< Resumes a stopped task.
    StopTask = 0x32,         ///< Suspends a task.
    KillTask = 0x33,         ///< Ends a task; what it holds is recovered.
    CreateObject = 0x34,     ///< A semaphore, message port, buffer pool, heap or publisher.
    DeleteObject = 0x35,     ///< Deletes an object of any of those types (a task: as KillTask).
    AddObjects = 0x36,       ///< Grows an agent's object table (the seed's AddObjects).
};

/// One object in a ListObjects reply.
struct SeiObjectEntry {
    uint32_t id = 0;
    /// The owning task's id, 0 for the system.
    uint32_t owner = 0;
    /// Not terminated; into the decoded buffer, and encode copies from it.
    const char* name = nullptr;
    uint8_t nameLength = 0;
};

/// One table's use in a NodeStatistics reply.
struct SeiTableUsage {
    uint8_t type = 0; ///< dcos::ObjectType.
    uint16_t used = 0;
    uint16_t capacity = 0;
};

/// What a Monitor stream samples: a publication's current page, a field of
/// it read as @p format at @p offset.
enum class SeiSampleFormat : uint8_t {
    U8 = 0,
    I8 = 1,
    U16 = 2,
    I16 = 3,
    U32 = 4,
    I32 = 5,
};
constexpr uint8_t kSeiLastSampleFormat = static_cast<uint8_t>(SeiSampleFormat::I32);
/// The bytes a sample of @p format takes in a publication's page.
constexpr uint8_t seiSampleSize(SeiSampleFormat format)
{
    return format <= SeiSampleFormat::I8 ? 1 : format <= SeiSampleFormat::I16 ? 2 : 4;
}
/// A publication's page (dcos::kDsmPageSize).
constexpr uint8_t kSeiPageSize = 16;

struct SeiMonitorChannel {
    uint32_t publisher = 0;
    uint8_t offset = 0;
    SeiSampleFormat format = SeiSampleFormat::U8;
};

/// Whether @p code is a command's request code.
bool isSeiCommand(uint8_t code);

/// Whether a request of @p command carries a MAC always (every command that
/// changes anything).
bool seiCommandNeedsMac(SeiCommand command);
/// Whether a request of @p command may carry a MAC and must when the node's
/// queries are closed (GetConfiguration, the object queries, Monitor).
bool seiCommandIsQuery(SeiCommand command);
/// Whether every node takes @p command from the broadcast address,
/// selected or not (ProbeSerial, Select, Deselect, ActivateBitRate).
bool seiCommandIsBroadcast(SeiCommand command);

/// The bits of a serial number ProbeSerial compares: the top @p bits of
/// them (0 to 32).
constexpr uint32_t seiProbeMask(uint8_t bits)
{
    return bits == 0 ? 0 : bits >= kSeiSerialBits ? ~uint32_t{0} : ~uint32_t{0} << (kSeiSerialBits - bits);
}

enum class SeiMessageKind : uint8_t {
    Request = 0,
    Reply = 1,
    Unreadable = 2, ///< [0xFF][status]: the reply to a request that could not be read at all.
};

/// One message, of any command and either direction; the fields its
/// command and kind do not use are ignored.
struct SeiMessage {
    SeiMessageKind kind = SeiMessageKind::Request;
    SeiCommand command = SeiCommand::Identify;
    /// Replies. A reply other than Ok carries nothing more, but LockedOut
    /// its seconds left.
    SeiStatus status = SeiStatus::Ok;
    uint16_t lockoutSecondsLeft = 0;

    /// Every command that changes anything: the MAC, always; the queries
    /// (seiCommandIsQuery): when hasMac.
    bool hasMac = false;
    uint8_t mac[kSeiMacSize] = {};

    /// Identify and Select replies: the node id the node runs with;
    /// GetConfiguration reply: the configured one; SetNodeId: the new one.
    uint16_t nodeId = 0;
    /// Identify and Select replies: the CAN node number the node answers as.
    uint8_t canNode = 0;
    /// Identify reply: as in an image header (1: isa486).
    uint8_t board = 0;
    /// Identify reply: the node's; Select: the one to select.
    uint32_t serial = 0;
    /// Identify reply.
    uint8_t protocol = kSeiProtocolVersion;
    /// Identify reply (kSeiIdentify*), GetConfiguration reply (kSeiConfiguration*).
    uint8_t flags = 0;
    /// Identify and GetConfiguration replies: the configured CAN bit rate;
    /// SetBitRate: the new one.
    uint32_t bitRate = 0;
    /// Identify reply: the configured node id.
    uint16_t configuredNodeId = 0;
    /// Identify reply: the version text; GetConfiguration reply and
    /// SetConfiguration request: the command line; CreateTask request: the
    /// entry point's name. Not terminated; into the decoded buffer, and encode
    /// copies from it.
    const char* text = nullptr;
    uint8_t textLength = 0;

    /// Challenge reply.
    uint8_t challenge[kSeiChallengeSize] = {};

    /// GetConfiguration reply: the configuration's; SetNodeId and
    /// SetBitRate replies: the one written.
    uint32_t sequence = 0;
    /// GetConfiguration reply: the lockout after three wrong MACs (0: 60 s).
    uint16_t lockoutSeconds = 0;

    /// ProbeSerial: the node answers when (serial & seiProbeMask(probeBits))
    /// == probeValue and its serial number is not 0.
    uint8_t probeBits = 0;
    uint32_t probeValue = 0;

    /// Replies KernelRefused: the kernel's dcos::Status.
    uint8_t kernelStatus = 0;

    /// ListObjects, FindObject, CreateObject, AddObjects requests, ObjectInfo
    /// reply: a dcos::ObjectType.
    uint8_t objectType = 0;
    /// ListObjects request: the first table index to list; reply: the
    /// index to ask for next, kSeiListEnd when the list is complete.
    uint16_t first = 0;
    uint16_t next = kSeiListEnd;
    /// ListObjects reply.
    uint8_t entryCount = 0;
    SeiObjectEntry entries[kSeiMaxListEntries] = {};
    /// ObjectInfo, StartTask, StopTask, KillTask, DeleteObject requests;
    /// FindObject, CreateTask, CreateObject replies.
    uint32_t objectId = 0;
    /// ObjectInfo reply: the owner (0 for the system) and the state
    /// (tasks: dcos::TaskState; other objects: 0).
    uint32_t owner = 0;
    uint8_t state = 0;
    /// FindObject, CreateTask, CreateObject requests, ObjectInfo reply: the
    /// object's name (CreateTask: the new task's). Not terminated; as text.
    const char* name = nullptr;
    uint8_t nameLength = 0;
    /// CreateTask request: the entry point's name is in text.
    uint8_t priority = 0;
    uint32_t stackSize = 0;
    uint32_t argument = 0;
    /// CreateObject request and ObjectInfo reply: dcos::Visibility;
    /// CreateObject request: the type's two parameters.
    uint8_t visibility = 0;
    uint32_t parameters[kSeiObjectParameters] = {};
    /// AddObjects request: how many slots to add.
    uint16_t count = 0;
    /// ObjectInfo reply: the type's figures (docs/protocols/config.md).
    uint8_t valueCount = 0;
    uint64_t values[kSeiMaxValues] = {};
    /// NodeStatistics reply.
    uint64_t uptimeNs = 0;
    uint32_t taskSwitches = 0;
    uint32_t stackFree = 0;
    uint8_t tableCount = 0;
    SeiTableUsage tables[kSeiMaxTables] = {};
    /// ActivateBitRate request: how long every node waits before it switches.
    uint16_t delayMs = 0;
    /// Monitor request: how long the stream runs unless renewed (0 stops
    /// it), how often it samples, kSeiMonitor* flags and the channels.
    uint16_t leaseSeconds = 0;
    uint16_t periodMs = 0;
    uint8_t monitorFlags = 0;
    uint8_t channelCount = 0;
    SeiMonitorChannel channels[kSeiMaxMonitorChannels] = {};

    /// Writes the message into @p out; its length, or 0 when it does not fit.
    size_t encode(uint8_t* out, size_t capacity) const;
    /// Reads a message of exactly @p length bytes; false for a wrong
    /// length, an unknown code or status, or a field out of its range.
    static bool decode(const uint8_t* data, size_t length, SeiMessage& out);
};

} // namespace sei
