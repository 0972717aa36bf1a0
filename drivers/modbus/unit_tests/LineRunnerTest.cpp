// LineRunner: the glue between a half-duplex UART and fieldbus/modbus's
// Slave and Master, driven here as the firmware's task drives it, by a fake
// UART and a simulated clock at 19200 baud 8E1 (11-bit characters).
//
// The fake port models what the 16550 and the runner's interrupt do: a
// frame handed to transmit() leaves at one character time per byte, the
// transmit FIFO runs dry one character before the last stop bit (the
// interrupt then calls fifoEmptied()), and finishTransmission() says true
// only once the last stop bit has gone, as LSR.TEMT does. Received bytes
// are pushed into the runner's queue with their times, as the receive
// interrupt does, and service() runs whenever the task would wake: at the
// deadline it returned, or at an interrupt.
#include <mbline/LineRunner.hpp>

#include <modbus/Crc16.hpp>
#include <modbus/InMemoryDataModel.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace {

using dcos::Status;
using mbline::Completion;
using mbline::LinePort;
using mbline::LineRunner;
using mbline::Role;
using modbus::ExceptionCode;
using modbus::ModbusError;
using modbus::Request;

using Bytes = std::vector<uint8_t>;

constexpr uint64_t kMillisecond = 1000000;
constexpr uint64_t kMicrosecond = 1000;
constexpr uint8_t kUnit = 17;
constexpr uint64_t kNever = ~0ull;
// How long after a request was submitted the tests' slave answers: past the
// request's 8 bytes on the line and the t3.5 a slave keeps before answering.
constexpr uint64_t kSlaveDelayNs = 10 * kMillisecond;

Bytes withCrc(Bytes bytes)
{
    const uint16_t crc = modbus::Crc16::compute(bytes.data(), bytes.size());
    bytes.push_back(static_cast<uint8_t>(crc & 0xFF));
    bytes.push_back(static_cast<uint8_t>(crc >> 8));
    return bytes;
}

modbus::RtuTiming timing19200()
{
    const modbus::ModbusResult<modbus::RtuTiming> timing = modbus::RtuTiming::make(19200);
    EXPECT_TRUE(timing.ok());
    return timing.value();
}

// The UART as the runner sees it, with the transmitter's timing.
class FakePort final : public LinePort {
public:
    FakePort(const uint64_t& clock, uint64_t characterNs) : clock_(clock), characterNs_(characterNs) {}

    Status transmit(const uint8_t* bytes, size_t length) override
    {
        if (refuse || sending_) {
            ++refused;
            return Status::Busy;
        }
        frames.emplace_back(bytes, bytes + length);
        startedNs.push_back(clock_);
        sending_ = true;
        fifoSignalled_ = false;
        lastStopBitNs_ = clock_ + length * characterNs_;
        return Status::Ok;
    }

    bool finishTransmission() override
    {
        if (!sending_ || clock_ < lastStopBitNs_) {
            return false;
        }
        sending_ = false;
        releasedNs.push_back(clock_);
        return true;
    }

    // When the transmit interrupt is due, or never.
    uint64_t fifoInterruptNs() const { return sending_ && !fifoSignalled_ ? lastStopBitNs_ - characterNs_ : kNever; }
    void fifoInterruptTaken() { fifoSignalled_ = true; }
    bool sending() const { return sending_; }

    bool refuse = false;
    unsigned refused = 0;
    std::vector<Bytes> frames;
    std::vector<uint64_t> startedNs;
    std::vector<uint64_t> releasedNs;

private:
    const uint64_t& clock_;
    uint64_t characterNs_;
    bool sending_ = false;
    bool fifoSignalled_ = false;
    uint64_t lastStopBitNs_ = 0;
};

class LineRunnerTest : public ::testing::Test {
protected:
    LineRunnerTest() : timing_(timing19200()), port_(now_, timing_.characterNs), runner_(port_)
    {
        model_.holdingRegister(0) = 0x1234;
        model_.holdingRegister(1) = 0xABCD;
    }

