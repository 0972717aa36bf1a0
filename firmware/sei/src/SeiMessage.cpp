#include <sei/SeiMessage.hpp>

#include <runtime/ByteCursor.hpp>

namespace sei {

namespace {

using Writer = runtime::ByteWriter;
using Reader = runtime::ByteReader;

bool readStatus(Reader& r, SeiMessage& m)
{
    const uint8_t value = r.u8();
    if (value > static_cast<uint8_t>(kSeiLastStatus)) {
        return false;
    }
    m.status = static_cast<SeiStatus>(value);
    return true;
}

// A text of one length byte and that many bytes, left in place.
bool readText(Reader& r, SeiMessage& m)
{
    m.textLength = r.u8();
    m.text = reinterpret_cast<const char*>(r.take(m.textLength));
    return m.text != nullptr || m.textLength == 0;
}

void writeText(Writer& w, const SeiMessage& m)
{
    w.u8(m.textLength);
    w.bytes(reinterpret_cast<const uint8_t*>(m.text), m.textLength);
}

// An object's name: one length byte (at most kSeiMaxName) and the bytes.
bool readName(Reader& r, const char*& name, uint8_t& length)
{
    length = r.u8();
    name = reinterpret_cast<const char*>(r.take(length));
    return length <= kSeiMaxName && (name != nullptr || length == 0);
}

void writeName(Writer& w, const char* name, uint8_t length)
{
    w.u8(length);
    w.bytes(reinterpret_cast<const uint8_t*>(name), length);
}

// A query's MAC is there or not: the bytes left after its fields are none
// or exactly a MAC (anything else leaves the reader inexact: Malformed).
void readOptionalMac(Reader& r, SeiMessage& m)
{
    m.hasMac = !r.exact();
    if (m.hasMac) {
        r.bytes(m.mac, sizeof m.mac);
    }
}

void writeOptionalMac(Writer& w, const SeiMessage& m)
{
    if (m.hasMac) {
        w.bytes(m.mac, sizeof m.mac);
    }
}

void encodeRequest(Writer& w, const SeiMessage& m)
{
    w.u8(static_cast<uint8_t>(m.command));
    switch (m.command) {
    case SeiCommand::Identify:
    case SeiCommand::Challenge:
    case SeiCommand::Deselect:
        break;
    case SeiCommand::GetConfiguration:
    case SeiCommand::NodeStatistics:
        writeOptionalMac(w, m);
        break;
    case SeiCommand::ListObjects:
        w.u8(m.objectType);
        w.u16(m.first);
        writeOptionalMac(w, m);
        break;
    case SeiCommand::FindObject:
        w.u8(m.objectType);
        writeName(w, m.name, m.nameLength);
        writeOptionalMac(w, m);
        break;
    case SeiCommand::ObjectInfo:
        w.u32(m.objectId);
        writeOptionalMac(w, m);
        break;
    case SeiCommand::Monitor:
        w.u16(m.leaseSeconds);
        w.u16(m.periodMs);
        w.u8(m.monitorFlags);
        w.u8(m.channelCount);
        for (size_t i = 0; i < m.channelCount && i < kSeiMaxMonitorChannels; ++i) {
            w.u32(m.channels[i].publisher);
            w.u8(m.channels[i].offset);
            w.u8(static_cast<uint8_t>(m.channels[i].format));
        }
        writeOptionalMac(w, m);
        break;
    case SeiCommand::SetNodeId:
        w.u16(m.nodeId);
        w.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::SetConfiguration:
        w.u16(m.nodeId);
        w.u32(m.bitRate);
        w.u8(m.flags);
        w.u16(m.lockoutSeconds);
        writeText(w, m);
        w.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::CreateTask:
        writeText(w, m);
        writeName(w, m.name, m.nameLength);
        w.u8(m.priority);
        w.u32(m.stackSize);
        w.u32(m.argument);
        w.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::StartTask:
    case SeiCommand::StopTask:
    case SeiCommand::KillTask:
    case SeiCommand::DeleteObject:
        w.u32(m.objectId);
        w.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::CreateObject:
        w.u8(m.objectType);
        writeName(w, m.name, m.nameLength);
        w.u8(m.visibility);
        w.u32(m.parameters[0]);
        w.u32(m.parameters[1]);
        w.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::AddObjects:
        w.u8(m.objectType);
        w.u16(m.count);
        w.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::ActivateBitRate:
        w.u16(m.delayMs);
        break;
    case SeiCommand::SetBitRate:
        w.u32(m.bitRate);
        w.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::Restart:
        w.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::ProbeSerial:
        w.u8(m.probeBits);
        w.u32(m.probeValue);
        break;
    case SeiCommand::Select:
        w.u32(m.serial);
        break;
    }
}

void encodeReply(Writer& w, const SeiMessage& m)
{
    w.u8(static_cast<uint8_t>(static_cast<uint8_t>(m.command) | kSeiReplyBit));
    w.u8(static_cast<uint8_t>(m.status));
    if (m.status == SeiStatus::LockedOut) {
        w.u16(m.lockoutSecondsLeft);
        return;
    }
    if (m.status == SeiStatus::KernelRefused) {
        w.u8(m.kernelStatus);
        return;
    }
    if (m.status != SeiStatus::Ok) {
        return;
    }
    switch (m.command) {
    case SeiCommand::ListObjects:
        w.u16(m.next);
        w.u8(m.entryCount);
        for (size_t i = 0; i < m.entryCount && i < kSeiMaxListEntries; ++i) {
            w.u32(m.entries[i].id);
            w.u32(m.entries[i].owner);
            writeName(w, m.entries[i].name, m.entries[i].nameLength);
        }
        break;
    case SeiCommand::FindObject:
    case SeiCommand::CreateTask:
    case SeiCommand::CreateObject:
        w.u32(m.objectId);
        break;
    case SeiCommand::ObjectInfo:
        w.u8(m.objectType);
        w.u8(m.state);
        w.u8(m.visibility);
        w.u32(m.owner);
        writeName(w, m.name, m.nameLength);
        w.u8(m.valueCount);
        for (size_t i = 0; i < m.valueCount && i < kSeiMaxValues; ++i) {
            w.u32(static_cast<uint32_t>(m.values[i]));
            w.u32(static_cast<uint32_t>(m.values[i] >> 32));
        }
        break;
    case SeiCommand::NodeStatistics:
        w.u32(static_cast<uint32_t>(m.uptimeNs));
        w.u32(static_cast<uint32_t>(m.uptimeNs >> 32));
        w.u32(m.taskSwitches);
        w.u32(m.stackFree);
        w.u8(m.tableCount);
        for (size_t i = 0; i < m.tableCount && i < kSeiMaxTables; ++i) {
            w.u8(m.tables[i].type);
            w.u16(m.tables[i].used);
            w.u16(m.tables[i].capacity);
        }
        break;
    case SeiCommand::SetConfiguration:
        w.u32(m.sequence);
        break;
    case SeiCommand::Monitor:
    case SeiCommand::StartTask:
    case SeiCommand::StopTask:
    case SeiCommand::KillTask:
    case SeiCommand::DeleteObject:
    case SeiCommand::AddObjects:
    case SeiCommand::ActivateBitRate:
        break;
    case SeiCommand::Identify:
        w.u16(m.nodeId);
        w.u8(m.canNode);
        w.u8(m.board);
        w.u32(m.serial);
        w.u8(m.protocol);
        w.u8(m.flags);
        w.u32(m.bitRate);
        w.u16(m.configuredNodeId);
        writeText(w, m);
        break;
    case SeiCommand::Challenge:
        w.bytes(m.challenge, sizeof m.challenge);
        break;
    case SeiCommand::GetConfiguration:
        w.u32(m.sequence);
        w.u16(m.nodeId);
        w.u32(m.bitRate);
        w.u8(m.flags);
        w.u16(m.lockoutSeconds);
        writeText(w, m);
        break;
    case SeiCommand::SetNodeId:
    case SeiCommand::SetBitRate:
        w.u32(m.sequence);
        break;
    case SeiCommand::Select:
        w.u16(m.nodeId);
        w.u8(m.canNode);
        break;
    case SeiCommand::Restart:
    case SeiCommand::ProbeSerial:
    case SeiCommand::Deselect:
        break;
    }
}

bool decodeRequest(Reader& r, SeiMessage& m)
{
    switch (m.command) {
    case SeiCommand::Identify:
    case SeiCommand::Challenge:
    case SeiCommand::Deselect:
        break;
    case SeiCommand::GetConfiguration:
    case SeiCommand::NodeStatistics:
        readOptionalMac(r, m);
        break;
    case SeiCommand::ListObjects:
        m.objectType = r.u8();
        m.first = r.u16();
        readOptionalMac(r, m);
        break;
    case SeiCommand::FindObject:
        m.objectType = r.u8();
        if (!readName(r, m.name, m.nameLength)) {
            return false;
        }
        readOptionalMac(r, m);
        break;
    case SeiCommand::ObjectInfo:
        m.objectId = r.u32();
        readOptionalMac(r, m);
        break;
    case SeiCommand::Monitor:
        m.leaseSeconds = r.u16();
        m.periodMs = r.u16();
        m.monitorFlags = r.u8();
        m.channelCount = r.u8();
        if (m.channelCount > kSeiMaxMonitorChannels || (m.monitorFlags & ~kSeiMonitorFlagsKnown) != 0) {
            return false;
        }
        for (size_t i = 0; i < m.channelCount; ++i) {
            m.channels[i].publisher = r.u32();
            m.channels[i].offset = r.u8();
            const uint8_t format = r.u8();
            if (format > kSeiLastSampleFormat) {
                return false;
            }
            m.channels[i].format = static_cast<SeiSampleFormat>(format);
            if (m.channels[i].offset + seiSampleSize(m.channels[i].format) > kSeiPageSize) {
                return false;
            }
        }
        readOptionalMac(r, m);
        break;
    case SeiCommand::SetConfiguration:
        m.nodeId = r.u16();
        m.bitRate = r.u32();
        m.flags = r.u8();
        m.lockoutSeconds = r.u16();
        if (!readText(r, m) || (m.flags & ~kSeiConfigurationFlagsKnown) != 0) {
            return false;
        }
        m.hasMac = true;
        r.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::CreateTask:
        if (!readText(r, m) || m.textLength > kSeiMaxName || !readName(r, m.name, m.nameLength)) {
            return false;
        }
        m.priority = r.u8();
        m.stackSize = r.u32();
        m.argument = r.u32();
        m.hasMac = true;
        r.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::StartTask:
    case SeiCommand::StopTask:
    case SeiCommand::KillTask:
    case SeiCommand::DeleteObject:
        m.objectId = r.u32();
        m.hasMac = true;
        r.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::CreateObject:
        m.objectType = r.u8();
        if (!readName(r, m.name, m.nameLength)) {
            return false;
        }
        m.visibility = r.u8();
        m.parameters[0] = r.u32();
        m.parameters[1] = r.u32();
        m.hasMac = true;
        r.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::AddObjects:
        m.objectType = r.u8();
        m.count = r.u16();
        m.hasMac = true;
        r.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::ActivateBitRate:
        m.delayMs = r.u16();
        break;
    case SeiCommand::SetNodeId:
        m.nodeId = r.u16();
        m.hasMac = true;
        r.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::SetBitRate:
        m.bitRate = r.u32();
        m.hasMac = true;
        r.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::Restart:
        m.hasMac = true;
        r.bytes(m.mac, sizeof m.mac);
        break;
    case SeiCommand::ProbeSerial:
        m.probeBits = r.u8();
        m.probeValue = r.u32();
        if (m.probeBits > kSeiSerialBits) {
            return false;
        }
        break;
    case SeiCommand::Select:
        m.serial = r.u32();
        break;
    }
    return true;
}

bool decodeReply(Reader& r, SeiMessage& m)
{
    if (!readStatus(r, m)) {
        return false;
    }
    if (m.status == SeiStatus::LockedOut) {
        m.lockoutSecondsLeft = r.u16();
        return true;
    }
    if (m.status == SeiStatus::KernelRefused) {
        m.kernelStatus = r.u8();
        return true;
    }
    if (m.status != SeiStatus::Ok) {
        return true;
    }
    switch (m.command) {
    case SeiCommand::ListObjects:
        m.next = r.u16();
        m.entryCount = r.u8();
        if (m.entryCount > kSeiMaxListEntries) {
            return false;
        }
        for (size_t i = 0; i < m.entryCount; ++i) {
            m.entries[i].id = r.u32();
            m.entries[i].owner = r.u32();
            if (!readName(r, m.entries[i].name, m.entries[i].nameLength)) {
                return false;
            }
        }
        break;
    case SeiCommand::FindObject:
    case SeiCommand::CreateTask:
    case SeiCommand::CreateObject:
        m.objectId = r.u32();
        break;
    case SeiCommand::ObjectInfo:
        m.objectType = r.u8();
        m.state = r.u8();
        m.visibility = r.u8();
        m.owner = r.u32();
        if (!readName(r, m.name, m.nameLength)) {
            return false;
        }
        m.valueCount = r.u8();
        if (m.valueCount > kSeiMaxValues) {
            return false;
        }
        for (size_t i = 0; i < m.valueCount; ++i) {
            const uint64_t low = r.u32();
            m.values[i] = low | (uint64_t{r.u32()} << 32);
        }
        break;
    case SeiCommand::NodeStatistics: {
        const uint64_t low = r.u32();
        m.uptimeNs = low | (uint64_t{r.u32()} << 32);
        m.taskSwitches = r.u32();
        m.stackFree = r.u32();
        m.tableCount = r.u8();
        if (m.tableCount > kSeiMaxTables) {
            return false;
        }
        for (size_t i = 0; i < m.tableCount; ++i) {
            m.tables[i].type = r.u8();
            m.tables[i].used = r.u16();
            m.tables[i].capacity = r.u16();
        }
        break;
    }
    case SeiCommand::SetConfiguration:
        m.sequence = r.u32();
        break;
    case SeiCommand::Monitor:
    case SeiCommand::StartTask:
    case SeiCommand::StopTask:
    case SeiCommand::KillTask:
    case SeiCommand::DeleteObject:
    case SeiCommand::AddObjects:
    case SeiCommand::ActivateBitRate:
        break;
    case SeiCommand::Identify:
        m.nodeId = r.u16();
        m.canNode = r.u8();
        m.board = r.u8();
        m.serial = r.u32();
        m.protocol = r.u8();
        m.flags = r.u8();
        m.bitRate = r.u32();
        m.configuredNodeId = r.u16();
        return readText(r, m);
    case SeiCommand::Challenge:
        r.bytes(m.challenge, sizeof m.challenge);
        break;
    case SeiCommand::GetConfiguration:
        m.sequence = r.u32();
        m.nodeId = r.u16();
        m.bitRate = r.u32();
        m.flags = r.u8();
        m.lockoutSeconds = r.u16();
        return readText(r, m);
    case SeiCommand::SetNodeId:
    case SeiCommand::SetBitRate:
        m.sequence = r.u32();
        break;
    case SeiCommand::Select:
        m.nodeId = r.u16();
        m.canNode = r.u8();
        break;
    case SeiCommand::Restart:
    case SeiCommand::ProbeSerial:
    case SeiCommand::Deselect:
        break;
    }
    return true;
}

} // namespace

namespace {

// What each command is, in one place: which need a MAC, which are queries
// (a MAC when the node's queries are closed), which every node takes from
// the broadcast address, and which are always open.
enum class CommandClass : uint8_t { Open, Query, Change, Broadcast };

struct CommandTraits {
    SeiCommand command;
    CommandClass kind;
};

constexpr CommandTraits kCommands[] = {
    {SeiCommand::Identify, CommandClass::Open},         {SeiCommand::Challenge, CommandClass::Open},
    {SeiCommand::GetConfiguration, CommandClass::Query}, {SeiCommand::ListObjects, CommandClass::Query},
    {SeiCommand::FindObject, CommandClass::Query},       {SeiCommand::ObjectInfo, CommandClass::Query},
    {SeiCommand::NodeStatistics, CommandClass::Query},   {SeiCommand::Monitor, CommandClass::Query},
    {SeiCommand::SetNodeId, CommandClass::Change},       {SeiCommand::SetBitRate, CommandClass::Change},
    {SeiCommand::Restart, CommandClass::Change},         {SeiCommand::SetConfiguration, CommandClass::Change},
    {SeiCommand::CreateTask, CommandClass::Change},      {SeiCommand::StartTask, CommandClass::Change},
    {SeiCommand::StopTask, CommandClass::Change},        {SeiCommand::KillTask, CommandClass::Change},
    {SeiCommand::CreateObject, CommandClass::Change},    {SeiCommand::DeleteObject, CommandClass::Change},
    {SeiCommand::AddObjects, CommandClass::Change},      {SeiCommand::ProbeSerial, CommandClass::Broadcast},
    {SeiCommand::Select, CommandClass::Broadcast},       {SeiCommand::Deselect, CommandClass::Broadcast},
    {SeiCommand::ActivateBitRate, CommandClass::Broadcast},
};

const CommandTraits* traitsOf(uint8_t code)
{
    for (const CommandTraits& traits : kCommands) {
        if (static_cast<uint8_t>(traits.command) == code) {
            return &traits;
        }
    }
    return nullptr;
}

bool isOfClass(SeiCommand command, CommandClass kind)
{
    const CommandTraits* traits = traitsOf(static_cast<uint8_t>(command));
    return traits != nullptr && traits->kind == kind;
}

} // namespace

bool isSeiCommand(uint8_t code)
{
    return traitsOf(code) != nullptr;
}

bool seiCommandNeedsMac(SeiCommand command)
{
    return isOfClass(command, CommandClass::Change);
}

bool seiCommandIsQuery(SeiCommand command)
{
    return isOfClass(command, CommandClass::Query);
}

bool seiCommandIsBroadcast(SeiCommand command)
{
    return isOfClass(command, CommandClass::Broadcast);
}

size_t SeiMessage::encode(uint8_t* out, size_t capacity) const
{
    Writer w(out, capacity);
    switch (kind) {
    case SeiMessageKind::Request:
        encodeRequest(w, *this);
        break;
    case SeiMessageKind::Reply:
        encodeReply(w, *this);
        break;
    case SeiMessageKind::Unreadable:
        w.u8(kSeiUnreadableCode);
        w.u8(static_cast<uint8_t>(status));
        break;
    }
    return w.finish();
}

bool SeiMessage::decode(const uint8_t* data, size_t length, SeiMessage& out)
{
    if (data == nullptr || length == 0) {
        return false;
    }
    Reader r(data, length);
    SeiMessage m;
    const uint8_t code = r.u8();
    bool fieldsInRange = false;
    if (code == kSeiUnreadableCode) {
        m.kind = SeiMessageKind::Unreadable;
        fieldsInRange = readStatus(r, m);
    } else if ((code & kSeiReplyBit) != 0) {
        const uint8_t command = static_cast<uint8_t>(code & ~kSeiReplyBit);
        if (!isSeiCommand(command)) {
            return false;
        }
        m.kind = SeiMessageKind::Reply;
        m.command = static_cast<SeiCommand>(command);
        fieldsInRange = decodeReply(r, m);
    } else {
        if (!isSeiCommand(code)) {
            return false;
        }
        m.kind = SeiMessageKind::Request;
        m.command = static_cast<SeiCommand>(code);
        fieldsInRange = decodeRequest(r, m);
    }
    if (!fieldsInRange || !r.exact()) {
        return false;
    }
    out = m;
    return true;
}

} // namespace sei
