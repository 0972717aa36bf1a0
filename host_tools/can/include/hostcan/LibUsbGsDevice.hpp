// A gs_usb adapter reached through libusb, from user space: no kernel
// driver (gs_usb.ko) and, with the udev rule of docs/guide/host-can.md, no
// root. The adapters are found by the vendor and product ids of Linux's
// gs_usb driver table and told apart by their USB serial number string.
#pragma once

#include <hostcan/GsUsbDevice.hpp>
#include <hostcan/Transport.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

struct libusb_context;
struct libusb_device_handle;

namespace hostcan {

/// A vendor and product id of a gs_usb device, with the name Linux gives it.
struct GsUsbId {
    uint16_t vendor;
    uint16_t product;
    const char* name;
};

/// The ids of drivers/net/can/usb/gs_usb.c's gs_usb_table, interface 0 of each.
const std::vector<GsUsbId>& gsUsbIds();

/// One adapter found on the USB, for `dcos-can list`.
struct GsUsbAdapterInfo {
    uint8_t bus = 0;
    uint8_t address = 0;
    uint16_t vendor = 0;
    uint16_t product = 0;
    std::string serial;       ///< iSerialNumber's string; empty when it could not be read.
    std::string productName;  ///< iProduct's string; empty when it could not be read.
    std::optional<unsigned> channels; ///< From DEVICE_CONFIG, when the interface could be claimed.
    std::string problem;      ///< Why the device could not be opened or asked, e.g. "permission denied".
};

class LibUsbGsDevice final : public GsUsbDevice {
public:
    /// Finds the adapter whose serial number is @p serial (the first one
    /// found when it is empty), claims interface 0, detaching a kernel
    /// driver bound to it (which libusb binds again on close), and finds its
    /// bulk endpoints in the interface descriptor. NotAvailable when no
    /// adapter matches, naming what was looked for; Open when one matches
    /// but cannot be opened or claimed, saying why.
    static std::unique_ptr<LibUsbGsDevice> open(const std::string& serial, TransportError& error);

    /// Every gs_usb adapter present. With @p askChannels, each one's
    /// interface is claimed for a moment to read DEVICE_CONFIG, unless a
    /// kernel driver holds it (which is then named in problem and left alone).
    /// An error only when USB cannot be enumerated at all.
    static std::vector<GsUsbAdapterInfo> list(bool askChannels, TransportError& error);

    ~LibUsbGsDevice() override;

    std::string description() const override { return description_; }
    uint8_t interfaceNumber() const override { return interface_; }
    size_t inPacketSize() const override { return inPacketSize_; }
    UsbResult controlIn(uint8_t request, uint16_t value, uint16_t index, uint8_t* data, size_t length,
                        std::chrono::milliseconds timeout) override;
    UsbResult controlOut(uint8_t request, uint16_t value, uint16_t index, const uint8_t* data, size_t length,
                         std::chrono::milliseconds timeout) override;
    UsbResult bulkIn(uint8_t* data, size_t capacity, std::chrono::milliseconds timeout) override;
    UsbResult bulkOut(const uint8_t* data, size_t length, std::chrono::milliseconds timeout) override;

private:
    LibUsbGsDevice() = default;

    // Maps a libusb error code (and a transfer's byte count) to a result;
    // an I/O error on a device that no longer answers becomes NoDevice.
    UsbResult result(int code, size_t length, const char* what);

    libusb_context* context_ = nullptr;
    libusb_device_handle* handle_ = nullptr;
    uint8_t interface_ = 0;
    uint8_t inEndpoint_ = 0;
    uint8_t outEndpoint_ = 0;
    size_t inPacketSize_ = 64;
    bool claimed_ = false;
    std::string description_;
};

} // namespace hostcan
