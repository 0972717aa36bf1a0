#include <pci/Enumerator.hpp>
#include <pci/FunctionConfig.hpp>

namespace pci {

using dcos::Result;
using dcos::Status;

Result<Device> Enumerator::read(Address address) const
{
    if (!address.valid()) {
        return Status::InvalidArgument;
    }
    FunctionConfig function(config_, address);
    Device device;
    device.address = address;
    device.vendorId = function.read16(reg::kVendorId);
    if (function.status() != Status::Ok) {
        return function.status();
    }
    if (device.vendorId == reg::kVendorNone) {
        return Status::NotFound;
    }
    device.deviceId = function.read16(reg::kDeviceId);
    const uint32_t revisionAndClass = function.read32(reg::kRevisionAndClass);
    device.revision = static_cast<uint8_t>(revisionAndClass);
    device.classCode = revisionAndClass >> reg::kClassCodeShift;
    const uint8_t headerType = function.read8(reg::kHeaderType);
    device.headerType = headerType & reg::kHeaderTypeLayoutMask;
    device.multiFunction = (headerType & reg::kHeaderTypeMultiFunction) != 0;
    // The subsystem registers exist in a device's header only; a bridge
    // has its I/O and memory windows there.
    if (device.headerType == reg::kHeaderTypeDevice) {
        device.subsystemVendorId = function.read16(reg::kSubsystemVendorId);
        device.subsystemId = function.read16(reg::kSubsystemId);
    }
    // The interrupt registers sit at 0x3C in every header type (LB 6.1 and
    // the bridge specification agree).
    device.interruptLine = function.read8(reg::kInterruptLine);
    device.interruptPin = function.read8(reg::kInterruptPin);
    if (function.status() != Status::Ok) {
        return function.status();
    }
    return device;
}

template <typename Visit>
void Enumerator::walk(Visit visit) const
{
    for (unsigned slot = 0; slot < reg::kDevicesPerBus; ++slot) {
        const Result<Device> first = read({kBus, static_cast<uint8_t>(slot), 0});
        if (!first.ok()) {
            continue; // Function 0 is present in every device (LB 6.2.1): nothing here.
        }
        if (!visit(first.value())) {
            return;
        }
        if (!first.value().multiFunction) {
            continue;
        }
        for (unsigned function = 1; function < reg::kFunctionsPerDevice; ++function) {
            const Result<Device> other = read({kBus, static_cast<uint8_t>(slot), static_cast<uint8_t>(function)});
            if (other.ok() && !visit(other.value())) {
                return;
            }
        }
    }
}

size_t Enumerator::scan(Device* devices, size_t capacity) const
{
    size_t found = 0;
    walk([&](const Device& device) {
        if (found < capacity) {
            devices[found] = device;
        }
        ++found;
        return true;
    });
    return found;
}

Result<Device> Enumerator::find(uint16_t vendorId, uint16_t deviceId, unsigned index) const
{
    Result<Device> match = Status::NotFound;
    unsigned seen = 0;
    walk([&](const Device& device) {
        if (device.vendorId != vendorId || device.deviceId != deviceId) {
            return true;
        }
        if (seen++ == index) {
            match = device;
            return false;
        }
        return true;
    });
    return match;
}

} // namespace pci
