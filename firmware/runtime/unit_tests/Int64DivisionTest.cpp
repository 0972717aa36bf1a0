#include <runtime/Int64Division.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>

namespace {

using runtime::divideSigned64;
using runtime::divideUnsigned64;

void expectUnsignedMatchesCompiler(uint64_t n, uint64_t d)
{
    const runtime::UnsignedQuotient r = divideUnsigned64(n, d);
    EXPECT_EQ(r.quotient, n / d) << n << " / " << d;
    EXPECT_EQ(r.remainder, n % d) << n << " % " << d;
}

void expectSignedMatchesCompiler(int64_t n, int64_t d)
{
    const runtime::SignedQuotient r = divideSigned64(n, d);
    EXPECT_EQ(r.quotient, n / d) << n << " / " << d;
    EXPECT_EQ(r.remainder, n % d) << n << " % " << d;
}

TEST(Int64Division, UnsignedEdgeCases)
{
    const uint64_t max = std::numeric_limits<uint64_t>::max();
    const uint64_t values[] = {0, 1, 2, 3, 7, 10, 0xFFFF, 0x10000, 0xFFFFFFFFull, 0x100000000ull,
                               0x100000001ull, 0x8000000000000000ull, max - 1, max,
                               1000000000ull, 1193182ull, 0x123456789ABCDEFull};
    for (uint64_t n : values) {
        for (uint64_t d : values) {
            if (d != 0) {
                expectUnsignedMatchesCompiler(n, d);
            }
        }
    }
}

TEST(Int64Division, UnsignedRandomAcrossAllWidths)
{
    std::mt19937_64 random(12345);
    for (int i = 0; i < 200000; ++i) {
        // Vary the bit widths of both operands so every loop length is hit.
        const unsigned nBits = 1 + static_cast<unsigned>(random() % 64);
        const unsigned dBits = 1 + static_cast<unsigned>(random() % 64);
        uint64_t n = random() >> (64 - nBits);
        uint64_t d = random() >> (64 - dBits);
        if (d == 0) {
            d = 1;
        }
        expectUnsignedMatchesCompiler(n, d);
    }
}

TEST(Int64Division, SignedTruncatesTowardsZero)
{
    const int64_t min = std::numeric_limits<int64_t>::min();
    const int64_t max = std::numeric_limits<int64_t>::max();
    const int64_t values[] = {0, 1, -1, 2, -2, 7, -7, 1000000007, -1000000007, max, min + 1, min,
                              0x100000000ll, -0x100000000ll};
    for (int64_t n : values) {
        for (int64_t d : values) {
            if (d == 0 || (n == min && d == -1)) {
                continue; // Undefined in C++ as well.
            }
            expectSignedMatchesCompiler(n, d);
        }
    }
    std::mt19937_64 random(777);
    for (int i = 0; i < 100000; ++i) {
        const int64_t n = static_cast<int64_t>(random()) >> (random() % 63);
        int64_t d = static_cast<int64_t>(random()) >> (random() % 63);
        if (d == 0) {
            d = 3;
        }
        if (n == min && d == -1) {
            continue;
        }
        expectSignedMatchesCompiler(n, d);
    }
}

TEST(Int64Division, ZeroDivisorIsReportedNotTrapped)
{
    const runtime::UnsignedQuotient r = divideUnsigned64(42, 0);
    EXPECT_EQ(r.quotient, ~uint64_t{0});
    EXPECT_EQ(r.remainder, 42u);
}

} // namespace
