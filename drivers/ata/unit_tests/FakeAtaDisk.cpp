#include "FakeAtaDisk.hpp"

namespace ata_test {

namespace reg = ata::reg;

FakeAtaDisk::FakeAtaDisk(uint32_t sectors, std::string model) : sectors_(sectors), model_(std::move(model))
{
    commandPorts_.disk = this;
    controlPorts_.disk = this;
    port_io_mock::attach(reg::kPrimaryCommandBase, reg::kCommandWindowSize, &commandPorts_);
    port_io_mock::attach(reg::kPrimaryControlBase, reg::kControlWindowSize, &controlPorts_);
}

std::vector<uint8_t> FakeAtaDisk::sector(uint32_t lba) const
{
    const auto found = data_.find(lba);
    return found != data_.end() ? found->second : std::vector<uint8_t>(reg::kSectorSize, 0);
}

void FakeAtaDisk::setSector(uint32_t lba, const std::vector<uint8_t>& bytes) { data_[lba] = bytes; }

uint8_t FakeAtaDisk::status() const
{
    if (hung_ || busyReads_ > 0) {
        // Each read of a busy device's status counts down its busy time.
        auto* self = const_cast<FakeAtaDisk*>(this);
        if (!hung_) {
            --self->busyReads_;
        }
        return reg::kStatusBusy;
    }
    uint8_t status = reg::kStatusReady;
    if (transfer_ != Transfer::None) {
        status |= reg::kStatusDataRequest;
    }
    if (errorBit_) {
        status |= reg::kStatusError;
    }
    return status;
}

uint32_t FakeAtaDisk::address() const
{
    return registers_[reg::kLbaLow] | (registers_[reg::kLbaMid] << 8) | (registers_[reg::kLbaHigh] << 16) |
           ((registers_[reg::kDevice] & 0x0F) << 24);
}

uint16_t FakeAtaDisk::readCommand(uint16_t offset, int width)
{
    if (offset == reg::kData && width == 16) {
        if (transfer_ != Transfer::In || position_ >= buffer_.size()) {
            return 0xFFFF;
        }
        const uint16_t word = static_cast<uint16_t>(buffer_[position_] | (buffer_[position_ + 1] << 8));
        position_ += 2;
        if (position_ == buffer_.size()) {
            nextSector();
        }
        return word;
    }
    if (offset == reg::kStatus) {
        return status();
    }
    if (offset == reg::kError) {
        return error_;
    }
    return registers_[offset];
}

void FakeAtaDisk::writeCommand(uint16_t offset, uint16_t value, int width)
{
    if (offset == reg::kData && width == 16) {
        if (transfer_ != Transfer::Out || position_ >= buffer_.size()) {
            return;
        }
        buffer_[position_++] = static_cast<uint8_t>(value);
        buffer_[position_++] = static_cast<uint8_t>(value >> 8);
        if (position_ == buffer_.size()) {
            data_[transferLba_] = buffer_;
            ++transferLba_;
            --remaining_;
            position_ = 0;
            busyReads_ = 2;
            if (remaining_ == 0) {
                transfer_ = Transfer::None;
            } else if (failing_.count(transferLba_) != 0) {
                error_ = failing_[transferLba_];
                errorBit_ = true;
                transfer_ = Transfer::None;
            }
        }
        return;
    }
    if (offset == reg::kCommand) {
        execute(static_cast<uint8_t>(value));
        return;
    }
    registers_[offset] = static_cast<uint8_t>(value);
}

void FakeAtaDisk::nextSector()
{
    position_ = 0;
    if (identifying_ || --remaining_ == 0) {
        transfer_ = Transfer::None;
        identifying_ = false;
        return;
    }
    ++transferLba_;
    busyReads_ = 2;
    if (failing_.count(transferLba_) != 0) {
        error_ = failing_[transferLba_];
        errorBit_ = true;
        transfer_ = Transfer::None;
        return;
    }
    buffer_ = sector(transferLba_);
}

void FakeAtaDisk::execute(uint8_t command)
{
    ++commands;
    errorBit_ = false;
    error_ = 0;
    busyReads_ = 3;
    const uint32_t count = registers_[reg::kSectorCount] == 0 ? 256 : registers_[reg::kSectorCount];
    const uint32_t lba = address();
    switch (command) {
    case reg::kCommandIdentifyDevice: {
        std::vector<uint16_t> words(reg::kWordsPerSector, 0);
        words[reg::kIdentifyCapabilitiesWord] = lba_ ? reg::kCapabilityLba : 0;
        words[reg::kIdentifyLbaSectorsWord] = static_cast<uint16_t>(sectors_);
        words[reg::kIdentifyLbaSectorsWord + 1] = static_cast<uint16_t>(sectors_ >> 16);
        std::string padded = model_;
        padded.resize(reg::kIdentifyModelWords * 2, ' ');
        for (unsigned i = 0; i < reg::kIdentifyModelWords; ++i) {
            words[reg::kIdentifyModelWord + i] =
                static_cast<uint16_t>((static_cast<uint8_t>(padded[2 * i]) << 8) | static_cast<uint8_t>(padded[2 * i + 1]));
        }
        buffer_.assign(reg::kSectorSize, 0);
        for (unsigned i = 0; i < reg::kWordsPerSector; ++i) {
            buffer_[2 * i] = static_cast<uint8_t>(words[i]);
            buffer_[2 * i + 1] = static_cast<uint8_t>(words[i] >> 8);
        }
        position_ = 0;
        identifying_ = true;
        transfer_ = Transfer::In;
        return;
    }
    case reg::kCommandReadSectors:
    case reg::kCommandWriteSectors:
        if ((registers_[reg::kDevice] & 0x40) == 0 || lba + count > sectors_) {
            error_ = 0x10; // IDNF: no such sector
            errorBit_ = true;
            transfer_ = Transfer::None;
            return;
        }
        transferLba_ = lba;
        remaining_ = count;
        position_ = 0;
        if (failing_.count(lba) != 0 ||
            (command == reg::kCommandWriteSectors && failingWrites_.count(lba) != 0)) {
            error_ = failing_.count(lba) != 0 ? failing_[lba] : failingWrites_[lba];
            errorBit_ = true;
            transfer_ = Transfer::None;
            return;
        }
        if (command == reg::kCommandReadSectors) {
            buffer_ = sector(lba);
            transfer_ = Transfer::In;
        } else {
            buffer_.assign(reg::kSectorSize, 0);
            transfer_ = Transfer::Out;
        }
        return;
    case reg::kCommandFlushCache:
        ++flushes;
        transfer_ = Transfer::None;
        return;
    default:
        error_ = 0x04; // ABRT
        errorBit_ = true;
        transfer_ = Transfer::None;
        return;
    }
}

} // namespace ata_test
