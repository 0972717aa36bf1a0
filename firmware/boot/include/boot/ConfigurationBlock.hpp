// The controller's configuration on its card (docs/boot.md, "The card"):
// what the stage loader needs before any image runs, and what the node
// starts with. Kept in two copies (RecordCopies.hpp) at
// card::kConfigurationLba, written at manufacture (dcos-card) and later by
// the node's configuration service.
//
//   offset size  field
//        0    8  magic "DCOSCONF"
//        8    4  sequence
//       12    1  format, 1
//       13    1  trusted keys, 0 to 4
//       14    2  node id (0: the kernel's default, 1)
//       16    4  CAN bit rate in bit/s: the kernel starts can0 on the network
//                at it (0: it stays down; recovery listens at 125 kbit/s)
//       20  260  trusted keys: public points, 65 bytes each (SEC 1 uncompressed)
//      280  160  kernel command line, printable ASCII, NUL-terminated
//      440    4  serial number (0: none), set at manufacture
//      444   32  configuration key, for the configuration protocol's MACs
//                (docs/protocols/config.md), set at manufacture
//      476    1  flags: bit 0 the key is set, bit 1 queries are closed
//      477    2  lockout after three wrong MACs, in seconds (0: 60)
//      479   29  0
//      508    4  CRC-32 of bytes 0 to 507
//
// Bytes 440 to 478 were 0 in the first records of format 1, which read as
// no serial number, no key, open queries and the default lockout.
#pragma once

#include <boot/CardLayout.hpp>
#include <boot/RecordCopies.hpp>

#include <stddef.h>
#include <stdint.h>

namespace boot {

struct ConfigurationBlock {
    static constexpr size_t kSize = card::kSectorSize;
    static constexpr size_t kMaximumKeys = 4;
    static constexpr size_t kKeySize = 65;
    static constexpr size_t kCommandLineSize = 160;
    static constexpr size_t kConfigurationKeySize = 32;
    /// flags: the configuration key is set.
    static constexpr uint8_t kHasConfigurationKey = 1u << 0;
    /// flags: the configuration protocol's queries need a MAC too.
    static constexpr uint8_t kQueriesClosed = 1u << 1;
    static constexpr uint8_t kKnownFlags = kHasConfigurationKey | kQueriesClosed;
    /// The lockout when the record names none.
    static constexpr uint16_t kDefaultLockoutSeconds = 60;

    uint32_t sequence = 0;
    uint8_t keyCount = 0;
    uint16_t nodeId = 0;
    uint32_t canBitRate = 0;
    uint8_t keys[kMaximumKeys][kKeySize] = {};
    char commandLine[kCommandLineSize] = {};
    uint32_t serialNumber = 0;
    uint8_t configurationKey[kConfigurationKeySize] = {};
    uint8_t flags = 0;
    uint16_t lockoutSeconds = 0;

    bool hasConfigurationKey() const { return (flags & kHasConfigurationKey) != 0; }
    bool queriesClosed() const { return (flags & kQueriesClosed) != 0; }
    uint16_t effectiveLockoutSeconds() const
    {
        return lockoutSeconds != 0 ? lockoutSeconds : kDefaultLockoutSeconds;
    }

    void encode(uint8_t (&sector)[kSize]) const;
    /// False for anything but a whole, valid record: magic, format, CRC, at
    /// most four keys each in uncompressed form, a terminated printable
    /// command line, node id not 0xFFFF, no unknown flag.
    static bool decode(const uint8_t (&sector)[kSize], ConfigurationBlock& out);
};

} // namespace boot
