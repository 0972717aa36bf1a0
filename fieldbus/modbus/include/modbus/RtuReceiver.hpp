// The receive side of an RTU line: the state machine of [SL] 2.5.1.1,
// Figure 14, driven by the times the characters arrive.
//
//     Initial             every character restarts t3.5; t3.5 of silence -> Idle
//     Idle                a character starts a frame -> Reception
//     Reception           characters are stored; silence > t1.5 -> Control and waiting
//     Control and waiting the frame is checked; a character here flags it "not OK"
//                         (and reception goes on, so the whole burst is one frame);
//                         t3.5 of silence -> the frame is delivered or discarded, Idle
//
// Time is a monotonic count of nanoseconds passed in by the caller; nothing
// here reads a clock. The time given with a character is when the UART
// delivered it, that is the end of its stop bit; the silence before it is
// therefore its time minus the previous character's minus one character time
// (clamped at zero, since a UART FIFO hands several characters over at once).
// poll() lets time pass without a character; the caller calls it at
// nextDeadlineNs() or later, and any call with a later time (a character's
// included) applies the timers that expired before it first.
//
// A frame is delivered when its CRC is right, it is 4 to 256 bytes long and no
// gap longer than t1.5 occurred inside it; everything else is discarded and
// counted, as [SL] 6.1 (the diagnostic counters of function 08) counts it.
// The receiver keeps two buffers: a delivered frame stays readable while the
// next one arrives, until takeFrame(), or until a second frame is delivered
// on top of it (counted as lost).
#pragma once

#include <modbus/Protocol.hpp>
#include <modbus/RtuTiming.hpp>

#include <stddef.h>
#include <stdint.h>

namespace modbus {

class RtuReceiver {
public:
    /// What nextDeadlineNs() returns when nothing is timed.
    static constexpr uint64_t kNoDeadline = ~static_cast<uint64_t>(0);

    /// The states of [SL] Figure 14 (the emission state belongs to the
    /// station; after it the line is Initial again, see restartSilence()).
    enum class State : uint8_t { Initial, Idle, Reception, ControlAndWaiting };

    /// What the receiver saw since it was made; modelled on the counters of
    /// function 08 ([AP] 6.8, sub-functions 0x0B, 0x0C and 0x12).
    struct Counters {
        uint32_t busMessages = 0;        ///< Every frame seen on the line, good or bad (0x0B).
        uint32_t crcErrors = 0;          ///< Frames discarded for a wrong CRC (0x0C).
        uint32_t overruns = 0;           ///< Frames discarded for running past 256 bytes (0x12).
        uint32_t gapErrors = 0;          ///< Frames discarded for a silence above t1.5 inside them.
        uint32_t shortFrames = 0;        ///< Frames of fewer than 4 bytes.
        uint32_t framesDelivered = 0;    ///< Frames delivered whole and checked.
        uint32_t framesLost = 0;         ///< Delivered frames replaced by the next before takeFrame().
        uint32_t ignoredCharacters = 0;  ///< Characters received before the line was idle (Initial).
        uint32_t damagedFrames = 0;      ///< Frames discarded for a character with a parity or framing error.
    };

    /// A receiver for a line with @p timing, in the Initial state since time 0.
    explicit RtuReceiver(const RtuTiming& timing = RtuTiming{}) : timing_(timing) {}

    /// One character, delivered by the UART at @p nowNs.
    void onByte(uint8_t byte, uint64_t nowNs);

    /// Several characters delivered at once at @p nowNs (a UART FIFO).
    void onBytes(const uint8_t* bytes, size_t count, uint64_t nowNs);

    /// Lets time pass: applies the t1.5 and t3.5 timers up to @p nowNs.
    /// The UART said the character just given to onByte() arrived with a
    /// parity or framing error (or as a break): the frame it belongs to is
    /// "not OK" and is discarded at its end ([SL] Figure 14 checks parity
    /// with the CRC). A character that was ignored (Initial) changes nothing.
    void markLastCharacterDamaged();

    void poll(uint64_t nowNs);

    /// The time from which the line has been silent: the station calls it
    /// when its own frame has left the UART, since [SL] Figure 14 leaves the
    /// emission state only after t3.5 of silence. The receiver is Initial
    /// again and drops a partial frame (an echo of the station's own bytes).
    void restartSilence(uint64_t nowNs);

    /// When poll() has something to do, or kNoDeadline.
    uint64_t nextDeadlineNs() const;

    /// Whether a checked frame waits in frame().
    bool frameReady() const { return readyLength_ != 0; }
    /// The delivered frame: address, PDU and CRC; valid until the next call
    /// that delivers another frame or takeFrame().
    const uint8_t* frame() const { return buffers_[1 - receiving_]; }
    /// Its length with the address and the CRC; 0 when none is ready.
    size_t frameLength() const { return readyLength_; }
    /// Releases the delivered frame.
    void takeFrame() { readyLength_ = 0; }

    /// Whether the line has been silent for t3.5 and no frame is arriving, so
    /// that a station may transmit.
    bool idle() const { return state_ == State::Idle; }
    State state() const { return state_; }
    const RtuTiming& timing() const { return timing_; }
    const Counters& counters() const { return counters_; }

private:
    void advance(uint64_t nowNs);
    void finishFrame();

    RtuTiming timing_;
    State state_ = State::Initial;
    uint64_t lastNs_ = 0;      // when the last character ended (or the silence began)
    bool notOk_ = false;       // a character arrived in Control and waiting
    bool damaged_ = false;     // a character of the frame came with a parity or framing error
    bool overrun_ = false;     // the frame ran past kMaxRtuAduLength
    size_t length_ = 0;        // bytes stored of the frame being received
    size_t readyLength_ = 0;   // bytes of the delivered frame, 0 when none
    uint8_t receiving_ = 0;    // which buffer takes the frame being received
    uint8_t buffers_[2][kMaxRtuAduLength] = {};
    Counters counters_;
};

} // namespace modbus
