#include <can/CanFrame.hpp>

namespace can {

LinkResult<CanFrame> CanFrame::makeData(uint32_t id, IdFormat format, const uint8_t* bytes, uint8_t length)
{
    const LinkError error = check(id, format, length);
    if (error != LinkError::Ok) {
        return error;
    }
    if (bytes == nullptr && length != 0) {
        return LinkError::InvalidArgument;
    }
    CanFrame frame;
    frame.id_ = id;
    frame.format_ = format;
    frame.length_ = length;
    for (uint8_t i = 0; i < length; ++i) {
        frame.data_[i] = bytes[i];
    }
    return frame;
}

LinkResult<CanFrame> CanFrame::makeRemote(uint32_t id, IdFormat format, uint8_t length)
{
    const LinkError error = check(id, format, length);
    if (error != LinkError::Ok) {
        return error;
    }
    CanFrame frame;
    frame.id_ = id;
    frame.format_ = format;
    frame.remote_ = true;
    frame.length_ = length;
    return frame;
}

bool operator==(const CanFrame& a, const CanFrame& b)
{
    if (a.id_ != b.id_ || a.format_ != b.format_ || a.remote_ != b.remote_ || a.length_ != b.length_) {
        return false;
    }
    for (uint8_t i = 0; i < CanFrame::kMaxDataLength; ++i) {
        if (a.data_[i] != b.data_[i]) {
            return false;
        }
    }
    return true;
}

} // namespace can