    void startSlave()
    {
        ASSERT_EQ(runner_.startSlave(timing_, model_, identification_, kUnit, now_), ModbusError::Ok);
        ASSERT_EQ(runner_.role(), Role::Slave);
    }

    void startMaster(uint8_t retries)
    {
        modbus::MasterConfig config;
        config.responseTimeoutNs = 100 * kMillisecond;
        config.turnaroundDelayNs = 50 * kMillisecond;
        config.retries = retries;
        ASSERT_EQ(runner_.startMaster(timing_, config, now_), ModbusError::Ok);
        ASSERT_EQ(runner_.role(), Role::Master);
    }

    // Runs the task and the transmit interrupt up to @p endNs, each at the
    // time it would run, and services the line once more at @p endNs.
    void runUntil(uint64_t endNs)
    {
        for (int rounds = 0; rounds < 100000; ++rounds) {
            const uint64_t wanted = runner_.service(now_);
            // The task runs taskLatencyNs_ after the time it asked for (a
            // timer tick's granularity, other tasks).
            const uint64_t woken = wanted == kNever ? kNever : wanted + taskLatencyNs_;
            uint64_t next = std::min(woken, port_.fifoInterruptNs());
            if (next <= now_) {
                // A deadline the runner asks for again at once would spin the task.
                ADD_FAILURE() << "service() asked to run again at " << next << " at " << now_;
                return;
            }
            if (next > endNs) {
                now_ = endNs;
                (void)runner_.service(now_);
                return;
            }
            now_ = next;
            if (now_ == port_.fifoInterruptNs()) {
                port_.fifoInterruptTaken();
                // The handler stamps the time it runs, interruptLatencyNs_
                // after the FIFO ran dry.
                runner_.fifoEmptied(now_ + interruptLatencyNs_);
            }
        }
        ADD_FAILURE() << "the line never went quiet";
    }

    // The bytes of @p frame arrive back to back, the first delivered at
    // @p firstNs; @p gapBefore (an index) gets @p extraNs more silence
    // before it. Returns when the last byte arrived.
    uint64_t receive(const Bytes& frame, uint64_t firstNs, size_t gapBefore = 0, uint64_t extraNs = 0)
    {
        uint64_t at = firstNs;
        for (size_t i = 0; i < frame.size(); ++i) {
            if (i > 0) {
                at += timing_.characterNs + (i == gapBefore ? extraNs : 0);
            }
            runUntil(at);
            EXPECT_TRUE(runner_.queue().push(frame[i], at));
        }
        return at;
    }

    // When the runner knows that a frame whose last byte arrived at @p lastNs has ended.
    uint64_t frameEndNs(uint64_t lastNs) const { return lastNs + timing_.t35Ns + timing_.characterNs; }

    // A request answered: it arrives from @p firstNs, and the line runs for
    // 20 ms after it.
    void exchange(const Bytes& request, uint64_t firstNs)
    {
        const uint64_t last = receive(request, firstNs);
        runUntil(last + 20 * kMillisecond);
    }

    uint64_t now_ = 0;
    uint64_t interruptLatencyNs_ = 0;
    uint64_t taskLatencyNs_ = 0;
    modbus::RtuTiming timing_;
    FakePort port_;
    LineRunner runner_;
    modbus::InMemoryDataModel<64, 64, 64, 64> model_;
    modbus::DeviceIdentification identification_{.vendorName = "DCOS", .productCode = "TEST", .revision = "1"};
};

const Bytes kReadTwoHolding = withCrc({kUnit, 0x03, 0x00, 0x00, 0x00, 0x02});
const Bytes kTwoHoldingAnswer = withCrc({kUnit, 0x03, 0x04, 0x12, 0x34, 0xAB, 0xCD});

