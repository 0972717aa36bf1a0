// The USB side of a gs_usb adapter, as small as the transport needs it:
// vendor control requests to its interface and bulk transfers on its two
// endpoints, each with a time-out and its outcome as a value.
//
// GsUsbTransport speaks the protocol through this interface only, so the
// host tests drive it with a scripted fake, and LibUsbGsDevice
// (LibUsbGsDevice.hpp) puts it on a real adapter through libusb.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>

namespace hostcan {

/// The outcome of one USB transfer.
struct UsbResult {
    enum class Status {
        Ok,
        Timeout,  ///< Nothing (or not everything) moved within the time-out; length says how much did.
        NoDevice, ///< The device is gone: unplugged, or reset away.
        Stall,    ///< The device refused the request or halted the endpoint.
        Overflow, ///< The device sent more than the buffer holds.
        Io,       ///< Any other failure, said in message.
    };
    Status status = Status::Ok;
    size_t length = 0;    ///< Bytes transferred, also when the time-out came first.
    std::string message;  ///< What the USB stack said, for a failure.

    bool ok() const { return status == Status::Ok; }
};

class GsUsbDevice {
public:
    virtual ~GsUsbDevice() = default;

    /// What to call the adapter in messages, e.g. "1d50:606f on bus 1 address 7, serial 0037...".
    virtual std::string description() const = 0;

    /// bInterfaceNumber of the gs_usb interface, the wIndex of HOST_FORMAT and DEVICE_CONFIG.
    virtual uint8_t interfaceNumber() const = 0;

    /// wMaxPacketSize of the bulk IN endpoint: one IN transfer asks for this
    /// much, so it ends with the device's packet whatever its length.
    virtual size_t inPacketSize() const = 0;

    /// A vendor request from the device (bmRequestType 0xC1), reading up to @p length bytes into @p data.
    virtual UsbResult controlIn(uint8_t request, uint16_t value, uint16_t index, uint8_t* data, size_t length,
                                std::chrono::milliseconds timeout) = 0;

    /// A vendor request to the device (bmRequestType 0x41) carrying @p length bytes.
    virtual UsbResult controlOut(uint8_t request, uint16_t value, uint16_t index, const uint8_t* data,
                                 size_t length, std::chrono::milliseconds timeout) = 0;

    /// One transfer from the bulk IN endpoint into @p data (at most
    /// @p capacity bytes), waiting at most @p timeout (at least 1 ms).
    virtual UsbResult bulkIn(uint8_t* data, size_t capacity, std::chrono::milliseconds timeout) = 0;

    /// One transfer of @p length bytes to the bulk OUT endpoint, waiting at most @p timeout.
    virtual UsbResult bulkOut(const uint8_t* data, size_t length, std::chrono::milliseconds timeout) = 0;
};

} // namespace hostcan
