// Fuzz target: the remote transaction messages' decoders
// (docs/protocols/remote-transactions.md), which take every frame a node
// receives as a request or a reply.
//
// Checks: a message the decoder accepts encodes back into exactly the same
// bytes (the layout has no slack, so no two byte strings mean one message),
// and a refused one is refused for a reason the specification gives.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <dcos/internal/RemoteMessage.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>

using namespace dcos::internal;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    RemoteRequest request;
    const RemoteMessageError requestError = decodeRequest(data, size, request);
    if (requestError == RemoteMessageError::None) {
        uint8_t again[kRemoteMessageBytes];
        encodeRequest(request, again);
        FUZZ_CHECK(size == kRemoteMessageBytes && std::memcmp(again, data, size) == 0);
        FUZZ_CHECK(request.object != 0);
    } else {
        FUZZ_CHECK(requestError == RemoteMessageError::WrongLength ||
                   requestError == RemoteMessageError::UnknownService ||
                   requestError == RemoteMessageError::NullObject);
    }
    RemoteReply reply;
    const RemoteMessageError replyError = decodeReply(data, size, reply);
    if (replyError == RemoteMessageError::None) {
        uint8_t again[kRemoteMessageBytes];
        encodeReply(reply, again);
        FUZZ_CHECK(size == kRemoteMessageBytes && std::memcmp(again, data, size) == 0);
        FUZZ_CHECK(isStatusValue(static_cast<uint8_t>(reply.status)));
    } else {
        FUZZ_CHECK(replyError == RemoteMessageError::WrongLength || replyError == RemoteMessageError::UnknownService ||
                   replyError == RemoteMessageError::UnknownStatus || replyError == RemoteMessageError::ReservedBits);
    }
    return 0;
}
