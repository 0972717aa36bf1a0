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
    }
    return "?";
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

} // namespace dcos::internal
