#include <bsp/LocalApic.hpp>

#include "../../arch_x86/unit_tests/PortIoMock.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace {

using bsp::LocalApic;
using port_io_mock::Access;

Access write32(uint16_t port, uint32_t value) { return {true, port, value, 32}; }
Access read32(uint16_t port, uint32_t value) { return {false, port, value, 32}; }

// The register page as memory: what a test reads back is what the driver
// wrote last to each register.
struct RegisterPage {
    alignas(16) uint32_t words[LocalApic::kWindowBytes / 4] = {};

    uint32_t& operator[](uint32_t offset) { return words[offset / 4]; }
    LocalApic apic() { return LocalApic(arch_x86::IoWindow::memory(reinterpret_cast<uintptr_t>(words), sizeof words)); }
};

// The same registers behind a port window, so the mock logs every access
// in order: the driver code is the same for both kinds of window.
constexpr uint16_t kPorts = 0x1000;
LocalApic portApic() { return LocalApic(arch_x86::IoWindow::ports(kPorts, LocalApic::kWindowBytes)); }
constexpr uint16_t port(uint32_t offset) { return static_cast<uint16_t>(kPorts + offset); }

// The interrupt command register's delivery status: pending for a given
// number of reads after each send (or forever), then idle.
class CommandRegister final : public port_io_mock::Responder {
public:
    static constexpr uint32_t kForever = 0xFFFFFFFFu;
    explicit CommandRegister(uint32_t busyReads) : busyReads_(busyReads) {}

    uint32_t read(uint16_t offset, int) override
    {
        if (offset != LocalApic::kCommandLow) {
            return 0;
        }
        ++reads;
        if (remaining_ > 0) {
            if (remaining_ != kForever) {
                --remaining_;
            }
            return low_ | LocalApic::kDeliveryPending;
        }
        return low_;
    }

    void write(uint16_t offset, uint32_t value, int) override
    {
        if (offset == LocalApic::kCommandLow) {
            low_ = value;
            remaining_ = busyReads_;
        }
    }

    uint32_t reads = 0;

private:
    uint32_t busyReads_;
    uint32_t remaining_ = 0;
    uint32_t low_ = 0;
};

// Detaches the responders a test attached, which live on its stack, however
// the test ends.
struct DetachOnExit {
    DetachOnExit() = default;
    DetachOnExit(const DetachOnExit&) = delete;
    ~DetachOnExit() { port_io_mock::reset(); }
};

TEST(LocalApic, IdAndVersionFields)
{
    RegisterPage page;
    page[LocalApic::kId] = 0x01000000;
    page[LocalApic::kVersion] = 0x00030011;
    const LocalApic apic = page.apic();
    EXPECT_EQ(apic.id(), 1);
    EXPECT_EQ(apic.version(), 0x11);
    EXPECT_EQ(apic.maximumLvtEntry(), 3);
    page[LocalApic::kId] = 0xF3000000; // Bits 24-31 are read whole.
    EXPECT_EQ(apic.id(), 0xF3);
}

TEST(LocalApic, EnableProgramsTheSpuriousVectorDestinationsAndLocalVectorTable)
{
    RegisterPage page;
    page[LocalApic::kId] = 0x01000000;
    page[LocalApic::kTaskPriority] = 0x30;
    LocalApic apic = page.apic();
    ASSERT_TRUE(apic.enable(0xFF));
    EXPECT_EQ(page[LocalApic::kSpuriousVector], 0x1FFu);
    EXPECT_EQ(page[LocalApic::kDestinationFormat], 0xFFFFFFFFu);
    EXPECT_EQ(page[LocalApic::kLogicalDestination], 0x02000000u); // Bit 1 for APIC id 1.
    EXPECT_EQ(page[LocalApic::kTaskPriority], 0u);
    EXPECT_EQ(page[LocalApic::kLvtLint0], 0x10700u); // Masked ExtINT.
    EXPECT_EQ(page[LocalApic::kLvtLint1], 0x00400u); // NMI, open.
    EXPECT_EQ(page[LocalApic::kLvtError], 0x10000u);
    EXPECT_EQ(page[LocalApic::kLvtTimer], 0x10000u);
}

