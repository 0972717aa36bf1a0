// Register offsets and bits of the multi-function ISA I/O board (isa-mfio).
//
// Every constant below cites its row of docs/iobus/mfio-register-map.md
// (version 1.0 of the map), the contract between the emulator model, this
// driver and the host tools. No other file of the driver spells a register
// offset or a bit as a bare number.
#pragma once

#include <stdint.h>

namespace iobus::mfio {

// Bus interface (map, "Bus interface").

/// Bytes of I/O ports the board decodes from its base port.
constexpr uint16_t kWindowSize = 0x40;
/// The base port the board's DIP switches select by default.
constexpr uint16_t kDefaultBase = 0x300;
/// The interrupt line the board's jumper selects by default.
constexpr uint8_t kDefaultIrq = 5;

// Registers (map, "Registers"); all 16 bits wide at even offsets.

constexpr uint16_t kIdRegister = 0x00;         ///< `ID`, read: always kBoardId.
constexpr uint16_t kRevisionRegister = 0x02;   ///< `REVISION`, read: major in the high byte, minor in the low byte.
constexpr uint16_t kControlRegister = 0x04;    ///< `CONTROL`, read/write.
constexpr uint16_t kStatusRegister = 0x06;     ///< `STATUS`, read.
constexpr uint16_t kAdcStartRegister = 0x08;   ///< `ADC_START`, write: bits 2:0 the channel to convert.
constexpr uint16_t kAdcDataRegister = 0x0A;    ///< `ADC_DATA`, read: result, its channel and overrange flag.
constexpr uint16_t kGainRegister = 0x0C;       ///< `GAIN`, read/write: two bits per channel.
constexpr uint16_t kIrqAckRegister = 0x0E;     ///< `IRQ_ACK`, write.
constexpr uint16_t kDigitalInputRegister = 0x10;  ///< `DI`, read: bit n = input n.
constexpr uint16_t kDigitalOutputRegister = 0x12; ///< `DO`, read/write: bit n = output n.
constexpr uint16_t kDacRegister0 = 0x20;       ///< `DAC0`; `DACn` is at kDacRegister0 + 2n.

/// The offset of `DACn` (map row "0x20 + 2n").
constexpr uint16_t dacRegister(unsigned channel) { return static_cast<uint16_t>(kDacRegister0 + 2u * channel); }

/// The value of `ID` (map: "always 0x4D46 ("MF")").
constexpr uint16_t kBoardId = 0x4D46;
/// The major revision of the map this driver implements (`REVISION` high byte).
constexpr uint8_t kSupportedMajorRevision = 1;
/// What a 16-bit read of an empty ISA bus returns.
constexpr uint16_t kEmptyBus = 0xFFFF;

// CONTROL bits (map row 0x04).
constexpr uint16_t kControlIrqEnable = 1u << 0; ///< Interrupt on conversion complete.
constexpr uint16_t kControlReset = 1u << 15;    ///< Write 1: every register to its reset value; self-clearing.

// STATUS bits (map row 0x06).
constexpr uint16_t kStatusBusy = 1u << 0;       ///< A conversion is running.
constexpr uint16_t kStatusDone = 1u << 1;       ///< A result is waiting (latched until IRQ_ACK).
constexpr uint16_t kStatusOverrange = 1u << 2;  ///< The last result saturated.
constexpr uint16_t kStatusIrqPending = 1u << 3; ///< The board is requesting its interrupt.

// ADC_START field (map row 0x08).
constexpr uint16_t kAdcStartChannelMask = 0x0007; ///< Bits 2:0, the channel.

// ADC_DATA fields (map row 0x0A).
constexpr uint16_t kAdcDataCodeMask = 0x0FFF;     ///< Bits 11:0, the result code.
constexpr unsigned kAdcDataChannelShift = 12;     ///< Bits 14:12, the converted channel.
constexpr uint16_t kAdcDataChannelMask = 0x0007;  ///< The channel field after shifting.
constexpr uint16_t kAdcDataOverrange = 1u << 15;  ///< Bit 15, the result saturated.

// GAIN fields (map row 0x0C): channel n at bits 2n+1:2n.
constexpr unsigned kGainBitsPerChannel = 2;
constexpr uint16_t kGainFieldMask = 0x3;
constexpr uint16_t kGainX1 = 0;    ///< ×1.
constexpr uint16_t kGainX10 = 1;   ///< ×10.
constexpr uint16_t kGainX100 = 2;  ///< ×100.
constexpr uint16_t kGainX1000 = 3; ///< ×1000.

/// The shift of channel n's gain field in `GAIN`.
constexpr unsigned gainShift(unsigned channel) { return kGainBitsPerChannel * channel; }

// IRQ_ACK bit (map row 0x0E).
constexpr uint16_t kIrqAckClear = 1u << 0; ///< Clear DONE and IRQ_PENDING, drop the request.

// DAC fields (map row 0x20 + 2n) and the analog format (map, "Analog scaling").
constexpr uint16_t kDacCodeMask = 0x0FFF; ///< Bits 11:0, the output code.
constexpr uint16_t kCodeMaximum = 4095;   ///< Largest 12-bit code, of the ADC and the DACs.
constexpr uint16_t kCodeZero = 0x800;     ///< Offset-binary code of 0 V.

/// Channel counts (map introduction, seed 9.4).
constexpr unsigned kAnalogInputs = 8;
constexpr unsigned kAnalogOutputs = 8;
constexpr unsigned kDigitalBits = 16;

/// Nominal conversion time (map, "A conversion takes 20 µs").
constexpr uint32_t kNominalConversionNs = 20000;

// Reset values (map, "Reset values").
constexpr uint16_t kResetControl = 0;
constexpr uint16_t kResetGain = 0;
constexpr uint16_t kResetDigitalOutputs = 0;
constexpr uint16_t kResetDac = kCodeZero;

} // namespace iobus::mfio
