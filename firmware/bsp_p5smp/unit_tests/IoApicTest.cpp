#include <bsp/IoApic.hpp>

#include "../../arch_x86/unit_tests/PortIoMock.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <utility>
#include <vector>

namespace {

using bsp::IoApic;

// An 82093AA behind the IOREGSEL / IOWIN pair: a write to the select
// register picks a register, and the window then reads or writes it. It
// records every register write, and every state a redirection entry passes
// through, so tests can check the order of a change and not just its end.
class IoApicModel final : public port_io_mock::Responder {
public:
    static constexpr unsigned kPins = 24;

    IoApicModel()
    {
        registers_[IoApic::kIdRegister] = 0x02000000;
        registers_[IoApic::kVersionRegister] = ((kPins - 1) << 16) | 0x11;
        // After reset every entry is masked (datasheet 3.2.4).
        for (unsigned pin = 0; pin < kPins; ++pin) {
            registers_[IoApic::kRedirectionBase + 2 * pin] = IoApic::kMasked;
        }
    }

    uint32_t read(uint16_t offset, int width) override
    {
        EXPECT_EQ(width, 32);
        if (offset == IoApic::kSelect) {
            return select_;
        }
        EXPECT_EQ(offset, IoApic::kWindow);
        return registers_[select_ & 0xFF];
    }

    void write(uint16_t offset, uint32_t value, int width) override
    {
        EXPECT_EQ(width, 32);
        if (offset == IoApic::kSelect) {
            select_ = value;
            return;
        }
        EXPECT_EQ(offset, IoApic::kWindow);
        const uint8_t index = static_cast<uint8_t>(select_);
        // The delivery status and remote IRR bits are read-only.
        if (index >= IoApic::kRedirectionBase && (index - IoApic::kRedirectionBase) % 2 == 0) {
            constexpr uint32_t readOnly = IoApic::kDeliveryPending | IoApic::kRemoteIrr;
            value = (value & ~readOnly) | (registers_[index] & readOnly);
        }
        registers_[index] = value;
        writes.emplace_back(index, value);
        if (index >= IoApic::kRedirectionBase) {
            const unsigned pin = (index - IoApic::kRedirectionBase) / 2;
            states.push_back({registers_[low(pin)], registers_[low(pin) + 1]});
        }
    }

    static uint8_t low(unsigned pin) { return static_cast<uint8_t>(IoApic::kRedirectionBase + 2 * pin); }

    uint32_t registers_[256] = {};
    std::vector<std::pair<uint8_t, uint32_t>> writes;
    std::vector<std::pair<uint32_t, uint32_t>> states; // (low, high) after each write

private:
    uint32_t select_ = 0;
};

constexpr uint16_t kPorts = 0x2000;

class IoApicTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        port_io_mock::reset();
        port_io_mock::attach(kPorts, IoApic::kWindowBytes, &model);
    }
    void TearDown() override { port_io_mock::reset(); }

    IoApicModel model;
    IoApic ioApic{arch_x86::IoWindow::ports(kPorts, IoApic::kWindowBytes)};
};

TEST_F(IoApicTest, ReadsSelectTheRegisterThenReadTheWindow)
{
    EXPECT_EQ(ioApic.id(), 2);
    const std::vector<port_io_mock::Access> expected = {{true, kPorts + 0x00, IoApic::kIdRegister, 32},
                                                        {false, kPorts + 0x10, 0x02000000, 32}};
    EXPECT_EQ(port_io_mock::takeLog(), expected);
    EXPECT_EQ(ioApic.version(), 0x11);
    EXPECT_EQ(ioApic.pinCount(), 24u);
}

TEST_F(IoApicTest, IdIsBits24To27)
{
    model.registers_[IoApic::kIdRegister] = 0xF5000000;
    EXPECT_EQ(ioApic.id(), 5);
}

TEST_F(IoApicTest, PinCountIsBoundedByTheRegisterIndexes)
{
    model.registers_[IoApic::kVersionRegister] = 0x00FF0011;
    EXPECT_EQ(ioApic.pinCount(), IoApic::kMaximumPins);
}

TEST_F(IoApicTest, MaskAllSetsOnlyEveryMaskBit)
{
    model.registers_[IoApicModel::low(3)] = 0x0000A030;
    model.registers_[IoApicModel::low(3) + 1] = 0x01000000;
    ioApic.maskAll();
    for (unsigned pin = 0; pin < IoApicModel::kPins; ++pin) {
        EXPECT_TRUE(ioApic.isMasked(pin)) << pin;
    }
    EXPECT_EQ(ioApic.entryLow(3), 0x0001A030u);
    EXPECT_EQ(ioApic.entryHigh(3), 0x01000000u);
    EXPECT_EQ(model.writes.size(), size_t(IoApicModel::kPins)); // Low words only.
}