TEST(LocalApic, EnableWritesTheSpuriousVectorBeforeAnyLvtEntry)
{
    // A software-disabled APIC keeps every LVT entry masked, so LINT1's NMI
    // entry would not take before the enable.
    port_io_mock::reset();
    port_io_mock::setDefaultRead(port(LocalApic::kId), 0);
    LocalApic apic = portApic();
    ASSERT_TRUE(apic.enable(0x3F));
    const std::vector<Access> log = port_io_mock::takeLog();
    ASSERT_FALSE(log.empty());
    EXPECT_EQ(log.front(), write32(port(LocalApic::kSpuriousVector), 0x13F)) << port_io_mock::describe(log);
    for (const Access& a : log) {
        EXPECT_EQ(a.width, 32);
    }
}

TEST(LocalApic, EnableRefusesASpuriousVectorWithoutItsLowFourBitsSet)
{
    RegisterPage page;
    LocalApic apic = page.apic();
    EXPECT_FALSE(apic.enable(0xF0));
    EXPECT_FALSE(apic.enable(0xFE));
    EXPECT_FALSE(apic.enable(0x0F)); // Vectors 0-15 are illegal.
    for (const uint32_t word : page.words) {
        EXPECT_EQ(word, 0u);
    }
}

TEST(LocalApic, EndOfInterruptWritesZero)
{
    RegisterPage page;
    page[LocalApic::kEndOfInterrupt] = 0xDEADBEEF;
    page.apic().endOfInterrupt();
    EXPECT_EQ(page[LocalApic::kEndOfInterrupt], 0u);
}

TEST(LocalApic, TimerDivideEncodings)
{
    using D = LocalApic::TimerDivide;
    EXPECT_EQ(LocalApic::divideConfiguration(D::By1), 0xBu);
    EXPECT_EQ(LocalApic::divideConfiguration(D::By2), 0x0u);
    EXPECT_EQ(LocalApic::divideConfiguration(D::By4), 0x1u);
    EXPECT_EQ(LocalApic::divideConfiguration(D::By8), 0x2u);
    EXPECT_EQ(LocalApic::divideConfiguration(D::By16), 0x3u);
    EXPECT_EQ(LocalApic::divideConfiguration(D::By32), 0x8u);
    EXPECT_EQ(LocalApic::divideConfiguration(D::By64), 0x9u);
    EXPECT_EQ(LocalApic::divideConfiguration(D::By128), 0xAu);
}

TEST(LocalApic, StartPeriodicWritesTheInitialCountLast)
{
    port_io_mock::reset();
    const LocalApic apic = portApic();
    ASSERT_TRUE(apic.startPeriodic(0x40, 100000, LocalApic::TimerDivide::By16));
    const std::vector<Access> expected = {
        write32(port(LocalApic::kTimerDivide), 0x3),
        write32(port(LocalApic::kLvtTimer), 0x20040), // periodic, vector 0x40, open
        write32(port(LocalApic::kTimerInitialCount), 100000),
    };
    EXPECT_EQ(port_io_mock::takeLog(), expected);
}

TEST(LocalApic, StartOneShotStopAndCounts)
{
    RegisterPage page;
    const LocalApic apic = page.apic();
    ASSERT_TRUE(apic.startOneShot(0x41, 5000, LocalApic::TimerDivide::By1));
    EXPECT_EQ(page[LocalApic::kTimerDivide], 0xBu);
    EXPECT_EQ(page[LocalApic::kLvtTimer], 0x41u);
    EXPECT_EQ(page[LocalApic::kTimerInitialCount], 5000u);
    EXPECT_EQ(apic.initialCount(), 5000u);
    page[LocalApic::kTimerCurrentCount] = 1234;
    EXPECT_EQ(apic.currentCount(), 1234u);
    apic.stopTimer();
    EXPECT_EQ(page[LocalApic::kLvtTimer], 0x10000u);
    EXPECT_EQ(page[LocalApic::kTimerInitialCount], 0u);
}

TEST(LocalApic, TimerRefusesAnIllegalVectorOrAZeroCount)
{
    RegisterPage page;
    const LocalApic apic = page.apic();
    EXPECT_FALSE(apic.startPeriodic(0x0F, 1000, LocalApic::TimerDivide::By2));
    EXPECT_FALSE(apic.startOneShot(0x40, 0, LocalApic::TimerDivide::By2));
    for (const uint32_t word : page.words) {
        EXPECT_EQ(word, 0u);
    }
}

TEST(LocalApic, RequestAndInServiceBitsSelectTheirWordAndBit)
{
    RegisterPage page;
    const LocalApic apic = page.apic();
    page[LocalApic::kInterruptRequest + 0x20] = 1u << 1;  // vector 0x41
    page[LocalApic::kInService + 0x70] = 1u << 31;        // vector 0xFF
    EXPECT_TRUE(apic.isRequested(0x41));
    EXPECT_FALSE(apic.isRequested(0x40));
    EXPECT_FALSE(apic.isRequested(0x21)); // Bit 1 of another word.
    EXPECT_FALSE(apic.isInService(0x41));
    EXPECT_TRUE(apic.isInService(0xFF));
    EXPECT_FALSE(apic.isRequested(0xFF));
}

