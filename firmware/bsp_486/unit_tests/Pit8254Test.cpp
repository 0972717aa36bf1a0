#include <bsp/Pit8254.hpp>

#include "../../arch_x86/unit_tests/PortIoMock.hpp"

#include <gtest/gtest.h>

namespace {

using port_io_mock::write8;

TEST(Pit8254, DivisorIsTheNearestInteger)
{
    EXPECT_EQ(bsp::Pit8254::divisorFor(1000), 1193);
    EXPECT_EQ(bsp::Pit8254::divisorFor(100), 11932);
    EXPECT_EQ(bsp::Pit8254::divisorFor(19), 62799); // The slowest rate still fits 16 bits.
    EXPECT_EQ(bsp::Pit8254::divisorFor(10000), 119);
}

TEST(Pit8254, StartProgramsCounter0AsARateGenerator)
{
    port_io_mock::reset();
    bsp::Pit8254 pit(arch_x86::IoWindow::ports(0x40, 4));
    EXPECT_EQ(pit.start(1000), dcos::Status::Ok);
    const std::vector<port_io_mock::Access> expected = {
        write8(0x43, 0x34),                     // counter 0, LSB then MSB, mode 2, binary
        write8(0x40, 1193 & 0xFF), write8(0x40, 1193 >> 8),
    };
    EXPECT_EQ(port_io_mock::takeLog(), expected);
    EXPECT_EQ(pit.requestedRateHz(), 1000u);
    // 1193 / 1.193182 MHz = 999847.3 ns.
    EXPECT_EQ(pit.tickPeriodNanoseconds(), 999847u);
}

TEST(Pit8254, RatesOutsideTheSupportedRangeAreRefusedUntouched)
{
    port_io_mock::reset();
    bsp::Pit8254 pit(arch_x86::IoWindow::ports(0x40, 4));
    EXPECT_EQ(pit.start(18), dcos::Status::InvalidArgument); // Divisor would overflow 16 bits.
    EXPECT_EQ(pit.start(10001), dcos::Status::InvalidArgument);
    EXPECT_EQ(pit.start(0), dcos::Status::InvalidArgument);
    EXPECT_TRUE(port_io_mock::takeLog().empty());
}

TEST(Pit8254, ReadCountLatchesThenReadsLowAndHigh)
{
    port_io_mock::reset();
    bsp::Pit8254 pit(arch_x86::IoWindow::ports(0x40, 4));
    port_io_mock::queueRead(0x40, 0x34);
    port_io_mock::queueRead(0x40, 0x12);
    EXPECT_EQ(pit.readCount(), 0x1234);
    const auto log = port_io_mock::takeLog();
    ASSERT_EQ(log.size(), 3u);
    EXPECT_EQ(log[0], write8(0x43, 0x00));
}

} // namespace