TEST_F(LineRunnerTest, SlaveAnswersARequestT35AfterItsLastByte)
{
    startSlave();
    const uint64_t last = receive(kReadTwoHolding, 10 * kMillisecond);
    runUntil(last + 20 * kMillisecond);
    ASSERT_EQ(port_.frames.size(), 1u);
    EXPECT_EQ(port_.frames[0], kTwoHoldingAnswer);
    // The frame ends after t3.5 of silence, known once one more character
    // time has passed without a byte (one could have been on its way), and
    // the answer goes at once.
    EXPECT_EQ(port_.startedNs[0], frameEndNs(last));
    // The driver is released when the last stop bit has gone, not when the FIFO ran dry.
    ASSERT_EQ(port_.releasedNs.size(), 1u);
    EXPECT_EQ(port_.releasedNs[0], port_.startedNs[0] + kTwoHoldingAnswer.size() * timing_.characterNs);
    EXPECT_FALSE(runner_.transmitting());
    EXPECT_EQ(runner_.counters().charactersReceived, kReadTwoHolding.size());
    EXPECT_EQ(runner_.counters().framesSent, 1u);
    // The interrupt came one character before the shift register emptied; the
    // check then found it busy once.
    EXPECT_EQ(runner_.counters().temtPolls, 1u);
    EXPECT_EQ(runner_.slave().counters().messages, 1u);
    EXPECT_EQ(runner_.transport().receiver().counters().framesDelivered, 1u);
}

TEST_F(LineRunnerTest, SlaveServesTheNextRequestAfterItsAnswerLeft)
{
    startSlave();
    exchange(kReadTwoHolding, 10 * kMillisecond);
    // A write, then a read of what it wrote: the slave is listening again,
    // so its first answer's end was reported to the station.
    exchange(withCrc({kUnit, 0x06, 0x00, 0x01, 0x55, 0xAA}), now_);
    exchange(withCrc({kUnit, 0x03, 0x00, 0x01, 0x00, 0x01}), now_);
    ASSERT_EQ(port_.frames.size(), 3u);
    EXPECT_EQ(port_.frames[1], withCrc({kUnit, 0x06, 0x00, 0x01, 0x55, 0xAA}));
    EXPECT_EQ(port_.frames[2], withCrc({kUnit, 0x03, 0x02, 0x55, 0xAA}));
    EXPECT_EQ(model_.holdingRegister(1), 0x55AA);
    EXPECT_EQ(runner_.slave().counters().messages, 3u);
    EXPECT_EQ(runner_.slave().counters().droppedWhileSending, 0u);
    EXPECT_EQ(runner_.counters().framesSent, 3u);
}

TEST_F(LineRunnerTest, SlaveAnswersAnUnknownFunctionWithException01)
{
    startSlave();
    exchange(withCrc({kUnit, 0x41, 0x00}), 10 * kMillisecond);
    ASSERT_EQ(port_.frames.size(), 1u);
    EXPECT_EQ(port_.frames[0], withCrc({kUnit, 0xC1, 0x01}));
    EXPECT_EQ(runner_.slave().counters().exceptions, 1u);
}

// A request one of whose characters the UART flagged (a parity error) gets no
// answer though its CRC is right; the next, clean one is answered.
TEST_F(LineRunnerTest, NoAnswerToARequestWithADamagedCharacter)
{
    startSlave();
    uint64_t at = 10 * kMillisecond;
    for (size_t i = 0; i < kReadTwoHolding.size(); ++i) {
        runUntil(at);
        EXPECT_TRUE(runner_.queue().push(kReadTwoHolding[i], at, i == 2));
        at += timing_.characterNs;
    }
    runUntil(at + 20 * kMillisecond);
    EXPECT_TRUE(port_.frames.empty());
    EXPECT_EQ(runner_.counters().damagedCharacters, 1u);
    EXPECT_EQ(runner_.transport().receiver().counters().damagedFrames, 1u);
    EXPECT_EQ(runner_.slave().counters().messages, 0u);
    exchange(kReadTwoHolding, now_ + timing_.characterNs);
    EXPECT_EQ(port_.frames.size(), 1u);
}

