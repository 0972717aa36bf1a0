#include <iobus/MfioChip.hpp>

namespace iobus {

using namespace mfio;

dcos::Status MfioChip::probe(MfioIdentity& identity) const
{
    identity.id = window_.read16(kIdRegister);
    if (identity.id != kBoardId) {
        // An empty slot reads all ones; another board answers something else.
        identity.revision = 0;
        return dcos::Status::NotFound;
    }
    identity.revision = window_.read16(kRevisionRegister);
    if ((identity.revision >> 8) != kSupportedMajorRevision) {
        return dcos::Status::NotSupported;
    }
    return dcos::Status::Ok;
}

void MfioChip::reset() const { window_.write16(kControlRegister, kControlReset); }

void MfioChip::setControl(bool interruptEnable) const
{
    window_.write16(kControlRegister, interruptEnable ? kControlIrqEnable : kResetControl);
}

uint16_t MfioChip::control() const { return window_.read16(kControlRegister); }

uint16_t MfioChip::status() const { return window_.read16(kStatusRegister); }

void MfioChip::startConversion(unsigned channel) const
{
    window_.write16(kAdcStartRegister, static_cast<uint16_t>(channel & kAdcStartChannelMask));
}

uint16_t MfioChip::data() const { return window_.read16(kAdcDataRegister); }

void MfioChip::acknowledge() const { window_.write16(kIrqAckRegister, kIrqAckClear); }

void MfioChip::writeGains(uint16_t gains) const { window_.write16(kGainRegister, gains); }

uint16_t MfioChip::gains() const { return window_.read16(kGainRegister); }

void MfioChip::writeDac(unsigned channel, uint16_t code) const
{
    window_.write16(dacRegister(channel % kAnalogOutputs), static_cast<uint16_t>(code & kDacCodeMask));
}

uint16_t MfioChip::dac(unsigned channel) const
{
    return static_cast<uint16_t>(window_.read16(dacRegister(channel % kAnalogOutputs)) & kDacCodeMask);
}

uint16_t MfioChip::digitalInputs() const { return window_.read16(kDigitalInputRegister); }

void MfioChip::writeDigitalOutputs(uint16_t bits) const { window_.write16(kDigitalOutputRegister, bits); }

uint16_t MfioChip::digitalOutputs() const { return window_.read16(kDigitalOutputRegister); }

} // namespace iobus
