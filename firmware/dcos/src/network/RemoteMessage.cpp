// The remote transaction messages' encoder and decoder
// (docs/protocols/remote-transactions.md). Pure code: no kernel state.
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/RemoteMessage.hpp>

namespace dcos::internal {

namespace {

constexpr uint64_t kNanosecondsPerMillisecond = 1'000'000;

void putBig16(uint8_t* at, uint16_t value)
{
    at[0] = static_cast<uint8_t>(value >> 8);
    at[1] = static_cast<uint8_t>(value);
}

void putBig32(uint8_t* at, uint32_t value)
{
    at[0] = static_cast<uint8_t>(value >> 24);
    at[1] = static_cast<uint8_t>(value >> 16);
    at[2] = static_cast<uint8_t>(value >> 8);
    at[3] = static_cast<uint8_t>(value);
}

uint16_t getBig16(const uint8_t* at) { return static_cast<uint16_t>((at[0] << 8) | at[1]); }

uint32_t getBig32(const uint8_t* at)
{
    return (uint32_t{at[0]} << 24) | (uint32_t{at[1]} << 16) | (uint32_t{at[2]} << 8) | at[3];
}

bool isService(uint8_t value) { return value >= 1 && value <= kLastRemoteService; }

} // namespace

const char* remoteServiceName(RemoteService service)
{
    switch (service) {
    case RemoteService::SemaphoreAcquire: return "acquire";
    case RemoteService::SemaphoreRelease: return "release";
    case RemoteService::SemaphoreGetCount: return "count";
    case RemoteService::PostEvent: return "post";
    case RemoteService::SendSignal: return "signal";
    case RemoteService::TaskGetState: return "state";
    case RemoteService::TaskGetPriority: return "priority";
    case RemoteService::SemaphoreGetHolder: return "holder";
    case RemoteService::DsmOpen: return "dsm-open";
    case RemoteService::NameToObject: return "name";
    case RemoteService::PortSend: return "port-send";
    case RemoteService::HeldAcquire: return "held-acquire";
    case RemoteService::HeldRelease: return "held-release";
    case RemoteService::TimerSetAlarm: return "set-alarm";
    case RemoteService::TimerCancelAlarm: return "cancel-alarm";
    case RemoteService::PoolAllocate: return "pool-allocate";
    case RemoteService::PoolReturn: return "pool-return";
    case RemoteService::HeapAllocate: return "heap-allocate";
    case RemoteService::HeapReturn: return "heap-return";
    }
    return "?";
}

const char* remoteMessageErrorName(RemoteMessageError error)
{
    switch (error) {
    case RemoteMessageError::None: return "none";
    case RemoteMessageError::WrongLength: return "wrong length";
    case RemoteMessageError::UnknownService: return "unknown service";
    case RemoteMessageError::NullObject: return "null object";
    case RemoteMessageError::UnknownStatus: return "unknown status";
    case RemoteMessageError::ReservedBits: return "reserved bits set";
    case RemoteMessageError::UnknownNode: return "unknown node";
    }
    return "?";
}

void encodeNodeStarted(const NodeStarted& announcement, uint8_t (&bytes)[kRemoteMessageBytes])
{
    __builtin_memset(bytes, 0, kRemoteMessageBytes);
    bytes[0] = static_cast<uint8_t>(announcement.node >> 8);
    bytes[1] = static_cast<uint8_t>(announcement.node);
}

RemoteMessageError decodeNodeStarted(const uint8_t* bytes, size_t length, NodeStarted& announcement)
{
    if (length != kRemoteMessageBytes) {
        return RemoteMessageError::WrongLength;
    }
    for (size_t i = 2; i < kRemoteMessageBytes; ++i) {
        if (bytes[i] != 0) {
            return RemoteMessageError::ReservedBits;
        }
    }
    const uint16_t node = static_cast<uint16_t>((bytes[0] << 8) | bytes[1]);
    if (node == 0 || node == 0xFFFF) {
        return RemoteMessageError::UnknownNode;
    }
    announcement.node = node;
    return RemoteMessageError::None;
}

uint32_t remoteTimeoutMs(uint64_t timeoutNs)
{
    if (timeoutNs == kWaitForever) {
        return kRemoteForever;
    }
    const uint64_t ms = timeoutNs / kNanosecondsPerMillisecond + (timeoutNs % kNanosecondsPerMillisecond != 0);
    return ms >= kRemoteForever ? kRemoteForever - 1 : static_cast<uint32_t>(ms);
}

uint64_t remoteTimeoutNs(uint32_t timeoutMs)
{
    return timeoutMs == kRemoteForever ? kWaitForever : uint64_t{timeoutMs} * kNanosecondsPerMillisecond;
}

bool isStatusValue(uint8_t value) { return value <= kLastStatusValue; }

void encodeRequest(const RemoteRequest& request, uint8_t (&bytes)[kRemoteMessageBytes])
{
    bytes[0] = static_cast<uint8_t>(request.service);
    bytes[1] = request.transaction;
    putBig16(bytes + 2, request.object);
    putBig32(bytes + 4, request.argument);
}

void encodeReply(const RemoteReply& reply, uint8_t (&bytes)[kRemoteMessageBytes])
{
    bytes[0] = static_cast<uint8_t>(reply.service);
    bytes[1] = reply.transaction;
    bytes[2] = static_cast<uint8_t>(reply.status);
    bytes[3] = reply.pending ? kReplyPending : 0;
    putBig32(bytes + 4, reply.value);
}

RemoteMessageError decodeRequest(const uint8_t* bytes, size_t length, RemoteRequest& request)
{
    if (length != kRemoteMessageBytes) {
        return RemoteMessageError::WrongLength;
    }
    if (!isService(bytes[0])) {
        return RemoteMessageError::UnknownService;
    }
    const uint16_t object = getBig16(bytes + 2);
    if (object == 0) {
        return RemoteMessageError::NullObject;
    }
    request.service = static_cast<RemoteService>(bytes[0]);
    request.transaction = bytes[1];
    request.object = object;
    request.argument = getBig32(bytes + 4);
    return RemoteMessageError::None;
}

RemoteMessageError decodeReply(const uint8_t* bytes, size_t length, RemoteReply& reply)
{
    if (length != kRemoteMessageBytes) {
        return RemoteMessageError::WrongLength;
    }
    if (!isService(bytes[0])) {
        return RemoteMessageError::UnknownService;
    }
    if (!isStatusValue(bytes[2])) {
        return RemoteMessageError::UnknownStatus;
    }
    if ((bytes[3] & ~kReplyFlagsDefined) != 0) {
        return RemoteMessageError::ReservedBits;
    }
    reply.service = static_cast<RemoteService>(bytes[0]);
    reply.transaction = bytes[1];
    reply.status = static_cast<Status>(bytes[2]);
    reply.pending = (bytes[3] & kReplyPending) != 0;
    reply.value = getBig32(bytes + 4);
    return RemoteMessageError::None;
}

// ---- name queries -----------------------------------------------------------

namespace {

constexpr uint8_t kNamePartShift = 6;
constexpr uint8_t kNameReservedMask = 0x30;
constexpr uint8_t kNameTypeMask = 0x0F;
constexpr size_t kNameBytesPerPart = 6;
constexpr size_t kLastPartNameBytes = kNameQueryNameBytes - 2 * kNameBytesPerPart;

} // namespace

bool isNamedObjectType(uint8_t type)
{
    switch (static_cast<ObjectType>(type)) {
    case ObjectType::Task:
    case ObjectType::Timer:
    case ObjectType::Device:
    case ObjectType::BufferPool:
    case ObjectType::Heap:
    case ObjectType::MessagePort:
    case ObjectType::DsmPublisher:
    case ObjectType::Semaphore: return true;
    default: return false;
    }
}

const char* nameQueryErrorName(NameQueryError error)
{
    switch (error) {
    case NameQueryError::None: return "none";
    case NameQueryError::WrongLength: return "wrong length";
    case NameQueryError::ReservedBits: return "reserved bits set";
    case NameQueryError::BadType: return "no such object type";
    }
    return "?";
}

void encodeNameQuery(uint8_t type, uint8_t transaction, const char* name,
                     uint8_t (&frames)[kNameQueryFrames][kRemoteMessageBytes], uint8_t relays)
{
    char padded[kNameQueryNameBytes]{};
    for (size_t i = 0; i + 1 < kNameQueryNameBytes && name[i] != '\0'; ++i) {
        padded[i] = name[i];
    }
    for (size_t part = 0; part < kNameQueryFrames; ++part) {
        uint8_t* frame = frames[part];
        frame[0] = static_cast<uint8_t>((part << kNamePartShift) | (type & kNameTypeMask));
        frame[1] = transaction;
        const size_t count = part + 1 < kNameQueryFrames ? kNameBytesPerPart : kLastPartNameBytes;
        for (size_t i = 0; i < kNameBytesPerPart; ++i) {
            frame[2 + i] = i < count ? static_cast<uint8_t>(padded[part * kNameBytesPerPart + i]) : 0;
        }
    }
    frames[kNameQueryFrames - 1][2 + kLastPartNameBytes] = relays < kNameRelays ? relays : kNameRelays;
}

NameQueryError decodeNameQueryPart(const uint8_t* bytes, size_t length, NameQueryPart& part)
{
    if (length != kRemoteMessageBytes) {
        return NameQueryError::WrongLength;
    }
    const uint8_t number = bytes[0] >> kNamePartShift;
    if (number >= kNameQueryFrames || (bytes[0] & kNameReservedMask) != 0 ||
        (number == kNameQueryFrames - 1 && (bytes[6] > kNameRelays || bytes[7] != 0))) {
        return NameQueryError::ReservedBits;
    }
    const uint8_t type = bytes[0] & kNameTypeMask;
    if (!isNamedObjectType(type)) {
        return NameQueryError::BadType;
    }
    part = NameQueryPart{};
    part.part = number;
    part.type = type;
    part.transaction = bytes[1];
    __builtin_memcpy(part.bytes, bytes + 2, kNameBytesPerPart);
    if (number == kNameQueryFrames - 1) {
        // Byte 6 is the relays left, not a name byte: the name ends at byte 5.
        part.relays = bytes[2 + kLastPartNameBytes];
        part.bytes[kLastPartNameBytes] = 0;
    }
    return NameQueryError::None;
}

namespace {

constexpr uint8_t kContinuationFlag = 0x80;
constexpr uint8_t kContinuationPartShift = 4;
constexpr uint8_t kContinuationReservedBit = 0x40;
constexpr uint8_t kSlotMask = 0x0F;
// Message bytes in part 0 (request bytes 5-7), part 1 and part 2.
constexpr size_t kPortSendBytes[kPortSendFrames] = {3, 7, 6};
// A held acquire's continuation is part number 3, which no port send has,
// so each continuation says what it belongs to; its bytes 1-4 are the
// holder, 5-7 zero.
constexpr uint8_t kHeldPart = 3;
constexpr size_t kHeldPartBytes = 7;
static_assert(kPortSendBytes[0] + kPortSendBytes[1] + kPortSendBytes[2] == kPortMessageBytes);

} // namespace

namespace {

// A port send's layout with another service: an alarm's.
void encodeSixteenBytes(RemoteService service, const PortSendRequest& request,
                        uint8_t (&frames)[kPortSendFrames][kRemoteMessageBytes], uint8_t (&lengths)[kPortSendFrames])
{
    encodePortSend(request, frames, lengths);
    frames[0][0] = static_cast<uint8_t>(service);
}

constexpr uint8_t kAlarmKindMask = 0x03;
constexpr uint8_t kAlarmSignalFlag = 0x10;

void putWord(uint8_t* to, uint32_t value)
{
    to[0] = static_cast<uint8_t>(value >> 24);
    to[1] = static_cast<uint8_t>(value >> 16);
    to[2] = static_cast<uint8_t>(value >> 8);
    to[3] = static_cast<uint8_t>(value);
}

uint32_t word(const uint8_t* from)
{
    return (uint32_t{from[0]} << 24) | (uint32_t{from[1]} << 16) | (uint32_t{from[2]} << 8) | from[3];
}

} // namespace

void encodeAlarm(const AlarmRequest& request, uint8_t (&frames)[kAlarmFrames][kRemoteMessageBytes],
                 uint8_t (&lengths)[kAlarmFrames])
{
    PortSendRequest shaped;
    shaped.transaction = request.transaction;
    shaped.object = request.object;
    shaped.priority = static_cast<int8_t>(static_cast<uint8_t>(request.kind) | (request.signal ? kAlarmSignalFlag : 0));
    putWord(shaped.message, request.owner);
    putWord(shaped.message + 4, request.value);
    putWord(shaped.message + 8, static_cast<uint32_t>(request.timeNs >> 32));
    putWord(shaped.message + 12, static_cast<uint32_t>(request.timeNs));
    encodeSixteenBytes(RemoteService::TimerSetAlarm, shaped, frames, lengths);
}

void encodePortSend(const PortSendRequest& request, uint8_t (&frames)[kPortSendFrames][kRemoteMessageBytes],
                    uint8_t (&lengths)[kPortSendFrames])
{
    RemoteRequest first;
    first.service = RemoteService::PortSend;
    first.transaction = request.transaction;
    first.object = request.object;
    first.argument = (uint32_t{static_cast<uint8_t>(request.priority)} << 24) |
                     (uint32_t{request.message[0]} << 16) | (uint32_t{request.message[1]} << 8) | request.message[2];
    encodeRequest(first, frames[0]);
    lengths[0] = kRemoteMessageBytes;
    size_t from = kPortSendBytes[0];
    for (size_t part = 1; part < kPortSendFrames; ++part) {
        frames[part][0] = static_cast<uint8_t>(kContinuationFlag | (part << kContinuationPartShift) |
                                               (request.transaction & kSlotMask));
        __builtin_memcpy(frames[part] + 1, request.message + from, kPortSendBytes[part]);
        lengths[part] = static_cast<uint8_t>(1 + kPortSendBytes[part]);
        from += kPortSendBytes[part];
    }
    frames[2][7] = 0; // Not sent: part 2 is seven bytes.
}

void encodeHeldAcquire(const HeldAcquireRequest& request,
                       uint8_t (&frames)[kHeldAcquireFrames][kRemoteMessageBytes])
{
    RemoteRequest first;
    first.service = RemoteService::HeldAcquire;
    first.transaction = request.transaction;
    first.object = request.object;
    first.argument = request.timeoutMs;
    encodeRequest(first, frames[0]);
    frames[1][0] = static_cast<uint8_t>(kContinuationFlag | (kHeldPart << kContinuationPartShift) |
                                        (request.transaction & kSlotMask));
    frames[1][1] = static_cast<uint8_t>(request.holder >> 24);
    frames[1][2] = static_cast<uint8_t>(request.holder >> 16);
    frames[1][3] = static_cast<uint8_t>(request.holder >> 8);
    frames[1][4] = static_cast<uint8_t>(request.holder);
    frames[1][5] = 0;
    frames[1][6] = 0;
    frames[1][7] = 0;
}

RemoteMessageError decodeContinuation(const uint8_t* bytes, size_t length, Continuation& part)
{
    if (!isContinuation(bytes, length) || (bytes[0] & kContinuationReservedBit) != 0) {
        return RemoteMessageError::UnknownService;
    }
    const uint8_t number = (bytes[0] >> kContinuationPartShift) & 0x3;
    if (number == 0) {
        return RemoteMessageError::UnknownService;
    }
    const size_t count = number == kHeldPart ? kHeldPartBytes : kPortSendBytes[number];
    if (length != 1 + count) {
        return RemoteMessageError::WrongLength;
    }
    if (number == kHeldPart && (bytes[5] | bytes[6] | bytes[7]) != 0) {
        return RemoteMessageError::ReservedBits;
    }
    part.part = number;
    part.slot = bytes[0] & kSlotMask;
    part.count = static_cast<uint8_t>(count);
    __builtin_memset(part.bytes, 0, sizeof part.bytes);
    __builtin_memcpy(part.bytes, bytes + 1, part.count);
    return RemoteMessageError::None;
}

void encodeRouteHeader(const RouteHeader& header, uint8_t (&bytes)[kRouteHeaderBytes])
{
    bytes[0] = static_cast<uint8_t>(0xC0 | (header.hopsLeft & 0x0F));
    bytes[1] = header.transaction;
    bytes[2] = static_cast<uint8_t>(header.destination >> 8);
    bytes[3] = static_cast<uint8_t>(header.destination);
}

RemoteMessageError decodeRouteHeader(const uint8_t* bytes, size_t length, RouteHeader& header)
{
    if (!isRouteHeader(bytes, length)) {
        return RemoteMessageError::ReservedBits;
    }
    if (length != kRouteHeaderBytes) {
        return RemoteMessageError::WrongLength;
    }
    const uint8_t hops = bytes[0] & 0x0F;
    if ((bytes[0] & 0x30) != 0 || hops == 0 || hops > kRouteHops) {
        return RemoteMessageError::ReservedBits;
    }
    header.hopsLeft = hops;
    header.transaction = bytes[1];
    header.destination = static_cast<uint16_t>((bytes[2] << 8) | bytes[3]);
    return RemoteMessageError::None;
}

ContinuedRequestAssembler::Outcome ContinuedRequestAssembler::start(const RemoteRequest& first)
{
    next_ = 0;
    switch (first.service) {
    case RemoteService::PortSend:
    case RemoteService::TimerSetAlarm: next_ = 1; break;
    case RemoteService::HeldAcquire: next_ = kHeldPart; break;
    default: return Outcome::Dropped;
    }
    first_ = first;
    __builtin_memset(bytes_, 0, sizeof bytes_);
    return Outcome::Started;
}

ContinuedRequestAssembler::Outcome ContinuedRequestAssembler::take(const Continuation& part)
{
    if (next_ == 0 || part.part != next_ || part.slot != (first_.transaction & kSlotMask)) {
        next_ = 0;
        return Outcome::Dropped;
    }
    const size_t from = part.part == 2 ? kPortSendBytes[1] : 0;
    __builtin_memcpy(bytes_ + from, part.bytes, part.count);
    if (part.part == 1) {
        ++next_;
        return Outcome::Taken;
    }
    next_ = 0;
    return Outcome::Complete;
}

PortSendRequest ContinuedRequestAssembler::portSend() const
{
    PortSendRequest request;
    request.transaction = first_.transaction;
    request.object = first_.object;
    request.priority = static_cast<int8_t>(first_.argument >> 24);
    request.message[0] = static_cast<uint8_t>(first_.argument >> 16);
    request.message[1] = static_cast<uint8_t>(first_.argument >> 8);
    request.message[2] = static_cast<uint8_t>(first_.argument);
    __builtin_memcpy(request.message + kPortSendBytes[0], bytes_, kPortMessageBytes - kPortSendBytes[0]);
    return request;
}

bool decodeAlarmRecord(uint8_t flags, const uint8_t (&record)[kPortMessageBytes], AlarmRequest& out)
{
    const uint8_t kind = flags & kAlarmKindMask;
    if ((flags & ~(kAlarmKindMask | kAlarmSignalFlag)) != 0 || kind == 0) {
        return false;
    }
    out.kind = static_cast<RemoteAlarmKind>(kind);
    out.signal = (flags & kAlarmSignalFlag) != 0;
    out.owner = word(record);
    out.value = word(record + 4);
    out.timeNs = (uint64_t{word(record + 8)} << 32) | word(record + 12);
    return true;
}

bool ContinuedRequestAssembler::alarm(AlarmRequest& out) const
{
    const PortSendRequest shaped = portSend();
    out.transaction = shaped.transaction;
    out.object = shaped.object;
    return decodeAlarmRecord(static_cast<uint8_t>(shaped.priority), shaped.message, out);
}

HeldAcquireRequest ContinuedRequestAssembler::heldAcquire() const
{
    HeldAcquireRequest request;
    request.transaction = first_.transaction;
    request.object = first_.object;
    request.timeoutMs = first_.argument;
    request.holder = (uint32_t{bytes_[0]} << 24) | (uint32_t{bytes_[1]} << 16) | (uint32_t{bytes_[2]} << 8) |
                     bytes_[3];
    return request;
}

bool NameQueryAssembler::take(const NameQueryPart& part)
{
    if (part.part == 0) {
        next_ = 1;
        type_ = part.type;
        transaction_ = part.transaction;
        __builtin_memcpy(name_, part.bytes, kNameBytesPerPart);
        return false;
    }
    if (part.part != next_ || part.type != type_ || part.transaction != transaction_) {
        next_ = 0;
        return false;
    }
    const size_t number = part.part;
    const bool last = number + 1 == kNameQueryFrames;
    __builtin_memcpy(name_ + number * kNameBytesPerPart, part.bytes, last ? kLastPartNameBytes : kNameBytesPerPart);
    if (!last) {
        ++next_;
        return false;
    }
    next_ = 0;
    relays_ = part.relays;
    // Well formed: 1 to 15 characters, then NULs only.
    size_t length = 0;
    while (length < kNameQueryNameBytes && name_[length] != '\0') {
        ++length;
    }
    if (length == 0 || length == kNameQueryNameBytes) {
        return false;
    }
    for (size_t i = length; i < kNameQueryNameBytes; ++i) {
        if (name_[i] != '\0') {
            return false;
        }
    }
    return true;
}

} // namespace dcos::internal
