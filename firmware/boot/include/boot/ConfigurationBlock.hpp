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
//      440   68  0
//      508    4  CRC-32 of bytes 0 to 507
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

    uint32_t sequence = 0;
    uint8_t keyCount = 0;
    uint16_t nodeId = 0;
    uint32_t canBitRate = 0;
    uint8_t keys[kMaximumKeys][kKeySize] = {};
    char commandLine[kCommandLineSize] = {};

    void encode(uint8_t (&sector)[kSize]) const;
    /// False for anything but a whole, valid record: magic, format, CRC, at
    /// most four keys each in uncompressed form, a terminated printable
    /// command line, node id not 0xFFFF.
    static bool decode(const uint8_t (&sector)[kSize], ConfigurationBlock& out);
};

} // namespace boot
