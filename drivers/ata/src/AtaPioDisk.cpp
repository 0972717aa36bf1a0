#include <ata/AtaPioDisk.hpp>
#include <ata/AtaRegisters.hpp>

namespace ata {

namespace {

// Sectors one command moves: the sector count register's 0 means 256.
constexpr uint32_t kSectorsPerCommand = 256;

} // namespace

const char* ataErrorText(AtaError error)
{
    switch (error) {
    case AtaError::Ok: return "done";
    case AtaError::NoDevice: return "no ATA device answers (no card in the socket?)";
    case AtaError::Timeout: return "the card did not answer in time";
    case AtaError::DeviceError: return "the card reported an error";
    case AtaError::OutOfRange: return "a sector beyond the card's last";
    }
    return "unknown ATA error";
}

AtaPioDisk::AtaPioDisk(const arch_x86::IoWindow& command, const arch_x86::IoWindow& control, uint32_t pollLimit)
    : command_(command), control_(control), pollLimit_(pollLimit)
{
}

AtaPioDisk AtaPioDisk::primary()
{
    return AtaPioDisk(arch_x86::IoWindow::ports(reg::kPrimaryCommandBase, reg::kCommandWindowSize),
                      arch_x86::IoWindow::ports(reg::kPrimaryControlBase, reg::kControlWindowSize));
}

AtaError AtaPioDisk::waitWhileBusy(uint8_t& status)
{
    // The alternate status does not acknowledge an interrupt; with nIEN set
    // there is none, but the data-in protocol (ATA-6 9.7) reads it anyway.
    for (uint32_t poll = 0; poll < pollLimit_; ++poll) {
        status = control_.read8(reg::kAlternateStatus);
        if ((status & reg::kStatusBusy) == 0) {
            return AtaError::Ok;
        }
    }
    return AtaError::Timeout;
}

AtaError AtaPioDisk::waitForData()
{
    uint8_t status = 0;
    const AtaError busy = waitWhileBusy(status);
    if (busy != AtaError::Ok) {
        return busy;
    }
    if ((status & (reg::kStatusError | reg::kStatusDeviceFault)) != 0) {
        error_ = command_.read8(reg::kError);
        (void)command_.read8(reg::kStatus);
        return AtaError::DeviceError;
    }
    if ((status & reg::kStatusDataRequest) == 0) {
        return AtaError::Timeout; // Not busy, no error, and no data: the device lost the command.
    }
    return AtaError::Ok;
}

AtaError AtaPioDisk::finish()
{
    uint8_t status = 0;
    const AtaError busy = waitWhileBusy(status);
    if (busy != AtaError::Ok) {
        return busy;
    }
    // Reading the status register ends the command (ATA-6 9.5, 9.7).
    status = command_.read8(reg::kStatus);
    if ((status & (reg::kStatusError | reg::kStatusDeviceFault)) != 0) {
        error_ = command_.read8(reg::kError);
        return AtaError::DeviceError;
    }
    return AtaError::Ok;
}

AtaError AtaPioDisk::issue(uint8_t commandCode, uint32_t lba, uint32_t count)
{
    uint8_t status = 0;
    AtaError ready = waitWhileBusy(status);
    if (ready != AtaError::Ok) {
        return ready;
    }
    command_.write8(reg::kDevice, static_cast<uint8_t>(reg::kDeviceLbaMaster | ((lba >> 24) & 0x0F)));
    ready = waitWhileBusy(status);
    if (ready != AtaError::Ok) {
        return ready;
    }
    command_.write8(reg::kSectorCount, static_cast<uint8_t>(count & 0xFF));
    command_.write8(reg::kLbaLow, static_cast<uint8_t>(lba));
    command_.write8(reg::kLbaMid, static_cast<uint8_t>(lba >> 8));
    command_.write8(reg::kLbaHigh, static_cast<uint8_t>(lba >> 16));
    command_.write8(reg::kCommand, commandCode);
    // The device sets BSY within 400 ns of the command (ATA-6 9.5): four
    // reads of the alternate status make sure the next poll sees it.
    for (int i = 0; i < 4; ++i) {
        (void)control_.read8(reg::kAlternateStatus);
    }
    return AtaError::Ok;
}

AtaError AtaPioDisk::identify()
{
    control_.write8(reg::kDeviceControl, reg::kControlInterruptsOff);
    command_.write8(reg::kDevice, reg::kDeviceLbaMaster);
    const uint8_t first = command_.read8(reg::kStatus);
    // An empty ISA channel floats high (0xFF); a missing master reads 0.
    if (first == 0xFF || first == 0x00) {
        return AtaError::NoDevice;
    }
    const AtaError issued = issue(reg::kCommandIdentifyDevice, 0, 0);
    if (issued != AtaError::Ok) {
        return issued;
    }
    const AtaError data = waitForData();
    if (data != AtaError::Ok) {
        return data == AtaError::DeviceError ? AtaError::NoDevice : data;
    }
    uint16_t words[reg::kWordsPerSector];
    for (uint16_t& word : words) {
        word = command_.read16(reg::kData);
    }
    const AtaError done = finish();
    if (done != AtaError::Ok) {
        return done;
    }
    if ((words[reg::kIdentifyCapabilitiesWord] & reg::kCapabilityLba) == 0) {
        return AtaError::NoDevice; // DCOS addresses cards by LBA only.
    }
    sectorCount_ = static_cast<uint32_t>(words[reg::kIdentifyLbaSectorsWord]) |
                   (static_cast<uint32_t>(words[reg::kIdentifyLbaSectorsWord + 1]) << 16);
    if (sectorCount_ > reg::kLba28Sectors) {
        sectorCount_ = reg::kLba28Sectors;
    }
    size_t length = 0;
    for (unsigned i = 0; i < reg::kIdentifyModelWords; ++i) {
        const uint16_t pair = words[reg::kIdentifyModelWord + i];
        model_[length++] = static_cast<char>(pair >> 8);
        model_[length++] = static_cast<char>(pair & 0xFF);
    }
    while (length > 0 && (model_[length - 1] == ' ' || model_[length - 1] == '\0')) {
        --length;
    }
    model_[length] = '\0';
    return sectorCount_ != 0 ? AtaError::Ok : AtaError::NoDevice;
}

AtaError AtaPioDisk::checkRange(uint32_t lba, uint32_t count) const
{
    if (count == 0 || lba >= sectorCount_ || count > sectorCount_ - lba) {
        return AtaError::OutOfRange;
    }
    return AtaError::Ok;
}

AtaError AtaPioDisk::transfer(uint8_t command, uint32_t lba, uint32_t count, uint16_t* in, const uint16_t* out)
{
    const AtaError range = checkRange(lba, count);
    if (range != AtaError::Ok) {
        return range;
    }
    while (count > 0) {
        const uint32_t chunk = count < kSectorsPerCommand ? count : kSectorsPerCommand;
        AtaError error = issue(command, lba, chunk);
        for (uint32_t sector = 0; error == AtaError::Ok && sector < chunk; ++sector) {
            error = waitForData();
            for (unsigned i = 0; error == AtaError::Ok && i < reg::kWordsPerSector; ++i) {
                if (in != nullptr) {
                    *in++ = command_.read16(reg::kData);
                } else {
                    command_.write16(reg::kData, *out++);
                }
            }
        }
        if (error == AtaError::Ok) {
            error = finish();
        }
        if (error != AtaError::Ok) {
            return error;
        }
        lba += chunk;
        count -= chunk;
    }
    return AtaError::Ok;
}

AtaError AtaPioDisk::read(uint32_t lba, uint32_t count, void* buffer)
{
    return transfer(reg::kCommandReadSectors, lba, count, static_cast<uint16_t*>(buffer), nullptr);
}

AtaError AtaPioDisk::write(uint32_t lba, uint32_t count, const void* buffer)
{
    const AtaError written =
        transfer(reg::kCommandWriteSectors, lba, count, nullptr, static_cast<const uint16_t*>(buffer));
    if (written != AtaError::Ok) {
        return written;
    }
    // The card may hold the data in a cache: the write is done when it is
    // on the medium, so that a power cut after success loses nothing.
    AtaError flushed = issue(reg::kCommandFlushCache, 0, 0);
    if (flushed == AtaError::Ok) {
        flushed = finish();
    }
    return flushed;
}

} // namespace ata
