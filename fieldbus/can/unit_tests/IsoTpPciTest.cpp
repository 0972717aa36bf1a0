// N_PCI constants, the STmin encoding and the connection's configuration.
#include <can/IsoTpConfig.hpp>
#include <can/IsoTpPci.hpp>

#include "IsoTpTestSupport.hpp"

#include <gtest/gtest.h>

namespace {

using can::CanFrame;
using can::IdFormat;
using can::IsoTpPci;
using can::LinkError;
using can::PciType;
using namespace isotp_test;

TEST(IsoTpPci, SeparationTimeOfEverySTminValue)
{
    for (unsigned value = 0; value <= 0xFF; ++value) {
        uint32_t expected;
        if (value <= 0x7F) {
            expected = value * 1000000u; // 0x00..0x7F: milliseconds
        } else if (value >= 0xF1 && value <= 0xF9) {
            expected = (value - 0xF0) * 100000u; // 0xF1..0xF9: 100..900 microseconds
        } else {
            expected = 127000000u; // reserved: the longest, 127 ms
        }
        EXPECT_EQ(IsoTpPci::separationTimeNs(static_cast<uint8_t>(value)), expected) << std::hex << value;
    }
}

TEST(IsoTpPci, EncodingRoundsUpToTheNextExpressibleTime)
{
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(0).value(), 0x00);
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(1).value(), 0xF1);
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(100000).value(), 0xF1);
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(100001).value(), 0xF2);
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(450000).value(), 0xF5);
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(900000).value(), 0xF9);
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(900001).value(), 0x01);
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(1000000).value(), 0x01);
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(1000001).value(), 0x02);
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(127000000).value(), 0x7F);
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(127000001).error(), LinkError::InvalidConfiguration);
    EXPECT_EQ(IsoTpPci::encodeSeparationTime(0xFFFFFFFF).error(), LinkError::InvalidConfiguration);
}

TEST(IsoTpPci, EveryValidSTminSurvivesDecodeAndEncode)
{
    for (unsigned value = 0; value <= 0xFF; ++value) {
        const bool reserved = (value >= 0x80 && value <= 0xF0) || value >= 0xFA;
        if (reserved) {
            continue;
        }
        const uint32_t ns = IsoTpPci::separationTimeNs(static_cast<uint8_t>(value));
        EXPECT_EQ(IsoTpPci::encodeSeparationTime(ns).value(), value) << std::hex << value;
    }
}

TEST(IsoTpPci, TypeOfAFrame)
{
    EXPECT_EQ(IsoTpPci::typeOf(incoming({0x03, 1, 2, 3})).value(), PciType::SingleFrame);
    EXPECT_EQ(IsoTpPci::typeOf(incoming({0x10, 0x0A, 1, 2, 3, 4, 5, 6})).value(), PciType::FirstFrame);
    EXPECT_EQ(IsoTpPci::typeOf(incoming({0x21, 1})).value(), PciType::ConsecutiveFrame);
    EXPECT_EQ(IsoTpPci::typeOf(incoming({0x30, 0, 0})).value(), PciType::FlowControl);
    EXPECT_EQ(IsoTpPci::typeOf(incoming({})).error(), LinkError::ShortFrame);
    for (unsigned type = 4; type <= 15; ++type) {
        EXPECT_EQ(IsoTpPci::typeOf(incoming({static_cast<uint8_t>(type << 4), 0, 0})).error(),
                  LinkError::ReservedPciType)
            << type;
    }
}

TEST(IsoTpPci, FramesArePaddedOnlyWhenAsked)
{
    const uint8_t bytes[3] = {0x02, 0xAA, 0xBB};
    can::IsoTpPadding padding;
    const CanFrame plain = IsoTpPci::makeFrame(kTxId, IdFormat::Extended, bytes, 3, padding);
    EXPECT_EQ(bytesOf(plain), (std::vector<uint8_t>{0x02, 0xAA, 0xBB}));
    EXPECT_TRUE(plain.isExtended());
    EXPECT_EQ(plain.id(), kTxId);

    padding.enabled = true;
    const CanFrame padded = IsoTpPci::makeFrame(kTxId, IdFormat::Extended, bytes, 3, padding);
    EXPECT_EQ(bytesOf(padded), (std::vector<uint8_t>{0x02, 0xAA, 0xBB, 0xCC, 0xCC, 0xCC, 0xCC, 0xCC}));
    padding.value = 0x55;
    EXPECT_EQ(bytesOf(IsoTpPci::makeFlowControl(kTxId, IdFormat::Extended, can::FlowStatus::Wait, 4, 0xF2, padding)),
              (std::vector<uint8_t>{0x31, 0x04, 0xF2, 0x55, 0x55, 0x55, 0x55, 0x55}));
}

TEST(IsoTpConfig, DefaultsMatchLinuxCanIsotp)
{
    const can::IsoTpConfig defaults;
    EXPECT_FALSE(defaults.padding.enabled);
    EXPECT_EQ(defaults.padding.value, 0xCC);
    EXPECT_EQ(defaults.blockSize, 0);
    EXPECT_EQ(defaults.separationTimeNs, 0u);
    EXPECT_EQ(defaults.timeoutAsNs, kSecond);
    EXPECT_EQ(defaults.timeoutBsNs, kSecond);
    EXPECT_EQ(defaults.timeoutCrNs, kSecond);
    EXPECT_FALSE(defaults.requirePaddedFrames);
    EXPECT_EQ(config().validate(), LinkError::Ok);
}

TEST(IsoTpConfig, ValuesOutOfRangeAreRefused)
{
    can::IsoTpConfig c = config();
    c.rxId = c.txId;
    EXPECT_EQ(c.validate(), LinkError::InvalidConfiguration);

    c = config();
    c.format = IdFormat::Standard;
    EXPECT_EQ(c.validate(), LinkError::InvalidIdentifier);
    c.txId = 0x7E0;
    c.rxId = 0x7E8;
    EXPECT_EQ(c.validate(), LinkError::Ok);
    c.rxId = 0x800;
    EXPECT_EQ(c.validate(), LinkError::InvalidIdentifier);

    c = config();
    c.txId = 0x20000000;
    EXPECT_EQ(c.validate(), LinkError::InvalidIdentifier);

    c = config();
    c.separationTimeNs = 127000001;
    EXPECT_EQ(c.validate(), LinkError::InvalidConfiguration);
    c.separationTimeNs = 127000000;
    EXPECT_EQ(c.validate(), LinkError::Ok);

    for (int which = 0; which < 3; ++which) {
        c = config();
        (which == 0 ? c.timeoutAsNs : which == 1 ? c.timeoutBsNs : c.timeoutCrNs) = 0;
        EXPECT_EQ(c.validate(), LinkError::InvalidConfiguration) << which;
    }
}

} // namespace