TEST_F(LineRunnerTest, NoAnswerToABadCrc)
{
    startSlave();
    Bytes bad = kReadTwoHolding;
    bad.back() ^= 0x01;
    exchange(bad, 10 * kMillisecond);
    EXPECT_TRUE(port_.frames.empty());
    EXPECT_EQ(runner_.transport().receiver().counters().crcErrors, 1u);
    EXPECT_EQ(runner_.slave().counters().messages, 0u);
    // The line is not stuck: the good frame after it is answered.
    exchange(kReadTwoHolding, now_);
    ASSERT_EQ(port_.frames.size(), 1u);
    EXPECT_EQ(port_.frames[0], kTwoHoldingAnswer);
}

TEST_F(LineRunnerTest, NoAnswerToAnotherSlavesAddress)
{
    startSlave();
    exchange(withCrc({kUnit + 1, 0x03, 0x00, 0x00, 0x00, 0x02}), 10 * kMillisecond);
    EXPECT_TRUE(port_.frames.empty());
    EXPECT_EQ(runner_.slave().counters().otherAddresses, 1u);
    EXPECT_EQ(runner_.transport().receiver().counters().framesDelivered, 1u);
}

TEST_F(LineRunnerTest, ABroadcastWriteIsExecutedWithoutAnAnswer)
{
    startSlave();
    exchange(withCrc({modbus::kBroadcastAddress, 0x06, 0x00, 0x05, 0x12, 0x34}), 10 * kMillisecond);
    EXPECT_TRUE(port_.frames.empty());
    EXPECT_EQ(model_.holdingRegister(5), 0x1234);
    EXPECT_EQ(runner_.slave().counters().messages, 1u);
    EXPECT_EQ(runner_.slave().counters().noResponses, 1u);
    // A broadcast read does nothing and is not answered either.
    exchange(withCrc({modbus::kBroadcastAddress, 0x03, 0x00, 0x05, 0x00, 0x01}), now_);
    EXPECT_TRUE(port_.frames.empty());
    EXPECT_EQ(runner_.slave().counters().noResponses, 2u);
}

TEST_F(LineRunnerTest, AFrameWithASilenceOverT15InsideIsDropped)
{
    startSlave();
    // Two character times of silence before the fifth byte: over t1.5 (1.5
    // characters), under t3.5, so the receiver sees one broken frame.
    const uint64_t last = receive(kReadTwoHolding, 10 * kMillisecond, 4, 2 * timing_.characterNs);
    runUntil(last + 20 * kMillisecond);
    EXPECT_TRUE(port_.frames.empty());
    EXPECT_EQ(runner_.transport().receiver().counters().gapErrors, 1u);
    EXPECT_EQ(runner_.slave().counters().messages, 0u);
}

TEST_F(LineRunnerTest, AFrameWithASilenceJustUnderT15InsideIsServed)
{
    startSlave();
    // The counterpart of the test above: a silence of t1.5 exactly is still
    // inside the frame. receive() runs the task at each byte's delivery time
    // before the byte is queued, as a wake for another reason would: the
    // character then on its way must not be taken for silence.
    const uint64_t last = receive(kReadTwoHolding, 10 * kMillisecond, 4, timing_.t15Ns);
    runUntil(last + 20 * kMillisecond);
    ASSERT_EQ(port_.frames.size(), 1u);
    EXPECT_EQ(port_.frames[0], kTwoHoldingAnswer);
    EXPECT_EQ(runner_.transport().receiver().counters().gapErrors, 0u);
}

