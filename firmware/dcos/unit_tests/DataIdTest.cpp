// Host tests for the data identifiers a publisher's Write hands out
// (seed 7.10): nextDataId runs as an ADD and an ADC on the target, and must
// give what the plain definition gives, kNoDsmData skipped at the wrap.
#include <dcos/internal/DsmManager.hpp>

#include <gtest/gtest.h>

using dcos::kNoDsmData;
using dcos::internal::nextDataId;

namespace {

// The identifier a reader compares against: never kNoDsmData, one more than
// the last otherwise.
uint32_t reference(uint32_t dataId)
{
    uint32_t next = dataId + 1;
    if (next == kNoDsmData) {
        ++next;
    }
    return next;
}

TEST(DataIdTest, ItCountsUpByOne)
{
    volatile uint32_t dataId = 41; // volatile: the run-time form, not the constant evaluation.
    EXPECT_EQ(nextDataId(dataId), 42u);
}

TEST(DataIdTest, ItSkipsNoDataAtTheWrap)
{
    volatile uint32_t last = 0xFFFFFFFFu;
    EXPECT_EQ(nextDataId(last), 1u);
    EXPECT_NE(nextDataId(last), kNoDsmData);
}

TEST(DataIdTest, ItAgreesWithThePlainDefinitionAroundEveryCarry)
{
    // Every value whose increment carries out of a byte, and their neighbours.
    for (uint32_t bits = 8; bits <= 32; bits += 8) {
        const uint32_t edge = bits == 32 ? 0xFFFFFFFFu : (1u << bits) - 1;
        for (uint32_t delta = 0; delta < 3; ++delta) {
            volatile uint32_t below = edge - delta;
            volatile uint32_t above = edge + delta; // Wraps to 0 and 1 at the top.
            EXPECT_EQ(nextDataId(below), reference(below)) << below;
            EXPECT_EQ(nextDataId(above), reference(above)) << above;
        }
    }
}

} // namespace
