#include <modbus/Crc16.hpp>
#include <modbus/RtuReceiver.hpp>

namespace modbus {

void RtuReceiver::onBytes(const uint8_t* bytes, size_t count, uint64_t nowNs)
{
    for (size_t i = 0; i < count; ++i) {
        onByte(bytes[i], nowNs);
    }
}

void RtuReceiver::onByte(uint8_t byte, uint64_t nowNs)
{
    // The character began one character time before it was delivered; the
    // silence before it ends there. A FIFO burst or a late timestamp cannot
    // make the silence negative.
    uint64_t startNs = nowNs >= timing_.characterNs ? nowNs - timing_.characterNs : 0;
    if (startNs < lastNs_) {
        startNs = lastNs_;
    }
    advance(startNs);

    switch (state_) {
    case State::Initial:
        ++counters_.ignoredCharacters;
        break;
    case State::Idle:
        state_ = State::Reception;
        notOk_ = false;
        damaged_ = false;
        overrun_ = false;
        length_ = 0;
        [[fallthrough]];
    case State::Reception:
        if (length_ < kMaxRtuAduLength) {
            buffers_[receiving_][length_++] = byte;
        } else {
            overrun_ = true;
        }
        break;
    case State::ControlAndWaiting:
        // [SL] Figure 14: a character after t1.5 makes the frame "not OK".
        // It is still part of the burst, so reception goes on and the whole
        // burst is discarded as one frame at the next t3.5.
        notOk_ = true;
        state_ = State::Reception;
        break;
    }
    if (nowNs > lastNs_) {
        lastNs_ = nowNs;
    }
}

void RtuReceiver::markLastCharacterDamaged()
{
    if (state_ == State::Reception) {
        damaged_ = true;
    }
}

void RtuReceiver::poll(uint64_t nowNs)
{
    advance(nowNs);
}

void RtuReceiver::restartSilence(uint64_t nowNs)
{
    state_ = State::Initial;
    length_ = 0;
    if (nowNs > lastNs_) {
        lastNs_ = nowNs;
    }
}

uint64_t RtuReceiver::nextDeadlineNs() const
{
    switch (state_) {
    case State::Initial:
    case State::Reception:
    case State::ControlAndWaiting:
        return lastNs_ + timing_.t35Ns;
    case State::Idle:
        break;
    }
    return kNoDeadline;
}

void RtuReceiver::advance(uint64_t nowNs)
{
    if (nowNs <= lastNs_) {
        return;
    }
    const uint64_t silenceNs = nowNs - lastNs_;
    switch (state_) {
    case State::Initial:
        if (silenceNs >= timing_.t35Ns) {
            state_ = State::Idle;
        }
        break;
    case State::Reception:
        if (silenceNs > timing_.t15Ns) {
            state_ = State::ControlAndWaiting;
        }
        [[fallthrough]];
    case State::ControlAndWaiting:
        if (silenceNs >= timing_.t35Ns) {
            finishFrame();
            state_ = State::Idle;
        }
        break;
    case State::Idle:
        break;
    }
}

void RtuReceiver::finishFrame()
{
    ++counters_.busMessages;
    if (notOk_) {
        ++counters_.gapErrors;
    } else if (damaged_) {
        ++counters_.damagedFrames;
    } else if (overrun_) {
        ++counters_.overruns;
    } else if (length_ < kMinRtuAduLength) {
        ++counters_.shortFrames;
    } else if (!Crc16::check(buffers_[receiving_], length_)) {
        ++counters_.crcErrors;
    } else {
        if (readyLength_ != 0) {
            ++counters_.framesLost;
        }
        ++counters_.framesDelivered;
        readyLength_ = length_;
        receiving_ = static_cast<uint8_t>(1 - receiving_);
    }
    length_ = 0;
}

} // namespace modbus