TEST_F(IoApicTest, RouteWritesMaskedLowThenHighThenLow)
{
    // An entry in use, to another processor at another vector.
    model.registers_[IoApicModel::low(2)] = 0x00000050;
    model.registers_[IoApicModel::low(2) + 1] = 0x00000000;
    ASSERT_TRUE(ioApic.route(2, 0x30, 1, false, false, false));
    const std::vector<std::pair<uint8_t, uint32_t>> expected = {
        {0x14, 0x00010030}, {0x15, 0x01000000}, {0x14, 0x00000030}};
    EXPECT_EQ(model.writes, expected);
    // No state between the first and the last write delivers.
    ASSERT_EQ(model.states.size(), 3u);
    EXPECT_NE(model.states[0].first & IoApic::kMasked, 0u);
    EXPECT_NE(model.states[1].first & IoApic::kMasked, 0u);
    EXPECT_EQ(ioApic.entryLow(2), 0x30u);
    EXPECT_EQ(ioApic.entryHigh(2), 0x01000000u);
    EXPECT_FALSE(ioApic.isMasked(2));
}

TEST_F(IoApicTest, RouteSetsPolarityTriggerAndMask)
{
    ASSERT_TRUE(ioApic.route(10, 0x3A, 0, true, true, true));
    EXPECT_EQ(ioApic.entryLow(10), 0x3Au | IoApic::kActiveLow | IoApic::kLevelTriggered | IoApic::kMasked);
    EXPECT_EQ(ioApic.entryLow(10), 0x1A03Au);
    EXPECT_EQ(ioApic.entryHigh(10), 0u);
    EXPECT_TRUE(ioApic.isMasked(10));
    ASSERT_TRUE(ioApic.route(23, 0xFE, 0x0F, false, true, false));
    EXPECT_EQ(ioApic.entryLow(23), 0x80FEu);
    EXPECT_EQ(ioApic.entryHigh(23), 0x0F000000u);
}

TEST_F(IoApicTest, RouteRefusesAPinBeyondTheTableOrAnIllegalVector)
{
    EXPECT_FALSE(ioApic.route(24, 0x30, 0, false, false, false));
    EXPECT_FALSE(ioApic.route(0, 0x0F, 0, false, false, false));
    EXPECT_TRUE(model.writes.empty());
}

TEST_F(IoApicTest, SetMaskedChangesOnlyTheMaskBit)
{
    ASSERT_TRUE(ioApic.route(4, 0x34, 1, true, true, true));
    model.writes.clear();
    ASSERT_TRUE(ioApic.setMasked(4, false));
    EXPECT_EQ(ioApic.entryLow(4), 0xA034u);
    EXPECT_FALSE(ioApic.isMasked(4));
    ASSERT_TRUE(ioApic.setMasked(4, true));
    EXPECT_EQ(ioApic.entryLow(4), 0x1A034u);
    EXPECT_EQ(ioApic.entryHigh(4), 0x01000000u);
    EXPECT_EQ(model.writes.size(), 2u);
    EXPECT_FALSE(ioApic.setMasked(24, false));
}

TEST_F(IoApicTest, PinsBeyondTheTableReadAsMaskedAndEmpty)
{
    EXPECT_TRUE(ioApic.isMasked(24));
    EXPECT_EQ(ioApic.entryLow(24), 0u);
    EXPECT_EQ(ioApic.entryHigh(200), 0u);
}

TEST(IoApic, WorksThroughAMemoryWindowToo)
{
    // Memory shows only the pair, so what is left is the last index
    // selected and the last value written through the window.
    alignas(16) uint32_t pair[IoApic::kWindowBytes / 4] = {};
    pair[IoApic::kWindow / 4] = 0x00170011; // What any read returns: 24 pins.
    const IoApic ioApic(arch_x86::IoWindow::memory(reinterpret_cast<uintptr_t>(pair), sizeof pair));
    ASSERT_TRUE(ioApic.route(1, 0x31, 0, false, false, false));
    EXPECT_EQ(pair[IoApic::kSelect / 4], 0x12u);
    EXPECT_EQ(pair[IoApic::kWindow / 4], 0x31u);
    constexpr IoApic atDefault(arch_x86::IoWindow::memory(IoApic::kDefaultBase, IoApic::kWindowBytes));
    EXPECT_EQ(atDefault.window().base(), IoApic::kDefaultBase);
}

} // namespace
