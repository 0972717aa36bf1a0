// Helpers shared by the ISO-TP tests: frames written as byte lists, the
// connection every test uses, and the milliseconds of a hand-made clock.
#pragma once

#include <can/CanFrame.hpp>
#include <can/IsoTpConfig.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>
#include <vector>

namespace isotp_test {

// The two ends of the connection: this end sends on 0x18DAF110 and listens
// on 0x18DA10F1, like a diagnostic tester; the peer does the reverse.
constexpr uint32_t kTxId = 0x18DAF110;
constexpr uint32_t kRxId = 0x18DA10F1;

constexpr uint64_t kMillisecond = 1000000;
constexpr uint64_t kSecond = 1000 * kMillisecond;

inline can::IsoTpConfig config()
{
    can::IsoTpConfig result;
    result.txId = kTxId;
    result.rxId = kRxId;
    result.format = can::IdFormat::Extended;
    return result;
}

// The configuration of the peer: the same identifiers, swapped.
inline can::IsoTpConfig peerConfig()
{
    can::IsoTpConfig result = config();
    result.txId = kRxId;
    result.rxId = kTxId;
    return result;
}

inline can::CanFrame frame(uint32_t id, std::initializer_list<uint8_t> bytes,
                           can::IdFormat format = can::IdFormat::Extended)
{
    const std::vector<uint8_t> data(bytes);
    const auto result = can::CanFrame::makeData(id, format, data.data(), static_cast<uint8_t>(data.size()));
    EXPECT_TRUE(result.ok());
    return result.value();
}

// A frame the peer sends to this end.
inline can::CanFrame incoming(std::initializer_list<uint8_t> bytes)
{
    return frame(kRxId, bytes);
}

inline std::vector<uint8_t> bytesOf(const can::CanFrame& frame)
{
    return std::vector<uint8_t>(frame.data(), frame.data() + frame.length());
}

// A message whose every byte differs from its neighbours, so a lost,
// repeated or misplaced segment shows.
inline std::vector<uint8_t> pattern(size_t length)
{
    std::vector<uint8_t> message(length);
    for (size_t i = 0; i < length; ++i) {
        message[i] = static_cast<uint8_t>((i * 7 + 3) ^ (i >> 8));
    }
    return message;
}

} // namespace isotp_test
