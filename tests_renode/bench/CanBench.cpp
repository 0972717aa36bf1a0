// The cost of one CAN frame through the SJA1000 driver (drivers/can) and the
// CAN link layer (fieldbus/can), received and sent (bench image only).
//
// A frame costs the processor four pieces of work, each measured here as
// one call with interrupts disabled:
//
//   received: Can.ReceiveInterrupt  the driver's interrupt service routine
//                                   for RI: the frame read out of the chip's
//                                   FIFO, checked, put in the receive ring,
//                                   the owner told (a PostEvent);
//             Can.ReadFrame         a task takes it with systemAgent.Read and
//                                   the link layer decodes its DCOS
//                                   identifier (MessageIdentifier::fromFrame);
//   sent:     Can.WriteFrame        a task builds a DCOS frame (link layer:
//                                   MessageIdentifier::make, CanFrame::makeData)
//                                   and hands it to systemAgent.Write, which
//                                   queues it and loads it into the chip;
//             Can.TransmitInterrupt the interrupt service routine for TI: the
//                                   frame taken off the queue, counted, the
//                                   owner told.
//
// Every frame is the worst case of the frame rate: 8 data bytes, an
// extended DCOS identifier. The figures leave out the kernel's interrupt
// entry and exit around the routine (Kernel.InterruptLatency measures the
// entry); run_benchmarks.py adds the pieces up and gives the processor share
// at 7,407 frames per second (docs/performance.md, "CAN frames").
//
// The bench image runs without a lab bus, so channel 0 of the board's card
// is a chip alone on its bus; in self-test mode its transmissions complete
// without an acknowledge, and with self reception (CMR.SRR) it receives its
// own frame, as the data sheet's self test does. The channel's interrupt
// line is masked at the 8259 for the benchmark, so that each routine runs
// as the measured call, with the chip's interrupt flags set by a frame that
// has really passed through the chip; the unmeasured restore step brings
// that about by polling the status register (bounded).
#include "BenchSupport.hpp"

#include <sja1000/IsaSja1000Channel.hpp>
#include <sja1000/Sja1000Chip.hpp>

#include <bsp/Board.hpp>
#include <can/CanFrame.hpp>
#include <can/MessageIdentifier.hpp>
#include <dcos/SystemAgent.hpp>

