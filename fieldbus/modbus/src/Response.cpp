#include <modbus/Response.hpp>

namespace modbus {

bool ResponseView::object(size_t index, DeviceIdObject& object) const
{
    if (index >= objectCount()) {
        return false;
    }
    size_t position = kDeviceIdHeaderLength;
    for (size_t i = 0; i <= index; ++i) {
        // checkResponse() has proven the layout; the bounds are checked again
        // so that a view of an unchecked PDU cannot read past it.
        if (position + 2 > length_ || position + 2 + pdu_[position + 1] > length_) {
            return false;
        }
        if (i == index) {
            object.id = pdu_[position];
            object.length = pdu_[position + 1];
            object.value = pdu_ + position + 2;
            return true;
        }
        position += 2 + pdu_[position + 1];
    }
    return false;
}

} // namespace modbus
