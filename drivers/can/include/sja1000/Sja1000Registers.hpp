// Register offsets and bits of the NXP (Philips) SJA1000 stand-alone CAN
// controller in PeliCAN mode.
//
// Every constant cites the section of the SJA1000 data sheet (Philips
// Semiconductors, "SJA1000 Stand-alone CAN controller", product
// specification, 2000 Jan 04) that defines it; "DS 6.4.3" means its section
// 6.4.3. No other file of the driver spells a register offset or a bit as a
// bare number. The driver uses PeliCAN mode only (CDR.CAN_mode set): BasicCAN
// mode has no extended frames and no error counters.
#pragma once

#include <stdint.h>

namespace sja1000::reg {

// PeliCAN address allocation (DS 6.4). Offsets from the chip's
// first register; a bus front end maps them onto ports or memory.

constexpr uint8_t kMode = 0;                   ///< MOD (DS 6.4.3).
constexpr uint8_t kCommand = 1;                ///< CMR, write only (DS 6.4.4).
constexpr uint8_t kStatus = 2;                 ///< SR, read only (DS 6.4.5).
constexpr uint8_t kInterrupt = 3;              ///< IR, read only; reading clears all but RI (DS 6.4.6).
constexpr uint8_t kInterruptEnable = 4;        ///< IER (DS 6.4.7).
constexpr uint8_t kBusTiming0 = 6;             ///< BTR0, written in reset mode (DS 6.5.1).
constexpr uint8_t kBusTiming1 = 7;             ///< BTR1, written in reset mode (DS 6.5.2).
constexpr uint8_t kOutputControl = 8;          ///< OCR, written in reset mode (DS 6.5.3).
constexpr uint8_t kArbitrationLostCapture = 11; ///< ALC (DS 6.4.8).
constexpr uint8_t kErrorCodeCapture = 12;      ///< ECC (DS 6.4.9).
constexpr uint8_t kErrorWarningLimit = 13;     ///< EWLR, written in reset mode (DS 6.4.10).
constexpr uint8_t kRxErrorCounter = 14;        ///< RXERR (DS 6.4.11).
constexpr uint8_t kTxErrorCounter = 15;        ///< TXERR (DS 6.4.12).
constexpr uint8_t kFrameBuffer = 16;           ///< Transmit buffer (write) and receive window (read), operating mode (DS 6.4.13, 6.4.14).
constexpr uint8_t kAcceptanceCode0 = 16;       ///< ACR0..ACR3 at 16..19, reset mode (DS 6.4.15).
constexpr uint8_t kAcceptanceMask0 = 20;       ///< AMR0..AMR3 at 20..23, reset mode (DS 6.4.15).
constexpr uint8_t kRxMessageCounter = 29;      ///< RMC (DS 6.4.16).
constexpr uint8_t kRxBufferStart = 30;         ///< RBSA (DS 6.4.17).
constexpr uint8_t kClockDivider = 31;          ///< CDR (DS 6.5.4).

/// Bytes of address space one chip decodes; a port-mapped chip takes this many ports.
constexpr uint16_t kWindowSize = 32;

// MOD bits (DS 6.4.3).
constexpr uint8_t kModeReset = 1u << 0;          ///< RM: reset mode; the chip leaves the bus.
constexpr uint8_t kModeListenOnly = 1u << 1;     ///< LOM: receive, never acknowledge or send.
constexpr uint8_t kModeSelfTest = 1u << 2;       ///< STM: a transmission succeeds without acknowledge.
constexpr uint8_t kModeSingleFilter = 1u << 3;   ///< AFM: one 32-bit filter instead of two 16-bit ones.
constexpr uint8_t kModeSleep = 1u << 4;          ///< SM.

// CMR bits (DS 6.4.4).
constexpr uint8_t kCommandTransmit = 1u << 0;            ///< TR: send the transmit buffer.
constexpr uint8_t kCommandAbort = 1u << 1;               ///< AT: cancel a pending transmission not yet under way.
constexpr uint8_t kCommandReleaseBuffer = 1u << 2;       ///< RRB: free the receive buffer's first message.
constexpr uint8_t kCommandClearOverrun = 1u << 3;        ///< CDO: clear the data overrun status.
constexpr uint8_t kCommandSelfReception = 1u << 4;       ///< SRR: send and receive the frame itself.
/// TR and AT together: a single-shot transmission, not repeated after an error or lost arbitration (DS 6.4.4 note).
constexpr uint8_t kCommandSingleShot = kCommandTransmit | kCommandAbort;

// SR bits (DS 6.4.5).
constexpr uint8_t kStatusReceiveBuffer = 1u << 0;     ///< RBS: at least one message in the receive FIFO.
constexpr uint8_t kStatusDataOverrun = 1u << 1;       ///< DOS: a message was lost, the FIFO was full.
constexpr uint8_t kStatusTransmitBuffer = 1u << 2;    ///< TBS: the CPU may write the transmit buffer.
constexpr uint8_t kStatusTransmitComplete = 1u << 3;  ///< TCS: the last requested transmission completed.
constexpr uint8_t kStatusReceiving = 1u << 4;         ///< RS.
constexpr uint8_t kStatusTransmitting = 1u << 5;      ///< TS.
constexpr uint8_t kStatusError = 1u << 6;             ///< ES: an error counter reached the warning limit.
constexpr uint8_t kStatusBusOff = 1u << 7;            ///< BS: bus-off; the chip has entered reset mode.

// IR and IER bits, one position each (DS 6.4.6, 6.4.7).
constexpr uint8_t kInterruptReceive = 1u << 0;        ///< RI: a message is in the receive FIFO.
constexpr uint8_t kInterruptTransmit = 1u << 1;       ///< TI: the transmit buffer became free.
constexpr uint8_t kInterruptErrorWarning = 1u << 2;   ///< EI: ES or BS changed.
constexpr uint8_t kInterruptDataOverrun = 1u << 3;    ///< DOI.
constexpr uint8_t kInterruptWakeUp = 1u << 4;         ///< WUI.
constexpr uint8_t kInterruptErrorPassive = 1u << 5;   ///< EPI: error-passive entered or left.
constexpr uint8_t kInterruptArbitrationLost = 1u << 6; ///< ALI: ALC holds the bit.
constexpr uint8_t kInterruptBusError = 1u << 7;       ///< BEI: ECC holds the error.

// BTR0 fields (DS 6.5.1).
constexpr uint8_t kBtr0PrescalerMask = 0x3F;  ///< BRP: tq = 2 * tCLK * (BRP + 1).
constexpr unsigned kBtr0JumpWidthShift = 6;   ///< SJW: jump width = tq * (SJW + 1).
constexpr uint8_t kBtr0JumpWidthMask = 0x03;

// BTR1 fields (DS 6.5.2).
constexpr uint8_t kBtr1Segment1Mask = 0x0F;   ///< TSEG1: tTSEG1 = tq * (TSEG1 + 1).
constexpr unsigned kBtr1Segment2Shift = 4;    ///< TSEG2: tTSEG2 = tq * (TSEG2 + 1).
constexpr uint8_t kBtr1Segment2Mask = 0x07;
constexpr uint8_t kBtr1TripleSampling = 1u << 7; ///< SAM: sample the bus three times (slow buses only).

// OCR (DS 6.5.3): normal output mode, TX0 push-pull, TX1 floating,
// the wiring of a card with a standard transceiver and Linux's default.
constexpr uint8_t kOutputControlNormalPushPull = 0x1A;

// ECC fields (DS 6.4.9).
constexpr unsigned kEccErrorCodeShift = 6;    ///< ERRC: bit, form, stuff or other error.
constexpr uint8_t kEccErrorCodeMask = 0x03;
constexpr uint8_t kEccErrorCodeBit = 0;
constexpr uint8_t kEccErrorCodeForm = 1;
constexpr uint8_t kEccErrorCodeStuff = 2;
constexpr uint8_t kEccErrorCodeOther = 3;
constexpr uint8_t kEccDirectionReceive = 1u << 5; ///< DIR: the error happened while receiving.
constexpr uint8_t kEccSegmentMask = 0x1F;     ///< SEG: where in the frame (0x19 is the ACK slot).
constexpr uint8_t kEccSegmentAckSlot = 0x19;

// Frame information byte of the frame buffer (DS 6.4.13).
constexpr uint8_t kFrameExtended = 1u << 7;   ///< FF: extended (29-bit) frame format.
constexpr uint8_t kFrameRemote = 1u << 6;     ///< RTR.
constexpr uint8_t kFrameLengthMask = 0x0F;    ///< DLC.

/// Offsets inside the frame buffer: standard frames carry two identifier
/// bytes, extended frames four, and the data follows (DS 6.4.13).
constexpr uint8_t kStandardDataOffset = 3;
constexpr uint8_t kExtendedDataOffset = 5;

// CDR bits (DS 6.5.4).
constexpr uint8_t kClockDividerPeliCan = 1u << 7;     ///< CAN mode: PeliCAN.
constexpr uint8_t kClockDividerBypassComparator = 1u << 6; ///< CBP: bypass the input comparator (with an external transceiver).
constexpr uint8_t kClockDividerClockOff = 1u << 3;    ///< Clock off: CLKOUT disabled.

/// The error warning limit after a hardware reset (DS 6.4.10).
constexpr uint8_t kDefaultErrorWarningLimit = 96;
/// The transmit error count at which the chip goes bus-off (ISO 11898-1 fault confinement).
constexpr unsigned kBusOffErrorCount = 256;
/// The error count from which a node is error-passive (ISO 11898-1 fault confinement).
constexpr unsigned kErrorPassiveCount = 128;

} // namespace sja1000::reg
