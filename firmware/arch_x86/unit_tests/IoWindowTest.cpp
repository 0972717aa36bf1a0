#include <arch_x86/IoWindow.hpp>

#include "PortIoMock.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace {

using port_io_mock::Access;

TEST(IoWindow, PortAccessesAddTheOffsetToTheBase)
{
    port_io_mock::reset();
    const auto window = arch_x86::IoWindow::ports(0x300, 16);
    port_io_mock::queueRead(0x302, 0x5A);
    EXPECT_EQ(window.read8(2), 0x5A);
    window.write8(15, 0x11);
    window.write16(4, 0xBEEF);
    const std::vector<Access> expected = {{false, 0x302, 0x5A, 8}, {true, 0x30F, 0x11, 8}, {true, 0x304, 0xBEEF, 16}};
    EXPECT_EQ(port_io_mock::takeLog(), expected);
}

TEST(IoWindow, AccessOutsideTheWindowPanicsWithoutTouchingHardware)
{
    port_io_mock::reset();
    const auto window = arch_x86::IoWindow::ports(0x3F8, 8);
    EXPECT_THROW(window.read8(8), std::runtime_error);
    EXPECT_THROW(window.write16(7, 0), std::runtime_error);
    EXPECT_TRUE(port_io_mock::takeLog().empty());
}

TEST(IoWindow, MisalignedWideAccessPanics)
{
    port_io_mock::reset();
    const auto window = arch_x86::IoWindow::ports(0x300, 16);
    EXPECT_THROW(window.read16(3), std::runtime_error);
    EXPECT_TRUE(port_io_mock::takeLog().empty());
}

TEST(IoWindow, MemoryWindowReadsAndWritesMemory)
{
    alignas(4) volatile uint8_t registers[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    const auto window = arch_x86::IoWindow::memory(reinterpret_cast<uintptr_t>(registers), sizeof registers);
    EXPECT_EQ(window.read8(3), 4);
    window.write8(0, 0xAA);
    EXPECT_EQ(registers[0], 0xAA);
    window.write16(6, 0x1234);
    EXPECT_EQ(window.read16(6), 0x1234);
    EXPECT_THROW(window.read8(8), std::runtime_error);
}

} // namespace
