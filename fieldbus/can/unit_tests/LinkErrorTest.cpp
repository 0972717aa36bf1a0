// LinkError: every reason has its own name, and folds into the kernel's Status.
#include <can/LinkError.hpp>

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace {

using can::LinkError;

constexpr uint8_t kLastError = static_cast<uint8_t>(LinkError::BufferTooSmall);

TEST(LinkError, EveryReasonHasADistinctName)
{
    std::set<std::string> names;
    for (uint8_t raw = 0; raw <= kLastError; ++raw) {
        const std::string name = can::linkErrorName(static_cast<LinkError>(raw));
        EXPECT_NE(name, "unknown link error") << int(raw);
        EXPECT_TRUE(names.insert(name).second) << "duplicate name " << name;
    }
    EXPECT_STREQ(can::linkErrorName(static_cast<LinkError>(kLastError + 1)), "unknown link error");
}

TEST(LinkError, StatusOfEachKindOfFailure)
{
    EXPECT_EQ(can::toStatus(LinkError::Ok), dcos::Status::Ok);
    EXPECT_EQ(can::toStatus(LinkError::TimeoutA), dcos::Status::Timeout);
    EXPECT_EQ(can::toStatus(LinkError::TimeoutBs), dcos::Status::Timeout);
    EXPECT_EQ(can::toStatus(LinkError::TimeoutCr), dcos::Status::Timeout);
    EXPECT_EQ(can::toStatus(LinkError::BufferOverflow), dcos::Status::NoMemory);
    EXPECT_EQ(can::toStatus(LinkError::BufferTooSmall), dcos::Status::NoMemory);
    EXPECT_EQ(can::toStatus(LinkError::Busy), dcos::Status::Busy);
    EXPECT_EQ(can::toStatus(LinkError::UnknownCommand), dcos::Status::NotSupported);
    EXPECT_EQ(can::toStatus(LinkError::WrongSequenceNumber), dcos::Status::InvalidArgument);
    EXPECT_EQ(can::toStatus(LinkError::InvalidHexDigit), dcos::Status::InvalidArgument);
    for (uint8_t raw = 1; raw <= kLastError; ++raw) {
        EXPECT_NE(can::toStatus(static_cast<LinkError>(raw)), dcos::Status::Ok) << int(raw);
    }
}

} // namespace
