#include <flash/FlashSession.hpp>

#include <boot/BootStateStore.hpp>
#include <boot/CardLayout.hpp>
#include <boot/Crc32.hpp>
#include <image/EcdsaP256.hpp>
#include <image/Sha256.hpp>

namespace flash {

namespace {

namespace card = boot::card;
using Sector = uint8_t[card::kSectorSize];

// A sector buffer: the session handles one request at a time.
Sector scratch;
uint8_t readBack[kMaxBlock];

} // namespace

FlashSession::FlashSession(FlashStore& store, const image::TrustedKey* keys, size_t keyCount,
                           const SessionIdentity& identity, const uint8_t* seed, size_t seedLength)
    : store_(store), keys_(keys), keyCount_(keyCount), identity_(identity)
{
    image::Sha256::digest(seed, seedLength, seed_);
}

bool FlashSession::slotHeader(uint8_t slot, image::ImageHeader& header)
{
    if (!store_.read(card::kSlotLba[slot], 1, scratch)) {
        return false;
    }
    const image::ImageResult<image::ImageHeader> decoded = image::ImageHeader::decode(scratch, sizeof scratch);
    if (!decoded.ok()) {
        return false;
    }
    header = decoded.value();
    return true;
}

FlashStatus FlashSession::hello(FlashMessage& reply)
{
    // A new challenge, and a new session: what was authenticated before is
    // not any more. A transfer in progress stays, to be resumed.
    ++hellos_;
    const uint8_t count[4] = {static_cast<uint8_t>(hellos_), static_cast<uint8_t>(hellos_ >> 8),
                              static_cast<uint8_t>(hellos_ >> 16), static_cast<uint8_t>(hellos_ >> 24)};
    image::Sha256 hash;
    hash.update(seed_, sizeof seed_);
    hash.update(count, sizeof count);
    hash.finish(challenge_);
    challengeFresh_ = true;
    authenticated_ = false;

    reply.protocol = kProtocolVersion;
    reply.mode = identity_.mode;
    reply.node = identity_.node;
    reply.board = static_cast<uint16_t>(identity_.board);
    for (size_t i = 0; i < kChallengeSize; ++i) {
        reply.challenge[i] = challenge_[i];
    }
    const boot::StoredBootState stored = boot::BootStateStore::read(store_);
    if (stored.present) {
        reply.confirmedSlot = stored.state.confirmedSlot;
        reply.trial = static_cast<uint8_t>(stored.state.trial);
        reply.trialSlot = stored.state.trialSlot;
    }
    for (uint8_t slot = 0; slot < card::kSlotCount; ++slot) {
        image::ImageHeader header;
        reply.slotHolds[slot] = slotHeader(slot, header);
        if (reply.slotHolds[slot]) {
            reply.slotVersion[slot] = header.version;
        }
    }
    reply.maxBlock = kMaxBlock;
    if (transferring_) {
        reply.transferSlot = slot_;
        reply.transferOffset = progress_;
        image::Sha256::digest(headerBytes_, sizeof headerBytes_, reply.transferDigest);
    }
    return FlashStatus::Ok;
}

FlashStatus FlashSession::authenticate(const FlashMessage& request)
{
    // One attempt per challenge: a recorded exchange cannot be replayed,
    // and a wrong guess costs the guesser a new Hello.
    const bool fresh = challengeFresh_;
    challengeFresh_ = false;
    authenticated_ = false;
    if (!fresh) {
        return FlashStatus::AuthenticationFailed;
    }
    const image::TrustedKey* key = image::TrustedKey::find(request.keyId, keys_, keyCount_);
    if (key == nullptr) {
        return FlashStatus::AuthenticationFailed;
    }
    uint8_t digest[32];
    authenticationDigest(identity_.node, challenge_, digest);
    if (!image::EcdsaP256::verify(key->point, digest, request.signature)) {
        return FlashStatus::AuthenticationFailed;
    }
    authenticated_ = true;
    return FlashStatus::Ok;
}

FlashStatus FlashSession::begin(const FlashMessage& request, FlashMessage& reply)
{
    const boot::StoredBootState stored = boot::BootStateStore::read(store_);
    if (!stored.readable) {
        return FlashStatus::CardError;
    }
    const uint8_t confirmed = stored.present ? stored.state.confirmedSlot : boot::BootState::kNoSlot;
    image::ImageVersion installed;
    image::ImagePolicy policy = image::ImagePolicy::forBoard(identity_.board);
    if (identity_.memoryEnd < policy.memoryEnd) {
        policy.memoryEnd = identity_.memoryEnd;
    }
    image::ImageHeader current;
    if (confirmed != boot::BootState::kNoSlot && slotHeader(confirmed, current)) {
        installed = current.version;
        policy.installed = &installed;
    }
    const image::ImageResult<image::ImageHeader> decoded =
        image::ImageHeader::decode(request.header, sizeof request.header);
    if (!decoded.ok()) {
        reply.imageError = decoded.error();
        return FlashStatus::ImageRefused;
    }
    const image::ImageResult<image::ImageHeader> checked = image::ImageVerifier::checkHeader(
        request.header, sizeof request.header, uint64_t{image::ImageHeader::kSize} + decoded.value().payloadSize,
        keys_, keyCount_, policy);
    if (!checked.ok()) {
        reply.imageError = checked.error();
        return FlashStatus::ImageRefused;
    }
    const uint8_t slot = confirmed == 0 ? 1 : 0;
    reply.slot = slot;
    if (slot == identity_.runningSlot) {
        // The node runs an image on trial from this slot: writing over it
        // would take the image the node must confirm, or revert from.
        return FlashStatus::SlotInUse;
    }
    if (transferring_ && slot == slot_ && __builtin_memcmp(headerBytes_, request.header, sizeof headerBytes_) == 0) {
        reply.offset = progress_; // The same image again: resume.
        return FlashStatus::Ok;
    }
    // A new transfer into the slot. A trial the slot held is dropped first,
    // so that a half-written image is never pending.
    if (stored.present && stored.state.trial != boot::TrialState::None && stored.state.trialSlot == slot) {
        boot::BootState cleared = stored.state;
        cleared.trial = boot::TrialState::None;
        cleared.trialSlot = boot::BootState::kNoSlot;
        if (!boot::BootStateStore::writeNext(store_, stored, cleared)) {
            return FlashStatus::CardError;
        }
    }
    for (size_t i = 0; i < sizeof scratch; ++i) {
        scratch[i] = i < sizeof request.header ? request.header[i] : 0;
    }
    if (!store_.write(card::kSlotLba[slot], 1, scratch)) {
        transferring_ = false;
        return FlashStatus::CardError;
    }
    for (size_t i = 0; i < sizeof headerBytes_; ++i) {
        headerBytes_[i] = request.header[i];
    }
    header_ = checked.value();
    slot_ = slot;
    progress_ = 0;
    sequence_ = 0;
    transferring_ = true;
    transferComplete_ = false;
    reply.offset = 0;
    return FlashStatus::Ok;
}

FlashStatus FlashSession::data(const FlashMessage& request, FlashMessage& reply)
{
    reply.offset = progress_;
    if (!transferring_) {
        return FlashStatus::NoTransfer;
    }
    if (request.offset != progress_ || request.sequence != sequence_) {
        return FlashStatus::OutOfOrder;
    }
    const uint32_t remaining = header_.payloadSize - progress_;
    // Whole sectors, except the payload's last block.
    if (request.length == 0 || request.length > remaining ||
        (request.length % card::kSectorSize != 0 && request.length != remaining)) {
        return FlashStatus::Malformed;
    }
    if (boot::crc32(request.bytes, request.length) != request.crc) {
        return FlashStatus::BadBlockCrc;
    }
    const uint32_t lba = card::kSlotLba[slot_] + 1 + progress_ / card::kSectorSize;
    const uint32_t whole = request.length / card::kSectorSize;
    const uint32_t tail = request.length % card::kSectorSize;
    if (whole != 0 && !store_.write(lba, whole, request.bytes)) {
        return FlashStatus::CardError;
    }
    if (tail != 0) {
        for (size_t i = 0; i < sizeof scratch; ++i) {
            scratch[i] = i < tail ? request.bytes[whole * card::kSectorSize + i] : 0;
        }
        if (!store_.write(lba + whole, 1, scratch)) {
            return FlashStatus::CardError;
        }
    }
    progress_ += request.length;
    ++sequence_;
    reply.offset = progress_;
    return FlashStatus::Ok;
}

FlashStatus FlashSession::requestRecovery()
{
    const boot::StoredBootState stored = boot::BootStateStore::read(store_);
    if (!stored.readable) {
        return FlashStatus::CardError;
    }
    if (stored.present && stored.state.recoveryRequested) {
        return FlashStatus::Ok;
    }
    boot::BootState next = stored.state;
    next.recoveryRequested = true;
    return boot::BootStateStore::writeNext(store_, stored, next) ? FlashStatus::Ok : FlashStatus::CardError;
}

FlashStatus FlashSession::end(FlashMessage& reply)
{
    if (!transferring_ && transferComplete_) {
        return FlashStatus::Ok; // A repeated End: its reply was lost.
    }
    if (!transferring_ || progress_ != header_.payloadSize) {
        return FlashStatus::NoTransfer;
    }
    // What is on the card counts, not what was sent: read it back.
    image::Sha256 hash;
    for (uint32_t done = 0; done < header_.payloadSize;) {
        const uint32_t chunk = header_.payloadSize - done < kMaxBlock ? header_.payloadSize - done : kMaxBlock;
        const uint32_t sectors = (chunk + card::kSectorSize - 1) / card::kSectorSize;
        if (!store_.read(card::kSlotLba[slot_] + 1 + done / card::kSectorSize, sectors, readBack)) {
            return FlashStatus::CardError;
        }
        hash.update(readBack, chunk);
        done += chunk;
    }
    uint8_t digest[image::ImageHeader::kDigestSize];
    hash.finish(digest);
    const image::ImageError payload = image::ImageVerifier::checkPayloadDigest(header_, digest);
    if (payload != image::ImageError::Ok) {
        reply.imageError = payload;
        transferring_ = false;
        return FlashStatus::ImageRefused;
    }
    const boot::StoredBootState stored = boot::BootStateStore::read(store_);
    if (!stored.readable) {
        return FlashStatus::CardError;
    }
    boot::BootState pending = stored.state;
    pending.trialSlot = slot_;
    pending.trial = boot::TrialState::Pending;
    if (!boot::BootStateStore::writeNext(store_, stored, pending)) {
        return FlashStatus::CardError;
    }
    transferring_ = false;
    transferComplete_ = true;
    return FlashStatus::Ok;
}

size_t FlashSession::handle(const uint8_t* request, size_t length, uint8_t* replyBytes, size_t capacity)
{
    FlashMessage message;
    FlashMessage reply;
    if (!FlashMessage::decode(request, length, message) || static_cast<uint8_t>(message.type) >= 0x80) {
        reply.type = MessageType::ErrorReply;
        reply.tag = length >= 2 ? request[1] : 0;
        reply.status = FlashStatus::Malformed;
        return reply.encode(replyBytes, capacity);
    }
    reply.tag = message.tag;
    reply.type = static_cast<MessageType>(static_cast<uint8_t>(message.type) | 0x80);
    switch (message.type) {
    case MessageType::Hello:
        reply.status = hello(reply);
        break;
    case MessageType::Authenticate:
        reply.status = authenticate(message);
        break;
    case MessageType::Begin:
        reply.status = authenticated_ ? begin(message, reply) : FlashStatus::NotAuthenticated;
        break;
    case MessageType::Data:
        reply.offset = progress_;
        reply.status = authenticated_ ? data(message, reply) : FlashStatus::NotAuthenticated;
        break;
    case MessageType::End:
        reply.status = authenticated_ ? end(reply) : FlashStatus::NotAuthenticated;
        break;
    case MessageType::Restart:
        if (!authenticated_) {
            reply.status = FlashStatus::NotAuthenticated;
        } else {
            reply.status = message.target == RestartTarget::Recovery ? requestRecovery() : FlashStatus::Ok;
            if (reply.status == FlashStatus::Ok) {
                restartRequested_ = true;
                restartTarget_ = message.target;
            }
        }
        break;
    default:
        reply.status = FlashStatus::Malformed;
        break;
    }
    return reply.encode(replyBytes, capacity);
}

} // namespace flash
