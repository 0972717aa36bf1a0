// The ATA register block of a CompactFlash card in True IDE mode, or any
// ATA disk, as the PC/AT's primary channel decodes it. Offsets, bits and
// commands from ATA/ATAPI-6 (T13 1410D revision 3b): the command block
// registers in section 7 (7.2 to 7.15), the status bits in 7.15.6, the
// device control register in 7.9; the commands in 8.16 (FLUSH CACHE), 8.15
// (IDENTIFY DEVICE), 8.27 (READ SECTORS) and 8.47 (WRITE SECTORS). The
// CompactFlash specification 4.1, 6.1.5, maps its True IDE mode registers
// onto the same addresses.
#pragma once

#include <stdint.h>

namespace ata::reg {

// The primary channel's two windows on a PC/AT.
constexpr uint16_t kPrimaryCommandBase = 0x1F0;
constexpr uint16_t kPrimaryControlBase = 0x3F6;
constexpr uint16_t kCommandWindowSize = 8;
constexpr uint16_t kControlWindowSize = 1;

// Command block (7.2 to 7.15), offsets from the command base.
constexpr uint16_t kData = 0;        ///< 16-bit data port (7.7)
constexpr uint16_t kError = 1;       ///< read: error (7.11)
constexpr uint16_t kFeatures = 1;    ///< write: features (7.12)
constexpr uint16_t kSectorCount = 2; ///< 7.14; 0 means 256 sectors
constexpr uint16_t kLbaLow = 3;      ///< LBA bits 7:0 (7.13)
constexpr uint16_t kLbaMid = 4;      ///< LBA bits 15:8
constexpr uint16_t kLbaHigh = 5;     ///< LBA bits 23:16
constexpr uint16_t kDevice = 6;      ///< device/head (7.10)
constexpr uint16_t kStatus = 7;      ///< read: status, clears a pending interrupt (7.15)
constexpr uint16_t kCommand = 7;     ///< write: command (7.4)

// Control block (7.3, 7.9), offset from the control base.
constexpr uint16_t kAlternateStatus = 0; ///< read: status without side effects (7.3)
constexpr uint16_t kDeviceControl = 0;   ///< write (7.9)

// Status (7.15.6).
constexpr uint8_t kStatusBusy = 0x80;       ///< BSY
constexpr uint8_t kStatusReady = 0x40;      ///< DRDY
constexpr uint8_t kStatusDeviceFault = 0x20; ///< DF
constexpr uint8_t kStatusDataRequest = 0x08; ///< DRQ
constexpr uint8_t kStatusError = 0x01;      ///< ERR

// Device register (7.10): bits 7 and 5 obsolete, set for old devices; bit
// 6 selects LBA addressing; bit 4 the device (0, the master); bits 3:0 LBA
// bits 27:24.
constexpr uint8_t kDeviceLbaMaster = 0xE0;

// Device control (7.9).
constexpr uint8_t kControlInterruptsOff = 0x02; ///< nIEN: no INTRQ, the driver polls
constexpr uint8_t kControlSoftwareReset = 0x04; ///< SRST

// Commands (section 8).
constexpr uint8_t kCommandReadSectors = 0x20;    ///< 8.27, PIO data-in
constexpr uint8_t kCommandWriteSectors = 0x30;   ///< 8.47, PIO data-out
constexpr uint8_t kCommandFlushCache = 0xE7;     ///< 8.16
constexpr uint8_t kCommandIdentifyDevice = 0xEC; ///< 8.15, PIO data-in

// IDENTIFY DEVICE words (8.15, Table 15).
constexpr unsigned kIdentifyModelWord = 27;      ///< 40 characters, two per word, high byte first
constexpr unsigned kIdentifyModelWords = 20;
constexpr unsigned kIdentifyCapabilitiesWord = 49;
constexpr uint16_t kCapabilityLba = 0x0200;      ///< word 49 bit 9
constexpr unsigned kIdentifyLbaSectorsWord = 60; ///< words 60-61: sectors addressable in LBA28

constexpr unsigned kSectorSize = 512;
constexpr unsigned kWordsPerSector = kSectorSize / 2;
/// LBA28 addresses up to 2^28 sectors.
constexpr uint32_t kLba28Sectors = 1u << 28;

} // namespace ata::reg
