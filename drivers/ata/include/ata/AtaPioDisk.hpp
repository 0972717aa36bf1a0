// An ATA disk driven by PIO with its interrupt off: the controller's
// CompactFlash card in True IDE mode on the primary channel (docs/boot.md,
// "The card"). Used by the stage loader before any kernel runs, and by a
// running node to write an image slot or the boot state, so it polls and
// never sleeps: every wait is bounded and ends in AtaError::Timeout.
//
// Reads and writes of whole 512-byte sectors, LBA28 addressing, at most
// 256 sectors a command (longer transfers are split). A write returns once
// the card has taken the data and flushed its cache (FLUSH CACHE), so a
// power cut after a successful write cannot lose it.
#pragma once

#include <arch_x86/IoWindow.hpp>

#include <stddef.h>
#include <stdint.h>

namespace ata {

enum class AtaError : uint8_t {
    Ok = 0,
    NoDevice,    ///< Nothing answers on the channel (a floating bus, or no LBA support).
    Timeout,     ///< The device stayed busy, or never asked for or offered data.
    DeviceError, ///< The device reported ERR or DF; error() holds its error register.
    OutOfRange,  ///< A sector beyond the device's last, or a zero-length transfer.
};

/// One line for an engineer.
const char* ataErrorText(AtaError error);

class AtaPioDisk {
public:
    /// Polls of the status register before a wait gives up: a dead card's
    /// bound. A CompactFlash card answers within microseconds, but the ATA
    /// standard lets a device take up to 31 s to become ready (ATA/ATAPI-6,
    /// 9.2), and a port read takes about a microsecond on an ISA bus, so
    /// this is about 32 s there. An emulated board reads its ports some ten
    /// times faster while its disk answers in host time: the 4,000,000 polls
    /// this once was gave up on a write of a busy host's emulated card.
    static constexpr uint32_t kPollLimit = 32'000'000;

    /// @p pollLimit replaces kPollLimit (host tests, whose waits need not
    /// last seconds).
    AtaPioDisk(const arch_x86::IoWindow& command, const arch_x86::IoWindow& control,
               uint32_t pollLimit = kPollLimit);

    /// The primary channel's master, where a PC/104 board's card sits.
    static AtaPioDisk primary();

    /// Resets nothing; turns the device's interrupt off, asks IDENTIFY
    /// DEVICE and keeps its size and model. Must succeed before any transfer.
    AtaError identify();

    /// Reads @p count sectors from @p lba into @p buffer (count * 512 bytes).
    AtaError read(uint32_t lba, uint32_t count, void* buffer);
    /// Writes @p count sectors at @p lba from @p buffer, then flushes the cache.
    AtaError write(uint32_t lba, uint32_t count, const void* buffer);

    /// Sectors the device addresses (0 before identify()).
    uint32_t sectorCount() const { return sectorCount_; }
    /// The device's model text, without trailing spaces.
    const char* model() const { return model_; }
    /// The error register after the last DeviceError.
    uint8_t errorRegister() const { return error_; }

private:
    AtaError waitWhileBusy(uint8_t& status);
    AtaError waitForData();
    AtaError finish();
    AtaError issue(uint8_t command, uint32_t lba, uint32_t count);
    AtaError checkRange(uint32_t lba, uint32_t count) const;
    /// Reads into @p in or writes from @p out (the other null), in commands
    /// of at most 256 sectors.
    AtaError transfer(uint8_t command, uint32_t lba, uint32_t count, uint16_t* in, const uint16_t* out);

    arch_x86::IoWindow command_;
    arch_x86::IoWindow control_;
    uint32_t pollLimit_;
    uint32_t sectorCount_ = 0;
    uint8_t error_ = 0;
    char model_[41] = {};
};

} // namespace ata
