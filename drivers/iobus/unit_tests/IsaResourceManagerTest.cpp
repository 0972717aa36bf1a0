// ISA port and line reservations, and conflict messages naming both claimants.
#include <iobus/IsaResourceManager.hpp>

#include <gtest/gtest.h>

#include <string>

namespace {

using dcos::Status;
using iobus::IsaConflict;
using iobus::IsaReservation;
using iobus::IsaResourceManager;
using iobus::kNoIrq;

std::string describe(const IsaConflict& conflict)
{
    char text[128];
    IsaResourceManager::describe(conflict, text, sizeof text);
    return text;
}

TEST(IsaResourceManager, OverlappingPortsNameBothClaimants)
{
    IsaResourceManager manager;
    ASSERT_EQ(manager.reserve("ne2000", 0x300, 0x20, 3, nullptr), Status::Ok);
    IsaConflict conflict;
    EXPECT_EQ(manager.reserve("mfio0", 0x300, 0x40, 5, &conflict), Status::AlreadyExists);
    EXPECT_FALSE(conflict.irq);
    EXPECT_STREQ(conflict.wantedBy, "mfio0");
    EXPECT_STREQ(conflict.heldBy, "ne2000");
    EXPECT_EQ(describe(conflict), "ports 0x300-0x33f wanted by mfio0 are held by ne2000 (0x300-0x31f)");
    EXPECT_EQ(manager.count(), 1u) << "a refused request reserves nothing";
}

TEST(IsaResourceManager, PartialOverlapAtEitherEndConflicts)
{
    IsaResourceManager manager;
    ASSERT_EQ(manager.reserve("a", 0x300, 0x10, kNoIrq, nullptr), Status::Ok);
    EXPECT_EQ(manager.reserve("b", 0x2F0, 0x11, kNoIrq, nullptr), Status::AlreadyExists);
    EXPECT_EQ(manager.reserve("b", 0x30F, 0x10, kNoIrq, nullptr), Status::AlreadyExists);
    EXPECT_EQ(manager.reserve("b", 0x2F0, 0x10, kNoIrq, nullptr), Status::Ok);
    EXPECT_EQ(manager.reserve("c", 0x310, 0x10, kNoIrq, nullptr), Status::Ok);
    EXPECT_EQ(manager.count(), 3u);
}

TEST(IsaResourceManager, SharedInterruptLineConflicts)
{
    IsaResourceManager manager;
    ASSERT_EQ(manager.reserve("com1", 0x3F8, 8, 4, nullptr), Status::Ok);
    IsaConflict conflict;
    EXPECT_EQ(manager.reserve("mfio0", 0x300, 0x40, 4, &conflict), Status::AlreadyExists);
    EXPECT_TRUE(conflict.irq);
    EXPECT_EQ(describe(conflict), "IRQ 4 wanted by mfio0 is held by com1");
    EXPECT_EQ(manager.reserveLine("sb16", 4, &conflict), Status::AlreadyExists);
    EXPECT_EQ(describe(conflict), "IRQ 4 wanted by sb16 is held by com1");
    EXPECT_EQ(manager.reserveLine("sb16", 7, &conflict), Status::Ok);
}

TEST(IsaResourceManager, ReleaseGivesBackEveryReservationOfTheClaimant)
{
    IsaResourceManager manager;
    ASSERT_EQ(manager.reserve("mfio0", 0x300, 0x40, 5, nullptr), Status::Ok);
    ASSERT_EQ(manager.reserve("other", 0x200, 0x10, kNoIrq, nullptr), Status::Ok);
    ASSERT_EQ(manager.reserveLine("mfio0", 9, nullptr), Status::Ok);
    EXPECT_EQ(manager.release("mfio0"), 2u);
    EXPECT_EQ(manager.count(), 1u);
    IsaReservation entry;
    ASSERT_TRUE(manager.entry(0, entry));
    EXPECT_STREQ(entry.claimant, "other");
    EXPECT_FALSE(manager.entry(1, entry));
    EXPECT_EQ(manager.reserve("mfio1", 0x300, 0x40, 5, nullptr), Status::Ok);
    EXPECT_EQ(manager.release("nobody"), 0u);
}

TEST(IsaResourceManager, BadRequestsAreRefused)
{
    IsaResourceManager manager;
    EXPECT_EQ(manager.reserve(nullptr, 0x300, 1, kNoIrq, nullptr), Status::InvalidArgument);
    EXPECT_EQ(manager.reserve("", 0x300, 1, kNoIrq, nullptr), Status::InvalidArgument);
    EXPECT_EQ(manager.reserve("a-name-of-16-chr", 0x300, 1, kNoIrq, nullptr), Status::InvalidArgument);
    EXPECT_EQ(manager.reserve("a", 0x300, 0, kNoIrq, nullptr), Status::InvalidArgument);
    EXPECT_EQ(manager.reserve("a", 0xFFF0, 0x20, kNoIrq, nullptr), Status::InvalidArgument);
    EXPECT_EQ(manager.reserve("a", 0x300, 1, 16, nullptr), Status::InvalidArgument);
    EXPECT_EQ(manager.reserveLine("a", kNoIrq, nullptr), Status::InvalidArgument);
    EXPECT_EQ(manager.reserve("fifteen-chars-x", 0xFFF0, 0x10, kNoIrq, nullptr), Status::Ok);
    EXPECT_EQ(manager.count(), 1u);
}

TEST(IsaResourceManager, FullTableIsReported)
{
    IsaResourceManager manager;
    for (size_t i = 0; i < IsaResourceManager::kCapacity; ++i) {
        ASSERT_EQ(manager.reserve("x", static_cast<uint16_t>(0x1000 + 0x10 * i), 0x10, kNoIrq, nullptr), Status::Ok);
    }
    EXPECT_EQ(manager.reserve("y", 0x200, 1, kNoIrq, nullptr), Status::TableFull);
}

TEST(IsaResourceManager, TheBoardsFixedDevicesAreRegisteredOnFirstUse)
{
    IsaResourceManager& board = iobus::isaResources();
    IsaConflict conflict;
    EXPECT_EQ(board.reserve("mfio0", 0x3F8, 0x40, 5, &conflict), Status::AlreadyExists);
    EXPECT_EQ(describe(conflict), "ports 0x3f8-0x437 wanted by mfio0 are held by com1 (0x3f8-0x3ff)");
    EXPECT_EQ(board.reserve("mfio0", 0x300, 0x40, 4, &conflict), Status::AlreadyExists);
    EXPECT_EQ(describe(conflict), "IRQ 4 wanted by mfio0 is held by com1");
    EXPECT_EQ(board.reserve("x", 0x20, 1, kNoIrq, &conflict), Status::AlreadyExists);
    EXPECT_STREQ(conflict.heldBy, "pic-master");
    EXPECT_EQ(board.reserve("x", 0x43, 1, kNoIrq, &conflict), Status::AlreadyExists);
    EXPECT_STREQ(conflict.heldBy, "pit");
    EXPECT_EQ(board.reserve("x", 0x71, 1, kNoIrq, &conflict), Status::AlreadyExists);
    EXPECT_STREQ(conflict.heldBy, "cmos-rtc");
    EXPECT_EQ(board.reserve("x", 0xF4, 1, kNoIrq, &conflict), Status::AlreadyExists);
    EXPECT_STREQ(conflict.heldBy, "debug-exit");
    EXPECT_EQ(board.reserveLine("x", 0, &conflict), Status::AlreadyExists);
    EXPECT_STREQ(conflict.heldBy, "pit");
    const size_t fixed = board.count();
    iobus::isaResources(); // A second use registers nothing twice.
    EXPECT_EQ(board.count(), fixed);
}

} // namespace
