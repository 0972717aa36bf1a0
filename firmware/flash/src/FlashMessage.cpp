#include <flash/FlashMessage.hpp>

#include <image/Sha256.hpp>
#include <runtime/ByteCursor.hpp>

namespace flash {

namespace {

using Writer = runtime::ByteWriter;
using Reader = runtime::ByteReader;

void writeVersion(Writer& w, const image::ImageVersion& v)
{
    w.u8(v.major);
    w.u8(v.minor);
    w.u16(v.patch);
    w.u32(v.build);
}

image::ImageVersion readVersion(Reader& r)
{
    image::ImageVersion v;
    v.major = r.u8();
    v.minor = r.u8();
    v.patch = r.u16();
    v.build = r.u32();
    return v;
}

// A status byte, then for a refused image its reason: false for a value
// out of range.
bool readStatus(Reader& r, FlashMessage& m)
{
    const uint8_t value = r.u8();
    if (value > static_cast<uint8_t>(FlashStatus::SlotInUse)) {
        return false;
    }
    m.status = static_cast<FlashStatus>(value);
    return true;
}

bool readImageError(Reader& r, FlashMessage& m)
{
    const uint8_t value = r.u8();
    if (value > static_cast<uint8_t>(image::ImageError::Downgrade)) {
        return false;
    }
    m.imageError = static_cast<image::ImageError>(value);
    return true;
}
bool slotOrNone(uint8_t value) { return value < 2 || value == 0xFF; }

} // namespace

const char* flashStatusText(FlashStatus status)
{
    switch (status) {
    case FlashStatus::Ok: return "done";
    case FlashStatus::NotAuthenticated: return "the session is not authenticated";
    case FlashStatus::AuthenticationFailed: return "authentication failed: the key is not trusted or the signature is wrong";
    case FlashStatus::ImageRefused: return "the image is refused";
    case FlashStatus::OutOfOrder: return "a block out of order";
    case FlashStatus::BadBlockCrc: return "a block's CRC does not match its bytes";
    case FlashStatus::CardError: return "the node's card cannot be read or written";
    case FlashStatus::NoTransfer: return "no transfer in progress, or not every byte has arrived";
    case FlashStatus::Malformed: return "a malformed request";
    case FlashStatus::Unsupported: return "a request the node does not serve here";
    case FlashStatus::SlotInUse:
        return "the node runs a trial image from the slot the new image needs: confirm it or restart the node first";
    }
    return "unknown status";
}

size_t FlashMessage::encode(uint8_t* out, size_t capacity) const
{
    Writer w(out, capacity);
    w.u8(static_cast<uint8_t>(type));
    w.u8(tag);
    switch (type) {
    case MessageType::Hello:
    case MessageType::End:
        break;
    case MessageType::Authenticate:
        w.bytes(keyId, sizeof keyId);
        w.bytes(signature, sizeof signature);
        break;
    case MessageType::Begin:
        w.bytes(header, sizeof header);
        break;
    case MessageType::Data:
        if (length > kMaxBlock) {
            return 0;
        }
        w.u32(sequence);
        w.u32(offset);
        w.u16(length);
        w.u32(crc);
        w.bytes(bytes, length);
        break;
    case MessageType::Restart:
        w.u8(static_cast<uint8_t>(target));
        break;
    case MessageType::HelloReply:
        w.u8(protocol);
        w.u8(static_cast<uint8_t>(mode));
        w.u16(node);
        w.u16(board);
        w.bytes(challenge, sizeof challenge);
        w.u8(confirmedSlot);
        w.u8(trial);
        w.u8(trialSlot);
        for (int slotIndex = 0; slotIndex < 2; ++slotIndex) {
            w.u8(slotHolds[slotIndex] ? 1 : 0);
            writeVersion(w, slotVersion[slotIndex]);
        }
        w.u16(maxBlock);
        w.u8(transferSlot);
        w.u32(transferOffset);
        w.bytes(transferDigest, sizeof transferDigest);
        break;
    case MessageType::AuthenticateReply:
    case MessageType::RestartReply:
    case MessageType::ErrorReply:
        w.u8(static_cast<uint8_t>(status));
        break;
    case MessageType::BeginReply:
        w.u8(static_cast<uint8_t>(status));
        w.u8(static_cast<uint8_t>(imageError));
        w.u8(slot);
        w.u32(offset);
        break;
    case MessageType::DataReply:
        w.u8(static_cast<uint8_t>(status));
        w.u32(offset);
        break;
    case MessageType::EndReply:
        w.u8(static_cast<uint8_t>(status));
        w.u8(static_cast<uint8_t>(imageError));
        break;
    }
    return w.finish();
}

bool FlashMessage::decode(const uint8_t* data, size_t length, FlashMessage& out)
{
    if (data == nullptr || length < 2) {
        return false;
    }
    Reader r(data, length);
    FlashMessage m;
    const uint8_t type = r.u8();
    m.tag = r.u8();
    uint8_t value = 0;
    switch (type) {
    case static_cast<uint8_t>(MessageType::Hello):
    case static_cast<uint8_t>(MessageType::End):
        break;
    case static_cast<uint8_t>(MessageType::Authenticate):
        r.bytes(m.keyId, sizeof m.keyId);
        r.bytes(m.signature, sizeof m.signature);
        break;
    case static_cast<uint8_t>(MessageType::Begin):
        r.bytes(m.header, sizeof m.header);
        break;
    case static_cast<uint8_t>(MessageType::Data):
        m.sequence = r.u32();
        m.offset = r.u32();
        m.length = r.u16();
        m.crc = r.u32();
        if (m.length > kMaxBlock) {
            return false;
        }
        m.bytes = r.here();
        r.skip(m.length);
        break;
    case static_cast<uint8_t>(MessageType::Restart):
        value = r.u8();
        if (value > static_cast<uint8_t>(RestartTarget::Recovery)) {
            return false;
        }
        m.target = static_cast<RestartTarget>(value);
        break;
    case static_cast<uint8_t>(MessageType::HelloReply):
        m.protocol = r.u8();
        value = r.u8();
        if (value > static_cast<uint8_t>(NodeMode::Recovery)) {
            return false;
        }
        m.mode = static_cast<NodeMode>(value);
        m.node = r.u16();
        m.board = r.u16();
        r.bytes(m.challenge, sizeof m.challenge);
        m.confirmedSlot = r.u8();
        m.trial = r.u8();
        m.trialSlot = r.u8();
        for (int slotIndex = 0; slotIndex < 2; ++slotIndex) {
            const uint8_t holds = r.u8();
            if (holds > 1) {
                return false;
            }
            m.slotHolds[slotIndex] = holds == 1;
            m.slotVersion[slotIndex] = readVersion(r);
        }
        m.maxBlock = r.u16();
        m.transferSlot = r.u8();
        m.transferOffset = r.u32();
        r.bytes(m.transferDigest, sizeof m.transferDigest);
        if (!slotOrNone(m.confirmedSlot) || !slotOrNone(m.trialSlot) || m.trial > 2 || m.maxBlock == 0 ||
            m.maxBlock > kMaxBlock || !slotOrNone(m.transferSlot)) {
            return false;
        }
        break;
    case static_cast<uint8_t>(MessageType::AuthenticateReply):
    case static_cast<uint8_t>(MessageType::RestartReply):
    case static_cast<uint8_t>(MessageType::ErrorReply):
        if (!readStatus(r, m)) {
            return false;
        }
        break;
    case static_cast<uint8_t>(MessageType::BeginReply):
        if (!readStatus(r, m) || !readImageError(r, m)) {
            return false;
        }
        m.slot = r.u8();
        m.offset = r.u32();
        if (!slotOrNone(m.slot)) {
            return false;
        }
        break;
    case static_cast<uint8_t>(MessageType::DataReply):
        if (!readStatus(r, m)) {
            return false;
        }
        m.offset = r.u32();
        break;
    case static_cast<uint8_t>(MessageType::EndReply):
        if (!readStatus(r, m) || !readImageError(r, m)) {
            return false;
        }
        break;
    default:
        return false;
    }
    if (!r.exact()) {
        return false;
    }
    m.type = static_cast<MessageType>(type);
    out = m;
    return true;
}

void authenticationDigest(uint16_t node, const uint8_t (&challenge)[kChallengeSize], uint8_t (&digest)[32])
{
    static const uint8_t kDomain[] = {'D', 'C', 'O', 'S', '-', 'F', 'L', 'A', 'S', 'H', '-', '1'};
    const uint8_t nodeBytes[2] = {static_cast<uint8_t>(node), static_cast<uint8_t>(node >> 8)};
    image::Sha256 hash;
    hash.update(kDomain, sizeof kDomain);
    hash.update(nodeBytes, sizeof nodeBytes);
    hash.update(challenge, kChallengeSize);
    hash.finish(digest);
}

} // namespace flash
