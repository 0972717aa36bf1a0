// The chip core's register sequences, checked against the recording port
// mock and docs/iobus/mfio-register-map.md.
#include <iobus/MfioChip.hpp>

#include "MfioTestSupport.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace {

using iobus::MfioChip;
using iobus::MfioIdentity;
using namespace iobus::mfio;
using namespace iobus_test;
using Log = std::vector<port_io_mock::Access>;

MfioChip chip() { return MfioChip(arch_x86::IoWindow::ports(kBase, kWindowSize)); }

TEST(MfioChip, ProbeReadsIdThenRevision)
{
    port_io_mock::reset();
    answerProbe();
    MfioIdentity identity{};
    EXPECT_EQ(chip().probe(identity), dcos::Status::Ok);
    EXPECT_EQ(identity.id, 0x4D46);
    EXPECT_EQ(identity.revision, 0x0100);
    const Log log = port_io_mock::takeLog();
    EXPECT_EQ(log, (Log{in16(0x00, 0x4D46), in16(0x02, 0x0100)})) << port_io_mock::describe(log);
}

TEST(MfioChip, EmptyBusIsNotFoundWithoutFurtherAccess)
{
    port_io_mock::reset();
    port_io_mock::setDefaultRead(port(kIdRegister), kEmptyBus);
    MfioIdentity identity{};
    EXPECT_EQ(chip().probe(identity), dcos::Status::NotFound);
    EXPECT_EQ(identity.id, 0xFFFF);
    EXPECT_EQ(port_io_mock::takeLog(), (Log{in16(0x00, 0xFFFF)}));
}

TEST(MfioChip, AnotherBoardIsNotFound)
{
    port_io_mock::reset();
    port_io_mock::queueRead(port(kIdRegister), 0x1234);
    MfioIdentity identity{};
    EXPECT_EQ(chip().probe(identity), dcos::Status::NotFound);
}

TEST(MfioChip, AnotherMajorRevisionIsNotSupported)
{
    port_io_mock::reset();
    port_io_mock::queueRead(port(kIdRegister), kBoardId);
    port_io_mock::queueRead(port(kRevisionRegister), 0x0200);
    MfioIdentity identity{};
    EXPECT_EQ(chip().probe(identity), dcos::Status::NotSupported);
}

TEST(MfioChip, RegisterOffsetsFollowTheMap)
{
    port_io_mock::reset();
    const MfioChip c = chip();
    c.reset();
    c.setControl(true);
    c.setControl(false);
    c.startConversion(5);
    c.acknowledge();
    c.writeGains(0xC020);
    c.writeDac(0, 0x000);
    c.writeDac(7, 0xFFF);
    c.writeDac(3, 0xF123); // Only bits 11:0 reach the register.
    c.writeDigitalOutputs(0xA55A);
    const Log log = port_io_mock::takeLog();
    EXPECT_EQ(log, (Log{out16(0x04, 0x8000), out16(0x04, 0x0001), out16(0x04, 0x0000), out16(0x08, 5),
                        out16(0x0E, 0x0001), out16(0x0C, 0xC020), out16(0x20, 0x000), out16(0x2E, 0xFFF),
                        out16(0x26, 0x123), out16(0x12, 0xA55A)}))
        << port_io_mock::describe(log);
}

TEST(MfioChip, ReadsComeFromTheirRegisters)
{
    port_io_mock::reset();
    port_io_mock::queueRead(port(kStatusRegister), kStatusDone | kStatusIrqPending);
    port_io_mock::queueRead(port(kAdcDataRegister), 0xB7FF);
    port_io_mock::queueRead(port(kDigitalInputRegister), 0x00F0);
    port_io_mock::queueRead(port(kDigitalOutputRegister), 0x0F00);
    port_io_mock::queueRead(port(dacRegister(2)), 0x0ABC);
    port_io_mock::queueRead(port(kGainRegister), 0x0003);
    const MfioChip c = chip();
    EXPECT_EQ(c.status(), kStatusDone | kStatusIrqPending);
    EXPECT_EQ(c.data(), 0xB7FF);
    EXPECT_EQ(c.digitalInputs(), 0x00F0);
    EXPECT_EQ(c.digitalOutputs(), 0x0F00);
    EXPECT_EQ(c.dac(2), 0x0ABC);
    EXPECT_EQ(c.gains(), 0x0003);
    const Log log = port_io_mock::takeLog();
    ASSERT_EQ(log.size(), 6u);
    EXPECT_EQ(log[0].port, 0x306);
    EXPECT_EQ(log[1].port, 0x30A);
    EXPECT_EQ(log[2].port, 0x310);
    EXPECT_EQ(log[3].port, 0x312);
    EXPECT_EQ(log[4].port, 0x324);
    EXPECT_EQ(log[5].port, 0x30C);
    for (const auto& access : log) {
        EXPECT_EQ(access.width, 16) << "every register is accessed 16 bits wide";
    }
}

TEST(MfioChip, ConversionChannelIsMaskedToThreeBits)
{
    port_io_mock::reset();
    chip().startConversion(9);
    EXPECT_EQ(port_io_mock::takeLog(), (Log{out16(0x08, 1)}));
}

} // namespace