TEST_F(LineRunnerTest, ARefusedAnswerIsCountedAndTheSlaveGoesOn)
{
    startSlave();
    port_.refuse = true;
    exchange(kReadTwoHolding, 10 * kMillisecond);
    EXPECT_TRUE(port_.frames.empty());
    EXPECT_EQ(port_.refused, 1u);
    EXPECT_EQ(runner_.counters().transmitRefused, 1u);
    EXPECT_EQ(runner_.counters().framesSent, 0u);
    EXPECT_FALSE(runner_.transmitting());
    port_.refuse = false;
    exchange(kReadTwoHolding, now_);
    ASSERT_EQ(port_.frames.size(), 1u);
    EXPECT_EQ(port_.frames[0], kTwoHoldingAnswer);
}

TEST_F(LineRunnerTest, OffServesNothingAndDropsWhatArrives)
{
    EXPECT_EQ(runner_.role(), Role::Off);
    EXPECT_TRUE(runner_.queue().push(0x11, 5));
    EXPECT_EQ(runner_.service(10), kNever);
    EXPECT_TRUE(runner_.queue().empty());
    EXPECT_EQ(runner_.submit(Request::readHoldingRegisters(kUnit, 0, 1).value(), 10), ModbusError::NotExpected);
    startSlave();
    EXPECT_EQ(runner_.submit(Request::readHoldingRegisters(kUnit, 0, 1).value(), 10), ModbusError::NotExpected);
    runner_.stop();
    EXPECT_EQ(runner_.role(), Role::Off);
}

TEST_F(LineRunnerTest, MasterGetsACorrectAnswer)
{
    startMaster(2);
    runUntil(10 * kMillisecond);
    ASSERT_EQ(runner_.submit(Request::readHoldingRegisters(kUnit, 0, 2).value(), now_), ModbusError::Ok);
    EXPECT_EQ(runner_.submit(Request::readHoldingRegisters(kUnit, 0, 2).value(), now_), ModbusError::Busy);
    ASSERT_EQ(port_.frames.size(), 1u);
    EXPECT_EQ(port_.frames[0], kReadTwoHolding);
    runUntil(now_ + kSlaveDelayNs);
    Completion completion;
    EXPECT_FALSE(runner_.takeCompletion(completion));
    const uint64_t last = receive(kTwoHoldingAnswer, now_);
    runUntil(frameEndNs(last));
    ASSERT_TRUE(runner_.takeCompletion(completion));
    EXPECT_EQ(completion.error, ModbusError::Ok);
    EXPECT_EQ(completion.function, 0x03);
    EXPECT_EQ(Bytes(completion.pdu, completion.pdu + completion.length), Bytes({0x03, 0x04, 0x12, 0x34, 0xAB, 0xCD}));
    EXPECT_FALSE(runner_.takeCompletion(completion));
    EXPECT_EQ(runner_.master().counters().transactions, 1u);
    EXPECT_EQ(runner_.master().counters().transmissions, 1u);
    EXPECT_EQ(runner_.master().counters().responses, 1u);
    EXPECT_EQ(runner_.counters().framesSent, 1u);
    EXPECT_EQ(runner_.counters().charactersReceived, kTwoHoldingAnswer.size());
}

// A slave may answer exactly t3.5 after the request's last stop bit
// ([SL] 2.5.1.1). The master learns when its request left from the transmit
// interrupt, whose handler runs some microseconds late; the answer must not
// be taken for one begun within the silence.
TEST_F(LineRunnerTest, MasterTakesAnAnswerBegunExactlyT35AfterItsRequestThoughItsInterruptRanLate)
{
    interruptLatencyNs_ = 20 * kMicrosecond;
    taskLatencyNs_ = 60 * kMicrosecond;
    startMaster(0);
    runUntil(10 * kMillisecond);
    ASSERT_EQ(runner_.submit(Request::readHoldingRegisters(kUnit, 0, 2).value(), now_), ModbusError::Ok);
    const uint64_t requestEndNs = port_.startedNs.back() + kReadTwoHolding.size() * timing_.characterNs;
    // The answer's first character starts t3.5 after the request's last stop
    // bit, so its own stop bit arrives one character time later.
    const uint64_t last = receive(kTwoHoldingAnswer, requestEndNs + timing_.t35Ns + timing_.characterNs);
    runUntil(frameEndNs(last) + taskLatencyNs_);
    Completion completion;
    ASSERT_TRUE(runner_.takeCompletion(completion));
    EXPECT_EQ(completion.error, ModbusError::Ok);
    EXPECT_EQ(runner_.master().counters().transmissions, 1u);
}

