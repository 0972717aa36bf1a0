#include <ata/AtaPioDisk.hpp>
#include <ata/AtaRegisters.hpp>

#include "FakeAtaDisk.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace {

using ata::AtaError;
using ata::AtaPioDisk;
namespace reg = ata::reg;

class AtaPioDiskTest : public ::testing::Test {
protected:
    void SetUp() override { port_io_mock::reset(); }
    void TearDown() override { port_io_mock::reset(); }

    static AtaPioDisk disk()
    {
        return AtaPioDisk(arch_x86::IoWindow::ports(reg::kPrimaryCommandBase, reg::kCommandWindowSize),
                          arch_x86::IoWindow::ports(reg::kPrimaryControlBase, reg::kControlWindowSize), 1000);
    }

    static std::vector<uint8_t> pattern(uint32_t sectors, uint8_t seed)
    {
        std::vector<uint8_t> bytes(sectors * reg::kSectorSize);
        for (size_t i = 0; i < bytes.size(); ++i) {
            bytes[i] = static_cast<uint8_t>(seed + i * 13 + (i >> 9));
        }
        return bytes;
    }
};

TEST_F(AtaPioDiskTest, IdentifyReadsTheSizeAndModelAndTurnsTheInterruptOff)
{
    ata_test::FakeAtaDisk card(16384, "SanDisk SDCFB-8");
    AtaPioDisk driver = disk();
    ASSERT_EQ(driver.identify(), AtaError::Ok);
    EXPECT_EQ(driver.sectorCount(), 16384u);
    EXPECT_STREQ(driver.model(), "SanDisk SDCFB-8");
    EXPECT_EQ(card.deviceControl, reg::kControlInterruptsOff);
}

TEST_F(AtaPioDiskTest, NothingOnTheChannelIsNoDevice)
{
    port_io_mock::setDefaultRead(reg::kPrimaryCommandBase + reg::kStatus, 0xFF);
    AtaPioDisk driver = disk();
    EXPECT_EQ(driver.identify(), AtaError::NoDevice);
    uint8_t buffer[512];
    EXPECT_EQ(driver.read(0, 1, buffer), AtaError::OutOfRange) << "no transfer before a successful identify";
}

TEST_F(AtaPioDiskTest, ADeviceWithoutLbaIsRefused)
{
    ata_test::FakeAtaDisk card(16384);
    card.withoutLba();
    AtaPioDisk driver = disk();
    EXPECT_EQ(driver.identify(), AtaError::NoDevice);
}

TEST_F(AtaPioDiskTest, ReadsAcrossTheCommandLimitInOrder)
{
    ata_test::FakeAtaDisk card(16384);
    const std::vector<uint8_t> written = pattern(300, 7);
    for (uint32_t i = 0; i < 300; ++i) {
        card.setSector(1000 + i, std::vector<uint8_t>(written.begin() + i * 512, written.begin() + (i + 1) * 512));
    }
    AtaPioDisk driver = disk();
    ASSERT_EQ(driver.identify(), AtaError::Ok);
    const unsigned before = card.commands;
    std::vector<uint8_t> read(300 * 512);
    ASSERT_EQ(driver.read(1000, 300, read.data()), AtaError::Ok);
    EXPECT_EQ(read, written);
    EXPECT_EQ(card.commands - before, 2u) << "256 sectors, then 44";
}

TEST_F(AtaPioDiskTest, WritesThenFlushesTheCache)
{
    ata_test::FakeAtaDisk card(16384);
    AtaPioDisk driver = disk();
    ASSERT_EQ(driver.identify(), AtaError::Ok);
    const std::vector<uint8_t> bytes = pattern(3, 99);
    ASSERT_EQ(driver.write(16381, 3, bytes.data()), AtaError::Ok) << "the card's last three sectors";
    for (uint32_t i = 0; i < 3; ++i) {
        EXPECT_EQ(card.sector(16381 + i), std::vector<uint8_t>(bytes.begin() + i * 512, bytes.begin() + (i + 1) * 512));
    }
    EXPECT_EQ(card.flushes, 1u);
}

TEST_F(AtaPioDiskTest, RefusesSectorsBeyondTheCardAndEmptyTransfers)
{
    ata_test::FakeAtaDisk card(100);
    AtaPioDisk driver = disk();
    ASSERT_EQ(driver.identify(), AtaError::Ok);
    uint8_t buffer[2 * 512] = {};
    EXPECT_EQ(driver.read(100, 1, buffer), AtaError::OutOfRange);
    EXPECT_EQ(driver.read(99, 2, buffer), AtaError::OutOfRange);
    EXPECT_EQ(driver.write(0xFFFFFFFF, 1, buffer), AtaError::OutOfRange);
    EXPECT_EQ(driver.read(5, 0, buffer), AtaError::OutOfRange);
    EXPECT_EQ(driver.read(99, 1, buffer), AtaError::Ok);
}

TEST_F(AtaPioDiskTest, ABadSectorIsADeviceErrorWithTheErrorRegister)
{
    ata_test::FakeAtaDisk card(1000);
    card.failSector(12, 0x40); // UNC: uncorrectable data
    AtaPioDisk driver = disk();
    ASSERT_EQ(driver.identify(), AtaError::Ok);
    std::vector<uint8_t> buffer(8 * 512);
    EXPECT_EQ(driver.read(10, 4, buffer.data()), AtaError::DeviceError);
    EXPECT_EQ(driver.errorRegister(), 0x40);
    EXPECT_EQ(driver.write(12, 1, buffer.data()), AtaError::DeviceError);
    EXPECT_EQ(card.flushes, 0u) << "no flush after a failed write";
    EXPECT_EQ(driver.read(20, 4, buffer.data()), AtaError::Ok) << "the card goes on working";
}

TEST_F(AtaPioDiskTest, ADeviceThatStaysBusyTimesOut)
{
    ata_test::FakeAtaDisk card(1000);
    AtaPioDisk driver = disk();
    ASSERT_EQ(driver.identify(), AtaError::Ok);
    card.hang();
    uint8_t buffer[512];
    EXPECT_EQ(driver.read(0, 1, buffer), AtaError::Timeout);
    EXPECT_EQ(driver.write(0, 1, buffer), AtaError::Timeout);
}

TEST_F(AtaPioDiskTest, EveryErrorHasItsOwnText)
{
    for (int i = 0; i <= static_cast<int>(AtaError::OutOfRange); ++i) {
        for (int j = 0; j < i; ++j) {
            EXPECT_STRNE(ata::ataErrorText(static_cast<AtaError>(i)), ata::ataErrorText(static_cast<AtaError>(j)));
        }
    }
}

} // namespace
