#include <hostcan/GsUsbProtocol.hpp>
#include <hostcan/LibUsbGsDevice.hpp>

// Debian installs the header as /usr/include/libusb-1.0/libusb.h; naming the
// folder here spares every host object the extra include path.
#include <libusb-1.0/libusb.h>

#include <algorithm>
#include <cstdio>
#include <thread>

namespace hostcan {

namespace {

// How long an I/O error is given to turn out an unplug: Linux takes the
// device away within some tens of milliseconds of the transfer failing.
constexpr int kGoneChecks = 10;
constexpr std::chrono::milliseconds kGoneCheckInterval{50};

// USB 2.0 specification, table 9-13: bmAttributes bits 1..0 give the
// transfer type, and bit 7 of bEndpointAddress the direction.
constexpr uint8_t kEndpointDirectionIn = 0x80;
// The gs_usb interface: Linux's driver table matches interface 0 of each
// device (USB_DEVICE_INTERFACE_NUMBER(..., 0)).
constexpr uint8_t kGsUsbInterface = 0;
// Time given to the control requests `list` sends to read a channel count.
constexpr unsigned kListRequestTimeoutMs = 500;

std::string hex4(uint16_t value)
{
    char text[8];
    std::snprintf(text, sizeof text, "%04x", value);
    return text;
}

std::string idText(uint16_t vendor, uint16_t product) { return hex4(vendor) + ":" + hex4(product); }

bool isGsUsb(const libusb_device_descriptor& descriptor)
{
    for (const GsUsbId& id : gsUsbIds()) {
        if (id.vendor == descriptor.idVendor && id.product == descriptor.idProduct) {
            return true;
        }
    }
    return false;
}

std::string idsLookedFor()
{
    std::string text;
    for (const GsUsbId& id : gsUsbIds()) {
        text += (text.empty() ? "" : ", ") + idText(id.vendor, id.product);
    }
    return text;
}

std::string readString(libusb_device_handle* handle, uint8_t index)
{
    if (index == 0) {
        return {};
    }
    unsigned char text[256];
    const int n = libusb_get_string_descriptor_ascii(handle, index, text, sizeof text);
    return n > 0 ? std::string(reinterpret_cast<const char*>(text), static_cast<size_t>(n)) : std::string();
}

std::string problemOf(int code)
{
    if (code == LIBUSB_ERROR_ACCESS) {
        return "permission denied (install the udev rule of docs/guide/host-can.md, or run as root)";
    }
    if (code == LIBUSB_ERROR_BUSY) {
        return "another program has claimed it";
    }
    return libusb_strerror(static_cast<libusb_error>(code));
}

// The bulk endpoints of interface 0's first alternate setting, read from
// the configuration descriptor rather than assumed: candleLight uses 0x81
// and 0x02, other firmware does not (newer Linux drivers detect them at
// probe for the same reason).
struct Endpoints {
    bool found = false;
    uint8_t in = 0;
    uint8_t out = 0;
    size_t inPacketSize = 64;
    uint8_t interfaceNumber = kGsUsbInterface;
};

Endpoints findEndpoints(libusb_device* device)
{
    Endpoints result;
    libusb_config_descriptor* config = nullptr;
    if (libusb_get_active_config_descriptor(device, &config) != 0 &&
        libusb_get_config_descriptor(device, 0, &config) != 0) {
        return result;
    }
    for (int i = 0; i < config->bNumInterfaces && !result.found; ++i) {
        const libusb_interface& interface = config->interface[i];
        if (interface.num_altsetting < 1 || interface.altsetting[0].bInterfaceNumber != kGsUsbInterface) {
            continue;
        }
        const libusb_interface_descriptor& setting = interface.altsetting[0];
        bool haveIn = false;
        bool haveOut = false;
        for (int e = 0; e < setting.bNumEndpoints; ++e) {
            const libusb_endpoint_descriptor& endpoint = setting.endpoint[e];
            if ((endpoint.bmAttributes & LIBUSB_TRANSFER_TYPE_MASK) != LIBUSB_TRANSFER_TYPE_BULK) {
                continue;
            }
            if ((endpoint.bEndpointAddress & kEndpointDirectionIn) != 0) {
                if (!haveIn) {
                    result.in = endpoint.bEndpointAddress;
                    // Bits 10..0 are the packet size (USB 2.0, table 9-13).
                    result.inPacketSize = std::max<size_t>(endpoint.wMaxPacketSize & 0x7FF, 8);
                    haveIn = true;
                }
            } else if (!haveOut) {
                result.out = endpoint.bEndpointAddress;
                haveOut = true;
            }
        }
        result.interfaceNumber = setting.bInterfaceNumber;
        result.found = haveIn && haveOut;
    }
    libusb_free_config_descriptor(config);
    return result;
}

unsigned timeoutMs(std::chrono::milliseconds timeout)
{
    // libusb reads 0 as "wait for ever"; every wait here has an end.
    return static_cast<unsigned>(std::max<long long>(timeout.count(), 1));
}

} // namespace

const std::vector<GsUsbId>& gsUsbIds()
{
    // drivers/net/can/usb/gs_usb.c, gs_usb_table (and its USB_*_VENDOR_ID /
    // USB_*_PRODUCT_ID definitions).
    static const std::vector<GsUsbId> ids = {
        {0x1D50, 0x606F, "Geschwister Schneider USB/CAN, candleLight, CANable (gs_usb)"},
        {0x1209, 0x2323, "candleLight"},
        {0x1CD2, 0x606F, "CES CANext FD"},
        {0x16D0, 0x10B8, "ABE CANdebugger FD"},
        {0x16D0, 0x0F30, "Xylanta SAINT3"},
        {0x1209, 0xCA01, "CANnectivity"},
    };
    return ids;
}

std::unique_ptr<LibUsbGsDevice> LibUsbGsDevice::open(const std::string& serial, TransportError& error)
{
    // What was looked for, for the messages: "gs_usb adapter with serial number X".
    const std::string looked = serial.empty() ? "gs_usb adapter" : "gs_usb adapter with serial number " + serial;
    const std::string wanted = (serial.empty() ? "a " : "the ") + looked;
    std::unique_ptr<LibUsbGsDevice> device(new LibUsbGsDevice());
    int code = libusb_init(&device->context_);
    if (code != 0) {
        device->context_ = nullptr;
        error = {TransportError::Kind::NotAvailable,
                 "cannot look for " + wanted + ": USB is not available here (" + problemOf(code) + ")"};
        return nullptr;
    }
    libusb_device** list = nullptr;
    const ssize_t count = libusb_get_device_list(device->context_, &list);
    if (count < 0) {
        error = {TransportError::Kind::NotAvailable,
                 "cannot look for " + wanted + ": cannot list USB devices (" + problemOf(static_cast<int>(count)) + ")"};
        return nullptr;
    }
    std::string refused; // Adapters that matched the ids but could not be opened, and why.
    libusb_device* chosen = nullptr;
    for (ssize_t i = 0; i < count && chosen == nullptr; ++i) {
        libusb_device_descriptor descriptor{};
        if (libusb_get_device_descriptor(list[i], &descriptor) != 0 || !isGsUsb(descriptor)) {
            continue;
        }
        const std::string where = idText(descriptor.idVendor, descriptor.idProduct) + " on bus " +
                                  std::to_string(libusb_get_bus_number(list[i])) + " address " +
                                  std::to_string(libusb_get_device_address(list[i]));
        libusb_device_handle* handle = nullptr;
        code = libusb_open(list[i], &handle);
        if (code != 0) {
            refused += (refused.empty() ? "" : "; ") + where + ": " + problemOf(code);
            continue;
        }
        const std::string found = readString(handle, descriptor.iSerialNumber);
        if (serial.empty() || found == serial) {
            chosen = list[i];
            device->handle_ = handle;
            device->description_ = where + (found.empty() ? "" : ", serial " + found);
        } else {
            libusb_close(handle);
        }
    }
    if (chosen == nullptr) {
        libusb_free_device_list(list, 1);
        if (!refused.empty()) {
            error = {TransportError::Kind::Open,
                     "cannot open " + wanted + ": found adapters that could not be opened: " + refused};
        } else {
            error = {TransportError::Kind::NotAvailable,
                     "no " + looked + " is plugged in (looked for USB ids " +
                         idsLookedFor() + "; `dcos-can list` shows what is there)"};
        }
        return nullptr;
    }
    const Endpoints endpoints = findEndpoints(chosen);
    libusb_free_device_list(list, 1);
    if (!endpoints.found) {
        error = {TransportError::Kind::Open,
                 device->description_ + ": interface 0 has no bulk IN and OUT endpoints, so it is no gs_usb adapter"};
        return nullptr;
    }
    device->interface_ = endpoints.interfaceNumber;
    device->inEndpoint_ = endpoints.in;
    device->outEndpoint_ = endpoints.out;
    device->inPacketSize_ = endpoints.inPacketSize;
    // With a kernel driver bound (gs_usb.ko made it can0), claiming would
    // fail; libusb detaches it for us and binds it again when we release.
    if (libusb_set_auto_detach_kernel_driver(device->handle_, 1) != 0 &&
        libusb_kernel_driver_active(device->handle_, device->interface_) == 1) {
        code = libusb_detach_kernel_driver(device->handle_, device->interface_);
        if (code != 0) {
            error = {TransportError::Kind::Open, device->description_ +
                                                     ": cannot detach the kernel driver from it: " + problemOf(code)};
            return nullptr;
        }
    }
    code = libusb_claim_interface(device->handle_, device->interface_);
    if (code != 0) {
        error = {TransportError::Kind::Open, device->description_ + ": cannot claim interface " +
                                                 std::to_string(device->interface_) + ": " + problemOf(code)};
        return nullptr;
    }
    device->claimed_ = true;
    return device;
}

std::vector<GsUsbAdapterInfo> LibUsbGsDevice::list(bool askChannels, TransportError& error)
{
    std::vector<GsUsbAdapterInfo> adapters;
    libusb_context* context = nullptr;
    int code = libusb_init(&context);
    if (code != 0) {
        error = {TransportError::Kind::NotAvailable, std::string("USB is not available here: ") + problemOf(code)};
        return adapters;
    }
    libusb_device** list = nullptr;
    const ssize_t count = libusb_get_device_list(context, &list);
    if (count < 0) {
        error = {TransportError::Kind::NotAvailable,
                 std::string("cannot list USB devices: ") + problemOf(static_cast<int>(count))};
        libusb_exit(context);
        return adapters;
    }
    for (ssize_t i = 0; i < count; ++i) {
        libusb_device_descriptor descriptor{};
        if (libusb_get_device_descriptor(list[i], &descriptor) != 0 || !isGsUsb(descriptor)) {
            continue;
        }
        GsUsbAdapterInfo info;
        info.bus = libusb_get_bus_number(list[i]);
        info.address = libusb_get_device_address(list[i]);
        info.vendor = descriptor.idVendor;
        info.product = descriptor.idProduct;
        libusb_device_handle* handle = nullptr;
        code = libusb_open(list[i], &handle);
        if (code != 0) {
            info.problem = problemOf(code);
            adapters.push_back(info);
            continue;
        }
        info.serial = readString(handle, descriptor.iSerialNumber);
        info.productName = readString(handle, descriptor.iProduct);
        const Endpoints endpoints = findEndpoints(list[i]);
        if (askChannels && libusb_kernel_driver_active(handle, endpoints.interfaceNumber) == 1) {
            // Listing must not take an adapter from the kernel: it is a
            // SocketCAN interface now, and `ip link` shows which.
            info.problem = "a kernel driver (gs_usb) holds it: it is a SocketCAN interface";
        } else if (askChannels) {
            code = libusb_claim_interface(handle, endpoints.interfaceNumber);
            if (code != 0) {
                info.problem = problemOf(code);
            } else {
                // HOST_FORMAT first, as Linux's probe does: the original
                // USB2CAN answers in the byte order it was told.
                const std::vector<uint8_t> hostConfig = gsusb::encodeHostConfig();
                uint8_t answer[gsusb::DeviceConfig::kSize] = {};
                (void)libusb_control_transfer(handle, gsusb::kRequestTypeOut,
                                              static_cast<uint8_t>(gsusb::Request::HostFormat),
                                              gsusb::kInterfaceRequestValue, endpoints.interfaceNumber,
                                              const_cast<uint8_t*>(hostConfig.data()),
                                              static_cast<uint16_t>(hostConfig.size()), kListRequestTimeoutMs);
                const int n = libusb_control_transfer(handle, gsusb::kRequestTypeIn,
                                                      static_cast<uint8_t>(gsusb::Request::DeviceConfig),
                                                      gsusb::kInterfaceRequestValue, endpoints.interfaceNumber, answer,
                                                      sizeof answer, kListRequestTimeoutMs);
                const gsusb::Result<gsusb::DeviceConfig> config =
                    gsusb::decodeDeviceConfig(answer, n < 0 ? 0 : static_cast<size_t>(n));
                if (n < 0) {
                    info.problem = std::string("DEVICE_CONFIG failed: ") + problemOf(n);
                } else if (!config.ok()) {
                    info.problem = "DEVICE_CONFIG answered " + config.reason();
                } else {
                    info.channels = config.value().channels();
                }
                libusb_release_interface(handle, endpoints.interfaceNumber);
            }
        }
        libusb_close(handle);
        adapters.push_back(info);
    }
    libusb_free_device_list(list, 1);
    libusb_exit(context);
    return adapters;
}

LibUsbGsDevice::~LibUsbGsDevice()
{
    if (handle_ != nullptr) {
        if (claimed_) {
            (void)libusb_release_interface(handle_, interface_);
        }
        libusb_close(handle_);
    }
    if (context_ != nullptr) {
        libusb_exit(context_);
    }
}

UsbResult LibUsbGsDevice::result(int code, size_t length, const char* what)
{
    UsbResult r;
    r.length = length;
    switch (code) {
    case LIBUSB_SUCCESS: return r;
    case LIBUSB_ERROR_TIMEOUT: r.status = UsbResult::Status::Timeout; break;
    case LIBUSB_ERROR_NO_DEVICE: r.status = UsbResult::Status::NoDevice; break;
    case LIBUSB_ERROR_PIPE: r.status = UsbResult::Status::Stall; break;
    case LIBUSB_ERROR_OVERFLOW: r.status = UsbResult::Status::Overflow; break;
    default: {
        // An unplug in the middle of a transfer often ends it with a plain
        // I/O error (the host controller cancels it before the kernel has
        // taken the device away), so the device is asked again for a while:
        // one that stops answering is gone, one that still answers failed.
        r.status = UsbResult::Status::Io;
        for (int attempt = 0; attempt < kGoneChecks; ++attempt) {
            int configuration = 0;
            if (libusb_get_configuration(handle_, &configuration) == LIBUSB_ERROR_NO_DEVICE) {
                r.status = UsbResult::Status::NoDevice;
                break;
            }
            std::this_thread::sleep_for(kGoneCheckInterval);
        }
        break;
    }
    }
    r.message = std::string(what) + ": " + libusb_strerror(static_cast<libusb_error>(code));
    return r;
}

UsbResult LibUsbGsDevice::controlIn(uint8_t request, uint16_t value, uint16_t index, uint8_t* data, size_t length,
                                    std::chrono::milliseconds timeout)
{
    const int n = libusb_control_transfer(handle_, gsusb::kRequestTypeIn, request, value, index, data,
                                          static_cast<uint16_t>(std::min<size_t>(length, 0xFFFF)), timeoutMs(timeout));
    return n >= 0 ? result(0, static_cast<size_t>(n), "control request") : result(n, 0, "control request");
}

UsbResult LibUsbGsDevice::controlOut(uint8_t request, uint16_t value, uint16_t index, const uint8_t* data,
                                     size_t length, std::chrono::milliseconds timeout)
{
    // libusb's signature takes a non-const buffer for both directions; an
    // OUT request only reads it.
    const int n = libusb_control_transfer(handle_, gsusb::kRequestTypeOut, request, value, index,
                                          const_cast<uint8_t*>(data),
                                          static_cast<uint16_t>(std::min<size_t>(length, 0xFFFF)), timeoutMs(timeout));
    return n >= 0 ? result(0, static_cast<size_t>(n), "control request") : result(n, 0, "control request");
}

UsbResult LibUsbGsDevice::bulkIn(uint8_t* data, size_t capacity, std::chrono::milliseconds timeout)
{
    int transferred = 0;
    const int code = libusb_bulk_transfer(handle_, inEndpoint_, data, static_cast<int>(capacity), &transferred,
                                          timeoutMs(timeout));
    return result(code, static_cast<size_t>(std::max(transferred, 0)), "bulk IN transfer");
}

UsbResult LibUsbGsDevice::bulkOut(const uint8_t* data, size_t length, std::chrono::milliseconds timeout)
{
    int transferred = 0;
    const int code = libusb_bulk_transfer(handle_, outEndpoint_, const_cast<uint8_t*>(data), static_cast<int>(length),
                                          &transferred, timeoutMs(timeout));
    return result(code, static_cast<size_t>(std::max(transferred, 0)), "bulk OUT transfer");
}

} // namespace hostcan