// The same for a slave: a master's next request may begin exactly t3.5 after
// the slave's answer left.
TEST_F(LineRunnerTest, SlaveServesARequestBegunExactlyT35AfterItsAnswerThoughItsInterruptRanLate)
{
    interruptLatencyNs_ = 20 * kMicrosecond;
    taskLatencyNs_ = 60 * kMicrosecond;
    startSlave();
    runUntil(10 * kMillisecond);
    exchange(kReadTwoHolding, now_);
    ASSERT_EQ(port_.frames.size(), 1u);
    const uint64_t answerEndNs = port_.startedNs.back() + port_.frames.back().size() * timing_.characterNs;
    const uint64_t last = receive(kReadTwoHolding, answerEndNs + timing_.t35Ns + timing_.characterNs);
    runUntil(last + 20 * kMillisecond);
    EXPECT_EQ(port_.frames.size(), 2u);
}

TEST_F(LineRunnerTest, MasterTimesOutAfterEveryRetry)
{
    startMaster(2);
    runUntil(10 * kMillisecond);
    ASSERT_EQ(runner_.submit(Request::readHoldingRegisters(kUnit, 0, 2).value(), now_), ModbusError::Ok);
    runUntil(now_ + 1000 * kMillisecond);
    // The first transmission and two retries of the same ADU, each a
    // time-out after the previous one left the line, counted from the
    // earliest the interrupt says it can have left
    // (LineRunner::kTransmitInterruptAllowanceNs before its stamp).
    ASSERT_EQ(port_.frames.size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(port_.frames[i], kReadTwoHolding);
    }
    for (size_t i = 1; i < 3; ++i) {
        EXPECT_EQ(port_.startedNs[i], port_.releasedNs[i - 1] + 100 * kMillisecond + timing_.characterNs -
                                          LineRunner::kTransmitInterruptAllowanceNs);
    }
    Completion completion;
    ASSERT_TRUE(runner_.takeCompletion(completion));
    EXPECT_EQ(completion.error, ModbusError::Timeout);
    EXPECT_EQ(completion.length, 0u);
    EXPECT_EQ(runner_.master().counters().timeouts, 3u);
    EXPECT_EQ(runner_.master().counters().transmissions, 3u);
    EXPECT_EQ(runner_.master().counters().failures, 1u);
    EXPECT_EQ(runner_.counters().framesSent, 3u);
    // The line is free for the next transaction.
    EXPECT_EQ(runner_.submit(Request::readHoldingRegisters(kUnit, 0, 2).value(), now_), ModbusError::Ok);
}

TEST_F(LineRunnerTest, MasterRetriesAfterAnAnswerWithABadCrc)
{
    startMaster(2);
    runUntil(10 * kMillisecond);
    ASSERT_EQ(runner_.submit(Request::readHoldingRegisters(kUnit, 0, 2).value(), now_), ModbusError::Ok);
    runUntil(now_ + kSlaveDelayNs);
    Bytes bad = kTwoHoldingAnswer;
    bad[3] ^= 0x80;
    uint64_t last = receive(bad, now_);
    runUntil(last + 150 * kMillisecond);
    // The damaged answer was dropped by the receiver, the attempt timed out and the request went again.
    EXPECT_EQ(runner_.transport().receiver().counters().crcErrors, 1u);
    ASSERT_EQ(port_.frames.size(), 2u);
    EXPECT_EQ(port_.frames[1], kReadTwoHolding);
    Completion completion;
    EXPECT_FALSE(runner_.takeCompletion(completion));
    last = receive(kTwoHoldingAnswer, now_);
    runUntil(frameEndNs(last));
    ASSERT_TRUE(runner_.takeCompletion(completion));
    EXPECT_EQ(completion.error, ModbusError::Ok);
    EXPECT_EQ(runner_.master().counters().timeouts, 1u);
    EXPECT_EQ(runner_.master().counters().transmissions, 2u);
    EXPECT_EQ(runner_.master().counters().responses, 1u);
}

