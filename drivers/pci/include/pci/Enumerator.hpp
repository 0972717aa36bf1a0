// Finds the functions on PCI bus 0.
//
// Every device number 0-31 is asked for function 0's Vendor ID; 0FFFFh
// means no device (LB 6.1). Functions 1-7 are asked only when function
// 0's Header Type has the multi-function bit (LB 6.2.1): a single-function
// device may decode its registers for every function number, and would
// otherwise be found eight times. That is at most 32 x 8 functions, each
// read once, so every call here is bounded.
//
// Only bus 0 is scanned. QEMU's pc machine puts every device there unless
// a pci-bridge is added on the command line, and so does the dual-Pentium
// board's; a PCI-to-PCI bridge is reported like any function (headerType
// reg::kHeaderTypeBridge), but the buses behind it are not walked.
#pragma once

#include <pci/ConfigSpace.hpp>
#include <pci/Device.hpp>

#include <dcos/Status.hpp>

#include <stddef.h>
#include <stdint.h>

namespace pci {

class Enumerator {
public:
    /// The most functions one bus can hold.
    static constexpr unsigned kMaxFunctions = reg::kDevicesPerBus * reg::kFunctionsPerDevice;
    /// The bus scanned.
    static constexpr uint8_t kBus = 0;

    /// Enumerates through @p config, which must outlive the enumerator.
    explicit constexpr Enumerator(const ConfigSpace& config) : config_(config) {}

    /// The function at @p address. NotFound when nothing answers there,
    /// InvalidArgument for a device above 31 or a function above 7.
    dcos::Result<Device> read(Address address) const;

    /// Writes the functions of bus 0, in address order, into the first
    /// @p capacity entries of @p devices, and returns how many functions
    /// the bus has: more than @p capacity says that some were left out.
    size_t scan(Device* devices, size_t capacity) const;

    /// The function of bus 0 with @p vendorId and @p deviceId that comes
    /// @p index-th (from 0) in address order; NotFound when there are not
    /// that many.
    dcos::Result<Device> find(uint16_t vendorId, uint16_t deviceId, unsigned index = 0) const;

private:
    // Calls visit(device) for every function of bus 0 in address order
    // until it returns false.
    template <typename Visit>
    void walk(Visit visit) const;

    const ConfigSpace& config_;
};

} // namespace pci
