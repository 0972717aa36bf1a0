#include <bsp/Rtc146818.hpp>

#include "../../arch_x86/unit_tests/PortIoMock.hpp"

#include <gtest/gtest.h>

#include <map>

namespace {

using bsp::Rtc146818;

constexpr uint16_t kIndexPort = 0x70;
constexpr uint16_t kDataPort = 0x71;

// Queues what the chip answers: the bytes of `registers` for every index
// the driver selects, in the order it reads them. The driver's access
// pattern (register A, seven bytes, register A, seven bytes, register B)
// is fixed, so the answers are queued in that order.
void queueConsistentRead(const std::map<uint8_t, uint8_t>& registers)
{
    const uint8_t order[] = {Rtc146818::registerA,   Rtc146818::secondsIndex, Rtc146818::minutesIndex,
                             Rtc146818::hoursIndex,  Rtc146818::dayOfMonthIndex, Rtc146818::monthIndex,
                             Rtc146818::yearIndex,   Rtc146818::centuryIndex, Rtc146818::registerA,
                             Rtc146818::secondsIndex, Rtc146818::minutesIndex, Rtc146818::hoursIndex,
                             Rtc146818::dayOfMonthIndex, Rtc146818::monthIndex, Rtc146818::yearIndex,
                             Rtc146818::centuryIndex, Rtc146818::registerB};
    for (const uint8_t index : order) {
        const auto value = registers.find(index);
        port_io_mock::queueRead(kDataPort, value != registers.end() ? value->second : 0);
    }
}

dcos::Result<dcos::DateTime> readWith(const std::map<uint8_t, uint8_t>& registers)
{
    port_io_mock::reset();
    queueConsistentRead(registers);
    const Rtc146818 rtc(arch_x86::IoWindow::ports(kIndexPort, 2));
    return rtc.read();
}

TEST(Rtc146818, ReadsBcdIn24HourFormat)
{
    // 2031-05-06 07:08:09, BCD, 24-hour: what a PC BIOS leaves.
    const auto time = readWith({{Rtc146818::secondsIndex, 0x09}, {Rtc146818::minutesIndex, 0x08},
                                {Rtc146818::hoursIndex, 0x07},   {Rtc146818::dayOfMonthIndex, 0x06},
                                {Rtc146818::monthIndex, 0x05},   {Rtc146818::yearIndex, 0x31},
                                {Rtc146818::centuryIndex, 0x20}, {Rtc146818::registerB, Rtc146818::twentyFourHour}});
    ASSERT_TRUE(time.ok()) << dcos::statusName(time.status());
    EXPECT_EQ(time.value().year, 2031);
    EXPECT_EQ(time.value().month, 5);
    EXPECT_EQ(time.value().day, 6);
    EXPECT_EQ(time.value().hour, 7);
    EXPECT_EQ(time.value().minute, 8);
    EXPECT_EQ(time.value().second, 9);
}

TEST(Rtc146818, SelectsEachRegisterBeforeReadingItWithNmiLeftOn)
{
    (void)readWith({{Rtc146818::monthIndex, 0x01}, {Rtc146818::dayOfMonthIndex, 0x01},
                    {Rtc146818::registerB, Rtc146818::twentyFourHour}});
    const auto log = port_io_mock::takeLog();
    ASSERT_GE(log.size(), 2u);
    EXPECT_EQ(log[0], port_io_mock::write8(kIndexPort, Rtc146818::registerA));
    for (size_t i = 0; i + 1 < log.size(); i += 2) {
        EXPECT_TRUE(log[i].write && log[i].port == kIndexPort && (log[i].value & 0x80) == 0) << i;
        EXPECT_TRUE(!log[i + 1].write && log[i + 1].port == kDataPort) << i;
    }
}

TEST(Rtc146818, ReadsBinaryIn12HourFormat)
{
    // 11:30:00 PM in binary 12-hour format is 23:30.
    const auto pm = readWith({{Rtc146818::hoursIndex, 11 | Rtc146818::hourPm}, {Rtc146818::minutesIndex, 30},
                              {Rtc146818::dayOfMonthIndex, 28}, {Rtc146818::monthIndex, 2},
                              {Rtc146818::yearIndex, 24}, {Rtc146818::centuryIndex, 20},
                              {Rtc146818::registerB, Rtc146818::binaryMode}});
    ASSERT_TRUE(pm.ok());
    EXPECT_EQ(pm.value().hour, 23);
    EXPECT_EQ(pm.value().year, 2024);
    // 12 AM is midnight, 12 PM is noon.
    const auto midnight = readWith({{Rtc146818::hoursIndex, 12}, {Rtc146818::dayOfMonthIndex, 1},
                                    {Rtc146818::monthIndex, 1}, {Rtc146818::registerB, Rtc146818::binaryMode}});
    ASSERT_TRUE(midnight.ok());
    EXPECT_EQ(midnight.value().hour, 0);
    const auto noon = readWith({{Rtc146818::hoursIndex, 12 | Rtc146818::hourPm}, {Rtc146818::dayOfMonthIndex, 1},
                                {Rtc146818::monthIndex, 1}, {Rtc146818::registerB, Rtc146818::binaryMode}});
    ASSERT_TRUE(noon.ok());
    EXPECT_EQ(noon.value().hour, 12);
}

TEST(Rtc146818, WithoutACenturyByteTheYearsAre2000To2099)
{
    const auto time = readWith({{Rtc146818::dayOfMonthIndex, 0x15}, {Rtc146818::monthIndex, 0x08},
                                {Rtc146818::yearIndex, 0x99}, {Rtc146818::centuryIndex, 0xFF},
                                {Rtc146818::registerB, Rtc146818::twentyFourHour}});
    ASSERT_TRUE(time.ok());
    EXPECT_EQ(time.value().year, 2099);
}

TEST(Rtc146818, ANeverSetClockIsReportedNotTrusted)
{
    // Bad BCD digits, a month 13, February 30: all refused.
    EXPECT_EQ(readWith({{Rtc146818::secondsIndex, 0x7A}, {Rtc146818::dayOfMonthIndex, 0x01},
                        {Rtc146818::monthIndex, 0x01}, {Rtc146818::registerB, Rtc146818::twentyFourHour}})
                  .status(),
              dcos::Status::Corrupted);
    EXPECT_EQ(readWith({{Rtc146818::dayOfMonthIndex, 0x01}, {Rtc146818::monthIndex, 0x13},
                        {Rtc146818::registerB, Rtc146818::twentyFourHour}})
                  .status(),
              dcos::Status::Corrupted);
    EXPECT_EQ(readWith({{Rtc146818::dayOfMonthIndex, 0x30}, {Rtc146818::monthIndex, 0x02},
                        {Rtc146818::yearIndex, 0x25}, {Rtc146818::registerB, Rtc146818::twentyFourHour}})
                  .status(),
              dcos::Status::Corrupted);
    // An absent chip reads 0xFF everywhere.
    port_io_mock::reset();
    port_io_mock::setDefaultRead(kDataPort, 0x00);
    for (int i = 0; i < 20; ++i) {
        port_io_mock::queueRead(kDataPort, 0xFF);
    }
    const Rtc146818 rtc(arch_x86::IoWindow::ports(kIndexPort, 2));
    EXPECT_NE(rtc.read().status(), dcos::Status::Ok);
}

TEST(Rtc146818, AClockStuckInItsUpdateCycleIsBusyAfterABoundedWait)
{
    port_io_mock::reset();
    port_io_mock::setDefaultRead(kDataPort, Rtc146818::updateInProgress);
    const Rtc146818 rtc(arch_x86::IoWindow::ports(kIndexPort, 2));
    EXPECT_EQ(rtc.read().status(), dcos::Status::Busy);
    EXPECT_EQ(port_io_mock::takeLog().size(), 2u * Rtc146818::kUpdateWaitPolls);
}

TEST(Rtc146818, BytesThatChangeBetweenReadsAreReadAgain)
{
    port_io_mock::reset();
    const Rtc146818 rtc(arch_x86::IoWindow::ports(kIndexPort, 2));
    // First pair disagrees (the seconds moved on), the second pair agrees.
    const uint8_t first[] = {0, 0x59, 0x59, 0x23, 0x31, 0x12, 0x30, 0x20};
    const uint8_t second[] = {0, 0x00, 0x00, 0x00, 0x01, 0x01, 0x31, 0x20};
    for (const uint8_t* pass : {first, second, second, second}) {
        for (int i = 0; i < 8; ++i) {
            port_io_mock::queueRead(kDataPort, pass[i]);
        }
    }
    port_io_mock::queueRead(kDataPort, Rtc146818::twentyFourHour);
    const auto time = rtc.read();
    ASSERT_TRUE(time.ok()) << dcos::statusName(time.status());
    EXPECT_EQ(time.value().year, 2031);
    EXPECT_EQ(time.value().month, 1);
    EXPECT_EQ(time.value().hour, 0);
}

} // namespace