namespace bench {
namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;
using dcos::systemAgent;
namespace reg = sja1000::reg;

// The card's first channel, as the console's `can` command has it; the
// benchmarks install their own driver object on it (the console's stays down).
sja1000::IsaSja1000Channel channel("can-bench", sja1000::kIsaCardDefaultBase, sja1000::kIsaCardDefaultIrq0);
// A second view of the same chip, for the benchmark's own requests (self
// reception) and to wait for the chip: never used while a routine runs.
const sja1000::Sja1000Chip chip(arch_x86::IoWindow::ports(sja1000::kIsaCardDefaultBase, reg::kWindowSize));
ObjectId channelId;

// The fastest CiA rate: the worst case for the processor.
constexpr uint32_t kBitRate = 1'000'000;
// The owner's events: an event bit the shell task never waits for.
constexpr uint32_t kOwnerEvent = 1u << 29;
// Status register polls before a frame counts as lost: a frame of 160 bits
// at 1 Mbit/s takes 160 us, well under 10^6 polls of one instruction each
// or more.
constexpr unsigned kMostPolls = 1'000'000;

// The DCOS frame every benchmark moves: priority 5, a DSM publication from
// node 1 to node 2, 8 data bytes.
constexpr uint8_t kPriority = 5;
constexpr uint8_t kSource = 1;
constexpr uint8_t kDestination = 2;
const uint8_t payload[can::CanFrame::kMaxDataLength] = {0x10, 0x21, 0x32, 0x43, 0x54, 0x65, 0x76, 0x87};

can::CanFrame benchFrame()
{
    const uint32_t id =
        can::MessageIdentifier::make(kPriority, can::MessageType::DsmPublication, kDestination, kSource)
            .value()
            .encode();
    return can::CanFrame::makeData(id, can::IdFormat::Extended, payload, sizeof payload).value();
}

volatile uint32_t decodedSource;

// Polls SR until every bit of @p bits is set; false when the chip never gets there.
bool waitForStatus(uint8_t bits)
{
    for (unsigned poll = 0; poll < kMostPolls; ++poll) {
        if ((chip.status() & bits) == bits) {
            return true;
        }
    }
    return false;
}

Status installChannel()
{
    if (channel.installed()) {
        return Status::Ok;
    }
    iobus::IsaConflict conflict;
    Result<ObjectId> id = channel.install("can-bench", dcos::Visibility::Local, &conflict);
    if (id.status() == Status::TableFull) {
        const Status grown = systemAgent.AddObjects(8);
        if (grown != Status::Ok) {
            return grown;
        }
        id = channel.install("can-bench", dcos::Visibility::Local, &conflict);
    }
    if (!id.ok()) {
        return id.status();
    }
    channelId = id.value();
    uint32_t rate = kBitRate;
    uint32_t mode = static_cast<uint32_t>(sja1000::BusMode::SelfTest);
    sja1000::Notification owner{self(), kOwnerEvent, kOwnerEvent, kOwnerEvent};
    Status status = systemAgent.Open(channelId);
    if (status == Status::Ok) {
        status = systemAgent.Control(channelId, sja1000::Sja1000Controller::kSetBitRate, &rate, sizeof rate);
    }
    if (status == Status::Ok) {
        status = systemAgent.Control(channelId, sja1000::Sja1000Controller::kSetBusMode, &mode, sizeof mode);
    }
    if (status == Status::Ok) {
        status = systemAgent.Control(channelId, sja1000::Sja1000Controller::kSetNotification, &owner, sizeof owner);
    }
    if (status != Status::Ok) {
        (void)systemAgent.Close(channelId);
        (void)channel.uninstall();
        return status;
    }
    // The routines run as the measured calls, not from the line.
    bsp::maskInterrupt(sja1000::kIsaCardDefaultIrq0);
    return Status::Ok;
}

void uninstallChannel()
{
    if (!channel.installed()) {
        return;
    }
    (void)systemAgent.Close(channelId);
    (void)channel.uninstall(); // Removes the routine and masks the line again.
}

// Sends the bench frame to the chip itself (self reception) and waits until
// it is received and the request complete; then reads IR once, which clears
// TI and leaves RI (it follows the FIFO), so the routine sees a reception only.
bool receiveOwnFrame()
{
    if (!waitForStatus(reg::kStatusTransmitBuffer)) {
        return false;
    }
    chip.writeTransmitBuffer(benchFrame());
    chip.transmit(/*selfReception=*/true);
    if (!waitForStatus(reg::kStatusReceiveBuffer | reg::kStatusTransmitComplete | reg::kStatusTransmitBuffer)) {
        return false;
    }
    (void)chip.interrupts();
    return true;
}

// Empties the driver's receive ring, unmeasured.
void drainRing()
{
    can::CanFrame frames[8];
    for (;;) {
        const Result<size_t> read = systemAgent.Read(channelId, 0, frames, sizeof frames);
        if (!read.ok() || read.value() == 0) {
            return;
        }
    }
}

// -- Can.ReceiveInterrupt ------------------------------------------------------

bool receptionPending()
{
    drainRing();
    return receiveOwnFrame();
}

void prepareReception()
{
    if (!receptionPending()) {
        check(Status::Timeout);
    }
}

Status setupReception(uint32_t)
{
    const Status installed = installChannel();
    if (installed != Status::Ok) {
        return installed;
    }
    return receptionPending() ? Status::Ok : Status::Timeout;
}

void receiveInterrupt() { channel.handleInterrupt(); }

// -- Can.ReadFrame ---------------------------------------------------------------

bool framePending()
{
    if (!receptionPending()) {
        return false;
    }
    channel.handleInterrupt(); // The frame into the receive ring.
    return true;
}

void prepareRead()
{
    if (!framePending()) {
        check(Status::Timeout);
    }
}

Status setupRead(uint32_t)
{
    const Status installed = installChannel();
    if (installed != Status::Ok) {
        return installed;
    }
    return framePending() ? Status::Ok : Status::Timeout;
}

void readFrame()
{
    can::CanFrame frame;
    const Result<size_t> read = systemAgent.Read(channelId, 0, &frame, sizeof frame);
    if (!read.ok() || read.value() != sizeof frame) {
        check(read.ok() ? Status::NotFound : read.status());
        return;
    }
    const can::LinkResult<can::MessageIdentifier> id = can::MessageIdentifier::fromFrame(frame);
    if (!id.ok()) {
        check(Status::InvalidArgument);
        return;
    }
    decodedSource = id.value().source();
}

// -- Can.WriteFrame ----------------------------------------------------------------

// Lets the chip finish the frame the last Write loaded and the routine take
// it off the queue, so the next Write finds an empty queue and a free buffer.
void finishTransmission()
{
    if (!waitForStatus(reg::kStatusTransmitComplete | reg::kStatusTransmitBuffer)) {
        check(Status::Timeout);
        return;
    }
    channel.handleInterrupt();
}

Status setupWrite(uint32_t)
{
    const Status installed = installChannel();
    if (installed != Status::Ok) {
        return installed;
    }
    drainRing();
    return waitForStatus(reg::kStatusTransmitBuffer) ? Status::Ok : Status::Timeout;
}

void writeFrame()
{
    const can::LinkResult<can::MessageIdentifier> id =
        can::MessageIdentifier::make(kPriority, can::MessageType::DsmPublication, kDestination, kSource);
    if (!id.ok()) {
        check(Status::InvalidArgument);
        return;
    }
    const can::LinkResult<can::CanFrame> frame =
        can::CanFrame::makeData(id.value().encode(), can::IdFormat::Extended, payload, sizeof payload);
    if (!frame.ok()) {
        check(Status::InvalidArgument);
        return;
    }
    const Result<size_t> written = systemAgent.Write(channelId, 0, &frame.value(), sizeof(can::CanFrame));
    if (!written.ok() || written.value() != sizeof(can::CanFrame)) {
        check(written.ok() ? Status::Busy : written.status());
    }
}

// -- Can.TransmitInterrupt -----------------------------------------------------------

// Writes a frame (unmeasured) and waits until the chip has sent it: TI is
// then pending for the routine.
bool transmissionDone()
{
    const can::CanFrame frame = benchFrame();
    const Result<size_t> written = systemAgent.Write(channelId, 0, &frame, sizeof frame);
    return written.ok() && written.value() == sizeof frame &&
           waitForStatus(reg::kStatusTransmitComplete | reg::kStatusTransmitBuffer);
}

void prepareTransmitDone()
{
    if (!transmissionDone()) {
        check(Status::Timeout);
    }
}

Status setupTransmitDone(uint32_t)
{
    const Status installed = installChannel();
    if (installed != Status::Ok) {
        return installed;
    }
    drainRing();
    return transmissionDone() ? Status::Ok : Status::Timeout;
}

void transmitInterrupt() { channel.handleInterrupt(); }

} // namespace
} // namespace bench

DCOS_BENCHMARK(canReceiveInterruptBench, "Can.ReceiveInterrupt", bench::setupReception, bench::receiveInterrupt,
               bench::Cost::Constant, .restore = bench::prepareReception, .teardown = bench::uninstallChannel);
DCOS_BENCHMARK(canReadFrameBench, "Can.ReadFrame", bench::setupRead, bench::readFrame, bench::Cost::Constant,
               .restore = bench::prepareRead, .teardown = bench::uninstallChannel);
DCOS_BENCHMARK(canWriteFrameBench, "Can.WriteFrame", bench::setupWrite, bench::writeFrame, bench::Cost::Constant,
               .restore = bench::finishTransmission, .teardown = bench::uninstallChannel);
DCOS_BENCHMARK(canTransmitInterruptBench, "Can.TransmitInterrupt", bench::setupTransmitDone,
               bench::transmitInterrupt, bench::Cost::Constant, .restore = bench::prepareTransmitDone,
               .teardown = bench::uninstallChannel);
