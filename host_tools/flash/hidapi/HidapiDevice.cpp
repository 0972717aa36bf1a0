// The hidapi back end of HidDevice (HidapiDevice.hpp). Its own folder, so
// that only dcos-flash links hidapi (mk/host_tools.mk), not the unit tests.
#include <hostflash/HidapiDevice.hpp>

#include <hidapi/hidapi.h>

#include <fmt/core.h>

#include <cwchar>
#include <string>

namespace hostflash {

namespace {

std::string narrow(const wchar_t* text)
{
    std::string out;
    if (text == nullptr) {
        return out;
    }
    for (; *text != L'\0'; ++text) {
        // Serial numbers and hidapi's messages are ASCII in practice; anything else shows as '?'.
        out += (*text >= 0x20 && *text < 0x7F) ? static_cast<char>(*text) : '?';
    }
    return out;
}

std::string lastError(hid_device* device)
{
    const std::string text = narrow(hid_error(device));
    return text.empty() ? "hidapi gives no reason" : text;
}

} // namespace

std::unique_ptr<HidapiDevice> HidapiDevice::open(const std::string& selector, HidOpenError& error, std::string& why)
{
    if (hid_init() != 0) {
        error = HidOpenError::NotFound;
        why = fmt::format("hidapi cannot start: {}", lastError(nullptr));
        return nullptr;
    }
    std::string path;
    if (!selector.empty() && selector.front() == '/') {
        path = selector;
    } else {
        hid_device_info* devices = hid_enumerate(mcp2221::kVendorId, mcp2221::kProductId);
        for (hid_device_info* device = devices; device != nullptr; device = device->next) {
            if (selector.empty() || narrow(device->serial_number) == selector) {
                path = device->path;
                break;
            }
        }
        hid_free_enumeration(devices);
        if (path.empty()) {
            error = HidOpenError::NotFound;
            why = selector.empty()
                      ? fmt::format("no MCP2221A ({:04x}:{:04x}) with a hidraw node is present (a device bound to "
                                    "Linux's hid-mcp2221 has none: see docs/guide/flashing.md)",
                                    mcp2221::kVendorId, mcp2221::kProductId)
                      : fmt::format("no MCP2221A with the serial number '{}' is present", selector);
            return nullptr;
        }
    }
    hid_device* handle = hid_open_path(path.c_str());
    if (handle == nullptr) {
        error = HidOpenError::Failed;
        why = fmt::format("cannot open the MCP2221A at {}: {}", path, lastError(nullptr));
        return nullptr;
    }
    error = HidOpenError::None;
    return std::unique_ptr<HidapiDevice>(new HidapiDevice(handle, path));
}

HidapiDevice::~HidapiDevice()
{
    hid_close(static_cast<hid_device*>(handle_));
    hid_exit();
}

bool HidapiDevice::write(const mcp2221::Report& report, std::string& why)
{
    // hidapi takes the report ID first; the MCP2221A's reports have none, which is ID 0.
    unsigned char data[mcp2221::kReportSize + 1] = {};
    std::copy(report.begin(), report.end(), data + 1);
    const int written = hid_write(static_cast<hid_device*>(handle_), data, sizeof data);
    if (written < 0) {
        why = lastError(static_cast<hid_device*>(handle_));
        return false;
    }
    return true;
}

int HidapiDevice::read(uint8_t* buffer, size_t capacity, std::chrono::milliseconds timeout, std::string& why)
{
    const int read = hid_read_timeout(static_cast<hid_device*>(handle_), buffer, capacity,
                                      static_cast<int>(timeout.count()));
    if (read < 0) {
        why = lastError(static_cast<hid_device*>(handle_));
    }
    return read;
}

} // namespace hostflash
