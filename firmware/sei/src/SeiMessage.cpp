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

void encodeRequest(Writer& w, const SeiMessage& m)
{
    w.u8(static_cast<uint8_t>(m.command));
    switch (m.command) {
    case SeiCommand::Identify:
    case SeiCommand::Challenge:
    case SeiCommand::Deselect:
        break;
    case SeiCommand::GetConfiguration:
        if (m.hasMac) {
            w.bytes(m.mac, sizeof m.mac);
        }
        break;
    case SeiCommand::SetNodeId:
        w.u16(m.nodeId);
        w.bytes(m.mac, sizeof m.mac);
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
    if (m.status != SeiStatus::Ok) {
        return;
    }
    switch (m.command) {
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

bool decodeRequest(Reader& r, size_t length, SeiMessage& m)
{
    switch (m.command) {
    case SeiCommand::Identify:
    case SeiCommand::Challenge:
    case SeiCommand::Deselect:
        break;
    case SeiCommand::GetConfiguration:
        // The MAC is there or not: one layout of 1 byte, one of 17.
        m.hasMac = length > 1;
        if (m.hasMac) {
            r.bytes(m.mac, sizeof m.mac);
        }
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
    if (m.status != SeiStatus::Ok) {
        return true;
    }
    switch (m.command) {
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

bool isSeiCommand(uint8_t code)
{
    switch (static_cast<SeiCommand>(code)) {
    case SeiCommand::Identify:
    case SeiCommand::Challenge:
    case SeiCommand::GetConfiguration:
    case SeiCommand::SetNodeId:
    case SeiCommand::SetBitRate:
    case SeiCommand::Restart:
    case SeiCommand::ProbeSerial:
    case SeiCommand::Select:
    case SeiCommand::Deselect:
        return true;
    }
    return false;
}

bool seiCommandNeedsMac(SeiCommand command)
{
    return command == SeiCommand::SetNodeId || command == SeiCommand::SetBitRate || command == SeiCommand::Restart;
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
        fieldsInRange = decodeRequest(r, length, m);
    }
    if (!fieldsInRange || !r.exact()) {
        return false;
    }
    out = m;
    return true;
}

} // namespace sei