TEST_F(LineRunnerTest, MasterTakesAnAnswerThatComesAfterItsTimeOutForNone)
{
    startMaster(0);
    runUntil(10 * kMillisecond);
    ASSERT_EQ(runner_.submit(Request::readHoldingRegisters(kUnit, 0, 2).value(), now_), ModbusError::Ok);
    runUntil(now_ + 150 * kMillisecond);
    Completion completion;
    ASSERT_TRUE(runner_.takeCompletion(completion));
    EXPECT_EQ(completion.error, ModbusError::Timeout);
    // The answer after the time-out belongs to no transaction: counted, not delivered.
    const uint64_t last = receive(kTwoHoldingAnswer, now_);
    runUntil(frameEndNs(last));
    EXPECT_FALSE(runner_.takeCompletion(completion));
    EXPECT_EQ(runner_.master().counters().foreignFrames, 1u);
    EXPECT_EQ(runner_.master().counters().responses, 0u);
    EXPECT_EQ(port_.frames.size(), 1u);
}

TEST_F(LineRunnerTest, MasterReportsAnExceptionAnswer)
{
    startMaster(2);
    runUntil(10 * kMillisecond);
    ASSERT_EQ(runner_.submit(Request::readHoldingRegisters(kUnit, 0, 2).value(), now_), ModbusError::Ok);
    runUntil(now_ + kSlaveDelayNs);
    const uint64_t last = receive(withCrc({kUnit, 0x83, 0x02}), now_);
    runUntil(frameEndNs(last));
    Completion completion;
    ASSERT_TRUE(runner_.takeCompletion(completion));
    EXPECT_EQ(completion.error, ModbusError::ExceptionResponse);
    EXPECT_EQ(completion.exception, ExceptionCode::IllegalDataAddress);
    // An exception is an answer: no retry.
    EXPECT_EQ(port_.frames.size(), 1u);
    EXPECT_EQ(runner_.master().counters().exceptions, 1u);
}

TEST_F(LineRunnerTest, MasterBroadcastCompletesAfterTheTurnaroundDelay)
{
    startMaster(2);
    runUntil(10 * kMillisecond);
    ASSERT_EQ(runner_.submit(Request::writeSingleRegister(modbus::kBroadcastAddress, 5, 0x1234).value(), now_),
              ModbusError::Ok);
    runUntil(now_ + 40 * kMillisecond);
    Completion completion;
    EXPECT_FALSE(runner_.takeCompletion(completion));
    runUntil(now_ + 20 * kMillisecond);
    ASSERT_TRUE(runner_.takeCompletion(completion));
    EXPECT_EQ(completion.error, ModbusError::Ok);
    EXPECT_EQ(completion.length, 0u);
    EXPECT_EQ(port_.frames.size(), 1u);
}

} // namespace

// -- a polling schedule on the line ------------------------------------------

