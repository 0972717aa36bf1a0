// The runtime's 64-bit division on the target, where its 32-bit-divisor
// path runs the i486's DIVL (the host tests run the portable path).
#include "TargetTest.hpp"

#include <runtime/Int64Division.hpp>

namespace {

// xorshift64: a fixed sequence, so a failure repeats.
uint64_t nextRandom(uint64_t& state)
{
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
}

bool divisionIdentities(shell::Shell& shell)
{
    uint64_t state = 0x9E3779B97F4A7C15ull;
    unsigned failures = 0;
    for (unsigned i = 0; i < 4000; ++i) {
        const uint64_t n = nextRandom(state) >> (nextRandom(state) % 64);
        uint64_t d = nextRandom(state) >> (nextRandom(state) % 64);
        if (d == 0) {
            d = 1;
        }
        const runtime::UnsignedQuotient r = runtime::divideUnsigned64(n, d);
        // q * d + r == n and r < d define the quotient uniquely.
        if (r.remainder >= d || r.quotient * d + r.remainder != n) {
            if (failures++ < 5) {
                shell.print("wrong: %llu / %llu gave %llu rest %llu\r\n", static_cast<unsigned long long>(n),
                            static_cast<unsigned long long>(d), static_cast<unsigned long long>(r.quotient),
                            static_cast<unsigned long long>(r.remainder));
            }
        }
    }
    // Values with a known answer, through the compiler's own calls.
    volatile uint64_t big = 0xFFFFFFFFFFFFFFFFull;
    volatile uint64_t tick = 999847;
    const bool known = big / tick == 18449566857438ull && big % tick == 739629 && (big >> 1) / 3 == 3074457345618258602ull;
    shell.print("4000 random divisions: %u wrong; known values %s\r\n", failures, known ? "right" : "WRONG");
    return failures == 0 && known;
}

} // namespace

DCOS_TARGET_TEST(int64DivisionTest, "div64", "64-bit division on the i486 (DIVL path) satisfies q*d+r=n",
                 divisionIdentities);
