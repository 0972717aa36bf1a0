#include <runtime/Format.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace {

template <typename... Args>
void expectSameAsLibc(const char* format, Args... args)
{
    char ours[256];
    char theirs[256];
    const size_t ourLength = runtime::formatToBuffer(ours, sizeof ours, format, args...);
    const int theirLength = std::snprintf(theirs, sizeof theirs, format, args...);
    EXPECT_STREQ(ours, theirs) << "format \"" << format << "\"";
    EXPECT_EQ(ourLength, static_cast<size_t>(theirLength)) << "format \"" << format << "\"";
}

TEST(Format, IntegersMatchLibc)
{
    expectSameAsLibc("%d %i %u", 0, -1, 4000000000u);
    expectSameAsLibc("%d", INT32_MIN);
    expectSameAsLibc("[%5d] [%-5d] [%05d] [%05d]", 42, 42, 42, -42);
    expectSameAsLibc("%x %X %08x %o", 0xdeadbeefu, 0xabcdefu, 0x1234u, 8u);
    expectSameAsLibc("%lld %llu %llx", static_cast<long long>(INT64_MIN),
                     static_cast<unsigned long long>(UINT64_MAX), 0x123456789abcdefull);
    expectSameAsLibc("%ld %lu", -123456789L, 123456789UL);
    expectSameAsLibc("%*d|%-*d|", 6, 12, 6, 12);
}

TEST(Format, StringsAndCharacters)
{
    expectSameAsLibc("%s|%10s|%-10s|%.3s|%c|%3c", "abc", "right", "left", "truncate", 'x', 'y');
    expectSameAsLibc("%.*s", 2, "abcdef");
    expectSameAsLibc("100%%");
}

TEST(Format, PointerIsFixedWidthHex)
{
    char out[64];
    runtime::formatToBuffer(out, sizeof out, "%p", reinterpret_cast<void*>(0x1234));
    const std::string expected = "0x" + std::string(sizeof(void*) * 2 - 4, '0') + "1234";
    EXPECT_EQ(out, expected);
}

TEST(Format, NullStringIsShownNotDereferenced)
{
    char out[32];
    const char* volatile nothing = nullptr; // Hidden from the compiler's format check.
    runtime::formatToBuffer(out, sizeof out, "%s", nothing);
    EXPECT_STREQ(out, "(null)");
}

TEST(Format, UnknownConversionIsCopiedThrough)
{
    // The formats come through volatile pointers so that the compiler's own
    // format check, which would reject them, does not see them.
    char out[32];
    const char* volatile unknown = "a%qb";
    runtime::formatToBuffer(out, sizeof out, unknown);
    EXPECT_STREQ(out, "a%qb");
    const char* volatile trailing = "end%";
    runtime::formatToBuffer(out, sizeof out, trailing);
    EXPECT_STREQ(out, "end%");
}

TEST(Format, TruncationIsReportedLikeSnprintf)
{
    char out[8];
    runtime::BufferSink sink(out, sizeof out);
    const size_t produced = runtime::format(sink, "%s", "0123456789");
    EXPECT_EQ(produced, 10u);
    EXPECT_EQ(sink.length(), 10u);
    EXPECT_TRUE(sink.truncated());
    EXPECT_STREQ(out, "0123456");

    char exact[11];
    runtime::BufferSink fits(exact, sizeof exact);
    runtime::format(fits, "%s", "0123456789");
    EXPECT_FALSE(fits.truncated());
    EXPECT_STREQ(exact, "0123456789");
}

TEST(Format, ZeroCapacityBufferCountsOnly)
{
    EXPECT_EQ(runtime::formatToBuffer(nullptr, 0, "%d", 12345), 5u);
}

} // namespace
