#include <bsp/RecoveryStrap.hpp>

#include "../../arch_x86/unit_tests/PortIoMock.hpp"

#include <gtest/gtest.h>

namespace {

TEST(RecoveryStrap, OnlyALowStrapBitIsAStrap)
{
    EXPECT_TRUE(bsp::recoveryStrapAsserted(0xFE));
    EXPECT_TRUE(bsp::recoveryStrapAsserted(0x00));
    EXPECT_FALSE(bsp::recoveryStrapAsserted(0x01));
    // The reset line's bit, low while the header holds the board in reset, is not the strap.
    EXPECT_FALSE(bsp::recoveryStrapAsserted(0xFF & ~bsp::kResetLineBit));
}

TEST(RecoveryStrap, ABoardWithoutTheJumperBlockReadsTheFloatingBusAndIsNotStrapped)
{
    port_io_mock::reset(); // Every port reads 0xFF, an empty ISA bus.
    EXPECT_FALSE(bsp::recoveryStrapSet());
    EXPECT_EQ(port_io_mock::takeLog(), (std::vector<port_io_mock::Access>{port_io_mock::read8(bsp::kJumperPort, 0xFF)}));
}

TEST(RecoveryStrap, TheStrapIsReadFromTheJumperPort)
{
    port_io_mock::reset();
    port_io_mock::queueRead(bsp::kJumperPort, 0xFE);
    EXPECT_TRUE(bsp::recoveryStrapSet());
    port_io_mock::queueRead(bsp::kJumperPort, 0xFD);
    EXPECT_FALSE(bsp::recoveryStrapSet());
}

} // namespace
