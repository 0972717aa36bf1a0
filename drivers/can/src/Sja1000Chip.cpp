#include <sja1000/Sja1000Chip.hpp>

namespace sja1000 {

using dcos::Status;

namespace {

// The four bytes of the acceptance code or mask, most significant first,
// as ACR0..ACR3 and AMR0..AMR3 take them (DS 6.4.15).
uint8_t byteOf(uint32_t word, unsigned index) { return static_cast<uint8_t>(word >> (24 - 8 * index)); }

// The clock divider every chip gets: PeliCAN mode, the comparator bypassed
// (the card has an external transceiver) and CLKOUT off (nothing uses it).
constexpr uint8_t kClockDivider = reg::kClockDividerPeliCan | reg::kClockDividerBypassComparator |
                                  reg::kClockDividerClockOff;

} // namespace

Status Sja1000Chip::probe() const
{
    // An empty ISA bus reads all ones; a chip never reports every MOD bit.
    if (read(reg::kMode) == 0xFF) {
        return Status::NotFound;
    }
    if (enterReset() != Status::Ok) {
        return Status::NotFound;
    }
    write(reg::kClockDivider, kClockDivider);
    if ((read(reg::kClockDivider) & reg::kClockDividerPeliCan) == 0) {
        return Status::NotFound;
    }
    return Status::Ok;
}

Status Sja1000Chip::enterReset() const
{
    for (unsigned attempt = 0; attempt < kModeChangeReads; ++attempt) {
        const uint8_t mode = read(reg::kMode);
        if ((mode & reg::kModeReset) != 0) {
            return Status::Ok;
        }
        write(reg::kMode, reg::kModeReset);
    }
    return Status::Busy;
}

Status Sja1000Chip::configure(const BitTiming& timing, const AcceptanceFilter& filter, uint8_t interrupts) const
{
    if (!inReset()) {
        return Status::Busy; // BTR, OCR, ACR and AMR are written only in reset mode (DS 6.4.1).
    }
    write(reg::kClockDivider, kClockDivider);
    write(reg::kInterruptEnable, 0);
    write(reg::kBusTiming0, timing.btr0);
    write(reg::kBusTiming1, timing.btr1);
    write(reg::kOutputControl, reg::kOutputControlNormalPushPull);
    for (unsigned i = 0; i < 4; ++i) {
        write(static_cast<uint8_t>(reg::kAcceptanceCode0 + i), byteOf(filter.code, i));
        write(static_cast<uint8_t>(reg::kAcceptanceMask0 + i), byteOf(filter.mask, i));
    }
    write(reg::kErrorWarningLimit, reg::kDefaultErrorWarningLimit);
    // The counters can be written only in reset mode; a restart after
    // bus-off begins with a clean slate, as the fault-confinement rules
    // would give it after 128 times 11 recessive bits.
    write(reg::kRxErrorCounter, 0);
    write(reg::kTxErrorCounter, 0);
    (void)read(reg::kInterrupt); // Drops whatever was pending from before.
    write(reg::kInterruptEnable, interrupts);
    return Status::Ok;
}

Status Sja1000Chip::start(BusMode mode) const
{
    uint8_t bits = reg::kModeSingleFilter;
    if (mode == BusMode::ListenOnly) {
        bits |= reg::kModeListenOnly;
    } else if (mode == BusMode::SelfTest) {
        bits |= reg::kModeSelfTest;
    }
    for (unsigned attempt = 0; attempt < kModeChangeReads; ++attempt) {
        write(reg::kMode, bits);
        if ((read(reg::kMode) & reg::kModeReset) == 0) {
            return Status::Ok;
        }
    }
    return Status::Busy;
}

bool Sja1000Chip::inReset() const { return (read(reg::kMode) & reg::kModeReset) != 0; }

void Sja1000Chip::writeTransmitBuffer(const can::CanFrame& frame) const
{
    uint8_t information = static_cast<uint8_t>(frame.length() & reg::kFrameLengthMask);
    if (frame.isRemote()) {
        information |= reg::kFrameRemote;
    }
    uint8_t offset = reg::kFrameBuffer;
    const uint32_t id = frame.id();
    if (frame.isExtended()) {
        // ID.28-21, ID.20-13, ID.12-5, then ID.4-0 in bits 7:3.
        write(offset++, static_cast<uint8_t>(information | reg::kFrameExtended));
        write(offset++, static_cast<uint8_t>(id >> 21));
        write(offset++, static_cast<uint8_t>(id >> 13));
        write(offset++, static_cast<uint8_t>(id >> 5));
        write(offset++, static_cast<uint8_t>(id << 3));
    } else {
        // ID.28-21, then ID.20-18 in bits 7:5: the 11 bits left-aligned.
        write(offset++, information);
        write(offset++, static_cast<uint8_t>(id >> 3));
        write(offset++, static_cast<uint8_t>(id << 5));
    }
    if (!frame.isRemote()) {
        for (uint8_t i = 0; i < frame.length(); ++i) {
            write(offset++, frame.byte(i));
        }
    }
}

void Sja1000Chip::transmit(bool selfReception, bool singleShot) const
{
    uint8_t command = selfReception ? reg::kCommandSelfReception : reg::kCommandTransmit;
    if (singleShot) {
        command |= reg::kCommandAbort;
    }
    write(reg::kCommand, command);
}

void Sja1000Chip::abortTransmission() const { write(reg::kCommand, reg::kCommandAbort); }

can::LinkResult<can::CanFrame> Sja1000Chip::readReceiveBuffer() const
{
    const uint8_t information = read(reg::kFrameBuffer);
    const bool extended = (information & reg::kFrameExtended) != 0;
    const bool remote = (information & reg::kFrameRemote) != 0;
    const uint8_t length = information & reg::kFrameLengthMask;
    uint32_t id;
    uint8_t dataOffset;
    if (extended) {
        id = (uint32_t{read(reg::kFrameBuffer + 1)} << 21) | (uint32_t{read(reg::kFrameBuffer + 2)} << 13) |
             (uint32_t{read(reg::kFrameBuffer + 3)} << 5) | (uint32_t{read(reg::kFrameBuffer + 4)} >> 3);
        dataOffset = reg::kFrameBuffer + reg::kExtendedDataOffset;
    } else {
        id = (uint32_t{read(reg::kFrameBuffer + 1)} << 3) | (uint32_t{read(reg::kFrameBuffer + 2)} >> 5);
        dataOffset = reg::kFrameBuffer + reg::kStandardDataOffset;
    }
    const can::IdFormat format = extended ? can::IdFormat::Extended : can::IdFormat::Standard;
    can::LinkResult<can::CanFrame> frame = can::LinkError::InvalidDataLength;
    if (remote) {
        frame = can::CanFrame::makeRemote(id, format, length);
    } else if (length <= can::CanFrame::kMaxDataLength) {
        uint8_t data[can::CanFrame::kMaxDataLength];
        for (uint8_t i = 0; i < length; ++i) {
            data[i] = read(static_cast<uint8_t>(dataOffset + i));
        }
        frame = can::CanFrame::makeData(id, format, data, length);
    }
    write(reg::kCommand, reg::kCommandReleaseBuffer);
    return frame;
}

void Sja1000Chip::clearOverrun() const { write(reg::kCommand, reg::kCommandClearOverrun); }

uint8_t Sja1000Chip::interrupts() const { return read(reg::kInterrupt); }

uint8_t Sja1000Chip::status() const { return read(reg::kStatus); }

ErrorCounters Sja1000Chip::errorCounters() const
{
    return {read(reg::kRxErrorCounter), read(reg::kTxErrorCounter)};
}

uint8_t Sja1000Chip::errorCode() const { return read(reg::kErrorCodeCapture); }

uint8_t Sja1000Chip::arbitrationLostBit() const { return read(reg::kArbitrationLostCapture); }

uint8_t Sja1000Chip::receivedMessages() const { return read(reg::kRxMessageCounter); }

ErrorState Sja1000Chip::errorState() const
{
    const uint8_t status = read(reg::kStatus);
    if ((status & reg::kStatusBusOff) != 0) {
        return ErrorState::BusOff;
    }
    const ErrorCounters counters = errorCounters();
    if (counters.transmit >= reg::kErrorPassiveCount || counters.receive >= reg::kErrorPassiveCount) {
        return ErrorState::Passive;
    }
    return (status & reg::kStatusError) != 0 ? ErrorState::Warning : ErrorState::Active;
}

} // namespace sja1000