TEST(LocalApic, TaskPriorityIsWrittenAsGiven)
{
    RegisterPage page;
    page.apic().setTaskPriority(0x20);
    EXPECT_EQ(page[LocalApic::kTaskPriority], 0x20u);
}

TEST(LocalApic, InterProcessorInterruptsWriteHighThenLowThenPoll)
{
    port_io_mock::reset();
    DetachOnExit detach;
    CommandRegister icr(0);
    port_io_mock::attach(kPorts, LocalApic::kWindowBytes, &icr);
    const LocalApic apic = portApic();
    const uint16_t high = port(LocalApic::kCommandHigh);
    const uint16_t low = port(LocalApic::kCommandLow);

    ASSERT_TRUE(apic.sendInit(1, 10));
    std::vector<Access> expected = {write32(high, 0x01000000), write32(low, 0xC500), read32(low, 0xC500)};
    EXPECT_EQ(port_io_mock::takeLog(), expected);

    // INIT deassert goes to every APIC, as the SDM asks.
    ASSERT_TRUE(apic.sendInitDeassert(1, 10));
    expected = {write32(high, 0x01000000), write32(low, 0x88500), read32(low, 0x88500)};
    EXPECT_EQ(port_io_mock::takeLog(), expected);

    ASSERT_TRUE(apic.sendStartup(1, 0x08, 10));
    expected = {write32(high, 0x01000000), write32(low, 0x4608), read32(low, 0x4608)};
    EXPECT_EQ(port_io_mock::takeLog(), expected);

    ASSERT_TRUE(apic.sendFixed(0, 0x30, 10));
    expected = {write32(high, 0x00000000), write32(low, 0x4030), read32(low, 0x4030)};
    EXPECT_EQ(port_io_mock::takeLog(), expected);
}

TEST(LocalApic, TheWaitForDeliveryIsBounded)
{
    port_io_mock::reset();
    DetachOnExit detach;
    CommandRegister stuck(CommandRegister::kForever);
    port_io_mock::attach(kPorts, LocalApic::kWindowBytes, &stuck);
    const LocalApic apic = portApic();
    EXPECT_FALSE(apic.sendFixed(1, 0x30, 25));
    EXPECT_EQ(stuck.reads, 25u);
    EXPECT_FALSE(apic.sendInit(1, 0)); // No read, no answer.
    EXPECT_EQ(stuck.reads, 25u);

    port_io_mock::reset();
    CommandRegister slow(3);
    port_io_mock::attach(kPorts, LocalApic::kWindowBytes, &slow);
    EXPECT_TRUE(apic.sendStartup(1, 0x09, 10));
    EXPECT_EQ(slow.reads, 4u);
    EXPECT_FALSE(apic.sendStartup(1, 0x09, 3));
}

TEST(LocalApic, AFixedInterruptBelowVector16IsNotSent)
{
    port_io_mock::reset();
    const LocalApic apic = portApic();
    EXPECT_FALSE(apic.sendFixed(1, 0x0F, 10));
    EXPECT_TRUE(port_io_mock::takeLog().empty());
}

TEST(LocalApic, ErrorStatusIsWrittenBeforeItIsRead)
{
    port_io_mock::reset();
    port_io_mock::queueRead(port(LocalApic::kErrorStatus), 0x40);
    const LocalApic apic = portApic();
    EXPECT_EQ(apic.errorStatus(), 0x40u);
    const std::vector<Access> expected = {write32(port(LocalApic::kErrorStatus), 0),
                                          read32(port(LocalApic::kErrorStatus), 0x40)};
    EXPECT_EQ(port_io_mock::takeLog(), expected);
}

TEST(LocalApic, TheWindowIsTheOneGiven)
{
    RegisterPage page;
    const LocalApic apic = page.apic();
    EXPECT_EQ(apic.window().base(), reinterpret_cast<uintptr_t>(page.words));
    EXPECT_EQ(apic.window().size(), LocalApic::kWindowBytes);
    constexpr LocalApic atDefault(arch_x86::IoWindow::memory(LocalApic::kDefaultBase, LocalApic::kWindowBytes));
    EXPECT_EQ(atDefault.window().base(), LocalApic::kDefaultBase);
}

} // namespace