TEST_F(LineRunnerTest, ASchedulePollsItsEntriesAndSaysWhichEnded)
{
    modbus::MasterConfig config;
    config.responseTimeoutNs = 100 * kMillisecond;
    config.retries = 1;
    ASSERT_EQ(runner_.startPolling(timing_, config, now_), ModbusError::Ok);
    EXPECT_TRUE(runner_.polling());
    ASSERT_TRUE(runner_.schedule().add(Request::readHoldingRegisters(kUnit, 0, 2).value(), 500 * kMillisecond,
                                       10 * kMillisecond).ok());
    ASSERT_TRUE(runner_.schedule().add(Request::readHoldingRegisters(kUnit + 1, 0, 2).value(), 500 * kMillisecond,
                                       10 * kMillisecond).ok());
    // The console's submit is refused while the schedule has the master.
    EXPECT_EQ(runner_.submit(Request::readHoldingRegisters(kUnit, 0, 2).value(), now_), ModbusError::Busy);
    runUntil(10 * kMillisecond + timing_.characterNs);
    ASSERT_EQ(port_.frames.size(), 1u);
    EXPECT_EQ(port_.frames[0], kReadTwoHolding);
    // Entry 0 is answered; nothing ended before its answer.
    runUntil(port_.startedNs[0] + kSlaveDelayNs);
    EXPECT_EQ(runner_.takePolled(), 0u);
    const uint64_t last = receive(kTwoHoldingAnswer, now_);
    runUntil(frameEndNs(last) + timing_.characterNs);
    EXPECT_EQ(runner_.takePolled(), 1u << 0);
    EXPECT_EQ(runner_.schedule().statistics(0).successes, 1u);
    EXPECT_EQ(runner_.schedule().response(0).registerValue(1), 0xABCD);
    // Entry 1's slave never answers: two transmissions, then its time-out ends it.
    runUntil(now_ + 400 * kMillisecond);
    ASSERT_EQ(port_.frames.size(), 3u);
    EXPECT_EQ(runner_.takePolled(), 1u << 1);
    EXPECT_EQ(runner_.schedule().statistics(1).timeouts, 1u);
    EXPECT_EQ(runner_.schedule().statistics(1).lastError, ModbusError::Timeout);
    // The next cycle polls entry 0 again, 500 ms after its first due time
    // (seen, like every deadline, once the line is known silent up to it:
    // one character later).
    runUntil(510 * kMillisecond + timing_.characterNs);
    ASSERT_EQ(port_.frames.size(), 4u);
    EXPECT_EQ(port_.startedNs[0], 10 * kMillisecond + timing_.characterNs);
    EXPECT_EQ(port_.startedNs[3], 510 * kMillisecond + timing_.characterNs);
    runner_.stop();
    EXPECT_FALSE(runner_.polling());
    // Polling again starts from an empty schedule.
    ASSERT_EQ(runner_.startPolling(timing_, config, now_), ModbusError::Ok);
    EXPECT_EQ(runner_.schedule().size(), 0u);
    EXPECT_EQ(runner_.schedule().statistics(0).transactions, 0u);
}

TEST_F(LineRunnerTest, AReplacedRequestGoesOutFromItsEntrysNextSubmission)
{
    modbus::MasterConfig config;
    config.responseTimeoutNs = 50 * kMillisecond;
    config.retries = 0;
    ASSERT_EQ(runner_.startPolling(timing_, config, now_), ModbusError::Ok);
    ASSERT_TRUE(runner_.schedule().add(Request::writeSingleRegister(kUnit, 4, 1).value(), 100 * kMillisecond).ok());
    runUntil(60 * kMillisecond);
    ASSERT_EQ(port_.frames.size(), 1u);
    EXPECT_EQ(port_.frames[0], withCrc({kUnit, 0x06, 0x00, 0x04, 0x00, 0x01}));
    ASSERT_EQ(runner_.schedule().replace(0, Request::writeSingleRegister(kUnit, 4, 2).value()), ModbusError::Ok);
    runUntil(160 * kMillisecond);
    ASSERT_EQ(port_.frames.size(), 2u);
    EXPECT_EQ(port_.frames[1], withCrc({kUnit, 0x06, 0x00, 0x04, 0x00, 0x02}));
    EXPECT_EQ(runner_.schedule().statistics(0).transactions, 2u);
    EXPECT_EQ(runner_.schedule().replace(1, Request::writeSingleRegister(kUnit, 4, 2).value()),
              ModbusError::InvalidArgument);
}
