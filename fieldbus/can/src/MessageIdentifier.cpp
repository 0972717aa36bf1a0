#include <can/MessageIdentifier.hpp>

namespace can {

LinkResult<MessageIdentifier> MessageIdentifier::fromFrame(const CanFrame& frame)
{
    if (!frame.isExtended()) {
        return LinkError::NotExtendedFrame;
    }
    if (frame.isRemote()) {
        return LinkError::UnexpectedRemoteFrame;
    }
    return decode(frame.id());
}

} // namespace can
