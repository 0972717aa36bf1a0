#include <bsp/Pic8259.hpp>

#include "../../arch_x86/unit_tests/PortIoMock.hpp"

#include <gtest/gtest.h>

namespace {

using port_io_mock::read8;
using port_io_mock::write8;

bsp::Pic8259 makePic()
{
    return bsp::Pic8259(arch_x86::IoWindow::ports(0x20, 2), arch_x86::IoWindow::ports(0xA0, 2));
}

TEST(Pic8259, InitialisationFollowsTheIcwSequenceAndMasksAllButCascade)
{
    port_io_mock::reset();
    auto pic = makePic();
    pic.initialise(0x20);
    const std::vector<port_io_mock::Access> expected = {
        write8(0x20, 0x11), write8(0xA0, 0x11), // ICW1: edge, cascade, ICW4 needed
        write8(0x21, 0x20), write8(0xA1, 0x28), // ICW2: vector bases
        write8(0x21, 0x04), write8(0xA1, 0x02), // ICW3: slave on IR2, slave id 2
        write8(0x21, 0x01), write8(0xA1, 0x01), // ICW4: 8086 mode
        write8(0x21, 0xFB), write8(0xA1, 0xFF), // OCW1: all masked but the cascade
    };
    const auto log = port_io_mock::takeLog();
    EXPECT_EQ(log, expected) << port_io_mock::describe(log);
    EXPECT_EQ(pic.maskBits(), 0xFFFB);
}

TEST(Pic8259, MaskAndUnmaskRewriteBothImrs)
{
    port_io_mock::reset();
    auto pic = makePic();
    pic.initialise(0x20);
    port_io_mock::takeLog();
    pic.unmask(0);
    pic.unmask(12);
    EXPECT_FALSE(pic.isMasked(12));
    pic.mask(12);
    EXPECT_TRUE(pic.isMasked(12));
    const std::vector<port_io_mock::Access> expected = {
        write8(0x21, 0xFA), write8(0xA1, 0xFF), write8(0x21, 0xFA), write8(0xA1, 0xEF),
        write8(0x21, 0xFA), write8(0xA1, 0xFF),
    };
    EXPECT_EQ(port_io_mock::takeLog(), expected);
}

TEST(Pic8259, CascadeLineAndOutOfRangeLinesCannotBeMasked)
{
    port_io_mock::reset();
    auto pic = makePic();
    pic.initialise(0x20);
    port_io_mock::takeLog();
    pic.mask(bsp::Pic8259::cascadeLine);
    pic.mask(16);
    pic.unmask(99);
    EXPECT_TRUE(port_io_mock::takeLog().empty());
    EXPECT_FALSE(pic.isMasked(bsp::Pic8259::cascadeLine));
}

TEST(Pic8259, EndOfInterruptOnTheSlaveAlsoEndsTheCascade)
{
    port_io_mock::reset();
    auto pic = makePic();
    pic.endOfInterrupt(3);
    pic.endOfInterrupt(14);
    const std::vector<port_io_mock::Access> expected = {
        write8(0x20, 0x63),                     // specific EOI, level 3
        write8(0xA0, 0x66), write8(0x20, 0x62), // slave level 6, then master level 2
    };
    EXPECT_EQ(port_io_mock::takeLog(), expected);
}

TEST(Pic8259, RequestRegisterCombinesBothChips)
{
    port_io_mock::reset();
    auto pic = makePic();
    port_io_mock::queueRead(0x20, 0x01);
    port_io_mock::queueRead(0xA0, 0x80);
    EXPECT_EQ(pic.readRequestRegister(), 0x8001);
    const std::vector<port_io_mock::Access> expected = {write8(0x20, 0x0A), write8(0xA0, 0x0A), read8(0x20, 0x01),
                                                         read8(0xA0, 0x80)};
    EXPECT_EQ(port_io_mock::takeLog(), expected);
}

TEST(Pic8259, SpuriousIrq7And15AreRecognisedByTheInServiceRegister)
{
    port_io_mock::reset();
    auto pic = makePic();
    EXPECT_TRUE(pic.isGenuine(3)); // Only 7 and 15 can be spurious; no access needed.
    EXPECT_TRUE(port_io_mock::takeLog().empty());
    port_io_mock::queueRead(0x20, 0x00);
    port_io_mock::queueRead(0xA0, 0x00);
    EXPECT_FALSE(pic.isGenuine(7));
    port_io_mock::queueRead(0x20, 0x80);
    port_io_mock::queueRead(0xA0, 0x00);
    EXPECT_TRUE(pic.isGenuine(7));
    port_io_mock::queueRead(0x20, 0x04);
    port_io_mock::queueRead(0xA0, 0x80);
    EXPECT_TRUE(pic.isGenuine(15));
}

} // namespace
