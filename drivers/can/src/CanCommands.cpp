// The console command `can`: bring the board's CAN channels up and down,
// send and dump frames in can-utils' text form, and show each channel's
// state and counters (docs/can/driver.md).
//
// The console owns one driver object per channel, can0 and can1
// (sja1000/BoardCanChannel.hpp): the ISA card's two chips, or on a node
// that owns a PCI bus the chips of the Kvaser PCIcan cards it finds at
// boot, then the ISA card's (placeChannels()). `up` installs a channel
// with the system agent and keeps one open on it, so the chip stays on the
// bus between commands; `down` closes and uninstalls it again. The console
// task is the channel's owner: `up` registers it for the driver's events,
// so every change of the error state is posted to it and kept in the
// driver's state log until `events` reads it. The
// commands that wait (send, dump) wait for the driver's events, never by
// polling, and always with a time-out.
#include <sja1000/CanNetworkLink.hpp>
#include <sja1000/BoardCanChannel.hpp>
#include <sja1000/KvaserPciCard.hpp>
#include <pci/ConfigSpace.hpp>

#include <can/FrameText.hpp>
#include <can/IsoTpReceiver.hpp>
#include <can/IsoTpSender.hpp>
#include <dcos/NetworkInterfacesManager.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/NetworkBootHooks.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <boot/BootInfo.hpp>
#include <bsp/Board.hpp>
#include <can/MessageIdentifier.hpp>
#include <runtime/Text.hpp>
#include <shell/Shell.hpp>

namespace sja1000 {

namespace {

using dcos::Status;
using dcos::systemAgent;
using dcos::taskAgent;
using shell::CommandResult;

constexpr unsigned kChannels = 2;
BoardCanChannel consoleChannels[kChannels] = {
    {"can0", kIsaCardDefaultBase, kIsaCardDefaultIrq0},
    {"can1", kIsaCardDefaultBase + kIsaSecondChannelOffset, kIsaCardDefaultIrq1},
};
const char* const kNames[kChannels] = {"can0", "can1"};

// Gives the channels to the chips of the Kvaser PCIcan cards on this
// node's PCI bus, in the order the bus has them, each card's interrupt
// routed first; the channels left over stay the ISA card's. Once, at the
// first use (the root task's networkBootStart, before any shell); what it
// finds wrong with a card it says on @p out, and that card is passed over.
void placeChannels(runtime::CharacterSink& out)
{
    static bool placed = false;
    if (placed) {
        return;
    }
    placed = true;
    if (!bsp::ownsPciBus()) {
        return;
    }
    const pci::ConfigSpace config;
    if (config.probe() != Status::Ok) {
        runtime::format(out, "can: no PCI configuration mechanism #1 answers; the ISA card's channels only\r\n");
        return;
    }
    // Bounded by the functions a bus can have; a card probe() refuses ends
    // the search only when it is the last there is.
    constexpr unsigned kMostCards = 32;
    unsigned next = 0;
    for (unsigned index = 0; index < kMostCards && next < kChannels; ++index) {
        KvaserPciProblem problem;
        const dcos::Result<KvaserPciCard> found = KvaserPciCard::probe(config, index, &problem);
        if (!found.ok()) {
            if (problem.fault == KvaserPciFault::NoCard) {
                break;
            }
            runtime::format(out, "can: Kvaser PCIcan %u passed over: %s (BAR%u): %s\r\n", index,
                            kvaserPciFaultName(problem.fault), problem.bar, dcos::statusName(found.status()));
            continue;
        }
        const KvaserPciCard& card = found.value();
        const Status routed = bsp::routePciInterrupt(card.bus(), card.device(),
                                                     static_cast<uint8_t>(card.interruptPin() - 1),
                                                     card.interruptLine());
        if (routed != Status::Ok) {
            runtime::format(out, "can: Kvaser PCIcan at %02x:%02x.%x passed over: its interrupt (irq %u) cannot "
                                 "be routed: %s\r\n",
                            card.bus(), card.device(), card.function(), card.interruptLine(),
                            dcos::statusName(routed));
            continue;
        }
        for (unsigned chip = 0; chip < card.channelCount() && next < kChannels; ++chip) {
            if (consoleChannels[next].placeOnPciCard(card, chip) == Status::Ok) {
                ++next;
            }
        }
    }
}

// The console task's events for the driver; bit 0 is the console's input.
constexpr uint32_t kReceiveEvent = 1u << 20;
constexpr uint32_t kStateEvent = 1u << 21;
constexpr uint32_t kSentEvent = 1u << 22;

constexpr uint64_t kMillisecond = 1'000'000;
constexpr unsigned long kDefaultSendTimeoutMs = 1000;
constexpr unsigned long kDefaultDumpTimeoutMs = 1000;
constexpr unsigned long kLongestTimeoutMs = 600'000;

const char* stateName(ErrorState state)
{
    switch (state) {
    case ErrorState::Active: return "error-active";
    case ErrorState::Warning: return "error-warning";
    case ErrorState::Passive: return "error-passive";
    case ErrorState::BusOff: return "bus-off";
    }
    return "?";
}

// Parses a channel argument, "0", "1", "can0" or "can1"; prints why not.
bool parseChannel(shell::Shell& shell, const char* text, unsigned& channel)
{
    for (unsigned i = 0; i < kChannels; ++i) {
        if ((text[0] == static_cast<char>('0' + i) && text[1] == '\0') ||
            (text[0] == 'c' && text[1] == 'a' && text[2] == 'n' && text[3] == static_cast<char>('0' + i) &&
             text[4] == '\0')) {
            channel = i;
            return true;
        }
    }
    shell.print("error: unknown channel '%s': the channels are can0 and can1 (or 0 and 1)\r\n", text);
    return false;
}

// The network links of the channels (can attach): while one is attached,
// the channel's frames belong to the remote agent.
CanNetworkLink networkLinks[kChannels];
uint8_t attachedInterface[kChannels];

// Whether the channel carries a network interface, which the commands that
// take its frames or change its set-up must leave alone; prints so.
bool attachedToNetwork(shell::Shell& shell, unsigned channel)
{
    if (!networkLinks[channel].started()) {
        return false;
    }
    shell.print("error: %s carries network interface %u; 'can detach %s' first\r\n", kNames[channel],
                attachedInterface[channel], kNames[channel]);
    return true;
}

// The channel's driver, up and, unless @p allowAttached, not attached to
// the network; prints why not.
bool requireUp(shell::Shell& shell, unsigned channel, bool allowAttached = false)
{
    if (!consoleChannels[channel].installed()) {
        shell.print("error: %s is down; bring it up with 'can up %s'\r\n", kNames[channel], kNames[channel]);
        return false;
    }
    return allowAttached || !attachedToNetwork(shell, channel);
}

// The channel of a subcommand whose one argument is a channel that is up
// ("can down can0"); false, with the usage or the error printed, otherwise.
bool soleUpChannel(shell::Shell& shell, int argc, char** argv, const char* usage, unsigned& channel,
                   bool allowAttached = false)
{
    if (argc != 3) {
        shell.print("usage: %s\r\n", usage);
        return false;
    }
    return parseChannel(shell, argv[2], channel) && requireUp(shell, channel, allowAttached);
}
// Points the driver's events at the task running the command (the shell
// may have been restarted since the channel came up).
void listenHere(unsigned channel)
{
    Notification notification{taskAgent.IdOfSelf(), kReceiveEvent, kStateEvent, kSentEvent};
    (void)systemAgent.Control(consoleChannels[channel].id(), Sja1000Controller::kSetNotification, &notification,
                              sizeof notification); // Cannot fail: the channel is up and the argument is right.
}

BusState stateOf(unsigned channel)
{
    BusState state{};
    (void)systemAgent.Control(consoleChannels[channel].id(), Sja1000Controller::kGetState, &state, sizeof state);
    return state;
}

bool parseMilliseconds(shell::Shell& shell, const char* text, unsigned long& ms)
{
    if (!shell::Shell::parseUnsigned(text, ms) || ms > kLongestTimeoutMs) {
        shell.print("error: time-out '%s' is not a number of milliseconds up to %lu\r\n", text, kLongestTimeoutMs);
        return false;
    }
    return true;
}

// Installs the channel's driver with the system agent and keeps it open,
// unless it is already; says why not on @p out.
bool install(runtime::CharacterSink& out, unsigned channel)
{
    BoardCanChannel& driver = consoleChannels[channel];
    if (driver.installed()) {
        return true;
    }
    const dcos::Result<dcos::ObjectId> installed = driver.install(dcos::Visibility::Regional, out);
    if (!installed.ok()) {
        return false;
    }
    // The device belongs to the system, so that no task's recovery
    // (the shell's, should it fail) takes the channel away.
    (void)systemAgent.XferOwnership(installed.value(), dcos::ObjectId{});
    const Status opened = systemAgent.Open(installed.value());
    if (opened != Status::Ok) {
        runtime::format(out, "error: no SJA1000 answers at 0x%03x: %s\r\n", driver.basePort(),
                        dcos::statusName(opened));
        (void)driver.uninstall(); // Not open, so it goes.
        return false;
    }
    return true;
}

// Sets the installed channel's bit rate and prints the line 'can up'
// prints; says why not on @p out.
bool setBitRate(runtime::CharacterSink& out, unsigned channel, uint32_t rate)
{
    BoardCanChannel& driver = consoleChannels[channel];
    const Status set = systemAgent.Control(driver.id(), Sja1000Controller::kSetBitRate, &rate, sizeof rate);
    if (set != Status::Ok) {
        runtime::format(out, "error: cannot set the bit rate: %s\r\n", dcos::statusName(set));
        return false;
    }
    const BusState state = stateOf(channel);
    // The ISA card's line is as it always was; a PCI card's names the card.
    char place[48] = "";
    if (driver.onPciCard()) {
        char where[44];
        driver.describePlace(where, sizeof where);
        runtime::formatToBuffer(place, sizeof place, " (%s)", where);
    }
    runtime::format(out, "%s up at 0x%03x irq %u%s: %lu bit/s, sample point %u.%u %%, %s\r\n", kNames[channel],
                    driver.basePort(), driver.irq(), place, static_cast<unsigned long>(state.bitRate),
                    state.samplePointPermille / 10, state.samplePointPermille % 10, stateName(state.errorState));
    return true;
}

// Whether @p text is a bit rate the chip makes exactly; says why not on @p out.
bool parseBitRate(runtime::CharacterSink& out, const char* text, uint32_t& rate)
{
    unsigned long value = 0;
    if (!shell::Shell::parseUnsigned(text, value) || value > UINT32_MAX ||
        !BitTimingCalculator::forBitRate(static_cast<uint32_t>(value)).ok()) {
        runtime::format(out, "error: bit rate '%s' cannot be made exactly; the CiA rates are 10000, 20000, 50000, "
                             "125000, 250000, 500000, 800000 and 1000000\r\n",
                        text);
        return false;
    }
    rate = static_cast<uint32_t>(value);
    return true;
}

CommandResult up(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    if (argc < 3 || argc > 4) {
        shell.print("usage: can up <channel> [bit rate]\r\n");
        return CommandResult::Failed;
    }
    if (!parseChannel(shell, argv[2], channel)) {
        return CommandResult::Failed;
    }
    uint32_t rate = Sja1000Controller::kDefaultBitRate;
    if (argc == 4 && !parseBitRate(shell.output(), argv[3], rate)) {
        return CommandResult::Failed;
    }
    if (attachedToNetwork(shell, channel) || !install(shell.output(), channel)) {
        return CommandResult::Failed;
    }
    // The owner learns of every state change from now on, not only while a
    // command that sends or receives runs.
    listenHere(channel);
    return setBitRate(shell.output(), channel, rate) ? CommandResult::Ok : CommandResult::Failed;
}

CommandResult down(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    if (!soleUpChannel(shell, argc, argv, "can down <channel>", channel)) {
        return CommandResult::Failed;
    }
    BoardCanChannel& driver = consoleChannels[channel];
    while (systemAgent.Close(driver.id()) == Status::Ok) {
    }
    const Status removed = driver.uninstall();
    if (removed != Status::Ok) {
        shell.print("error: cannot take %s down: %s\r\n", kNames[channel], dcos::statusName(removed));
        return CommandResult::Failed;
    }
    shell.print("%s down\r\n", kNames[channel]);
    return CommandResult::Ok;
}

CommandResult send(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    unsigned long timeoutMs = kDefaultSendTimeoutMs;
    if (argc < 4 || argc > 5) {
        shell.print("usage: can send <channel> <id>#<data> [time-out ms]\r\n");
        return CommandResult::Failed;
    }
    if (!parseChannel(shell, argv[2], channel) || !requireUp(shell, channel) ||
        (argc == 5 && !parseMilliseconds(shell, argv[4], timeoutMs))) {
        return CommandResult::Failed;
    }
    const can::LinkResult<can::CanFrame> frame = can::FrameText::parse(argv[3]);
    if (!frame.ok()) {
        shell.print("error: '%s' is not a frame (%s): write <id>#<data>, 3 hex digits for a standard identifier, 8 "
                    "for an extended one, e.g. 123#DEADBEEF or 1ABCDEF0#01.02\r\n",
                    argv[3], can::linkErrorName(frame.error()));
        return CommandResult::Failed;
    }
    listenHere(channel);
    // Any earlier sent event is stale; this one is for this frame.
    (void)taskAgent.ReceiveEvent(kSentEvent, dcos::EventWait::Any, dcos::kPoll);
    const dcos::Result<size_t> written =
        systemAgent.Write(consoleChannels[channel].id(), 0, &frame.value(), sizeof(can::CanFrame));
    if (!written.ok() || written.value() != sizeof(can::CanFrame)) {
        shell.print("error: %s did not take the frame: %s\r\n", kNames[channel],
                    written.ok() ? "its transmit queue is full" : dcos::statusName(written.status()));
        return CommandResult::Failed;
    }
    const dcos::Result<uint32_t> woken =
        taskAgent.ReceiveEvent(kSentEvent, dcos::EventWait::Any, timeoutMs * kMillisecond);
    if (!woken.ok()) {
        const BusState state = stateOf(channel);
        shell.print("error: not sent within %lu ms: %s, %u transmit errors%s; the frame stays queued\r\n", timeoutMs,
                    stateName(state.errorState), state.transmitErrors,
                    state.noAcknowledge ? ", no other node acknowledges" : "");
        return CommandResult::Failed;
    }
    char text[can::FrameText::kMaxFormattedLength + 1];
    (void)can::FrameText::format(frame.value(), text, sizeof text);
    shell.print("%s  %s  sent\r\n", kNames[channel], text);
    return CommandResult::Ok;
}

// The arguments of a subcommand that waits on a channel: "<channel>
// [count] [time-out ms]", the channel up, the count from @p leastCount to
// 10000. False, with the usage or the error printed, otherwise.
bool channelCountTimeout(shell::Shell& shell, int argc, char** argv, const char* usage, unsigned long leastCount,
                         unsigned& channel, unsigned long& count, unsigned long& timeoutMs)
{
    if (argc < 3 || argc > 5) {
        shell.print("usage: %s <channel> [count] [time-out ms]\r\n", usage);
        return false;
    }
    if (!parseChannel(shell, argv[2], channel) || !requireUp(shell, channel)) {
        return false;
    }
    if (argc >= 4 && (!shell::Shell::parseUnsigned(argv[3], count) || count < leastCount || count > 10000)) {
        shell.print("error: count '%s' is not a number from %lu to 10000\r\n", argv[3], leastCount);
        return false;
    }
    return argc != 5 || parseMilliseconds(shell, argv[4], timeoutMs);
}

CommandResult dump(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    unsigned long count = 1;
    unsigned long timeoutMs = kDefaultDumpTimeoutMs;
    if (!channelCountTimeout(shell, argc, argv, "can dump", 1, channel, count, timeoutMs)) {
        return CommandResult::Failed;
    }
    listenHere(channel);
    const uint64_t deadline = dcos::timerAgent.Uptime() + timeoutMs * kMillisecond;
    unsigned long shown = 0;
    while (shown < count) {
        // No more frames than are still to be shown: the driver hands over
        // what fits, and a frame taken past the count would be lost to the
        // next reader.
        can::CanFrame frames[8];
        const size_t wanted = count - shown < 8 ? count - shown : 8;
        const dcos::Result<size_t> read =
            systemAgent.Read(consoleChannels[channel].id(), 0, frames, wanted * sizeof(can::CanFrame));
        if (!read.ok()) {
            shell.print("error: cannot read %s: %s\r\n", kNames[channel], dcos::statusName(read.status()));
            return CommandResult::Failed;
        }
        const size_t got = read.value() / sizeof(can::CanFrame);
        for (size_t i = 0; i < got && shown < count; ++i, ++shown) {
            char text[can::FrameText::kMaxFormattedLength + 1];
            (void)can::FrameText::format(frames[i], text, sizeof text);
            shell.print("%s  %s\r\n", kNames[channel], text);
        }
        if (got != 0) {
            continue;
        }
        const uint64_t now = dcos::timerAgent.Uptime();
        if (now >= deadline) {
            break;
        }
        // Frames that arrive between the Read and this wait have posted the
        // event already, so the wait returns at once for them.
        (void)taskAgent.ReceiveEvent(kReceiveEvent, dcos::EventWait::Any, deadline - now);
    }
    if (shown < count) {
        shell.print("%lu of %lu frames within %lu ms\r\n", shown, count, timeoutMs);
        return CommandResult::Failed;
    }
    return CommandResult::Ok;
}

// -- ISO 15765-2 transfers, with the link layer's state machines ------------

// An ISO-TP identifier as can-utils' isotpsend takes it: hexadecimal,
// extended when it does not fit 11 bits or is written with 8 digits.
bool parseIsoTpId(shell::Shell& shell, const char* text, uint32_t& id, bool& extended)
{
    unsigned digits = 0;
    uint32_t value = 0;
    for (const char* p = text; *p != '\0'; ++p, ++digits) {
        const char c = *p;
        const int digit = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10
                                                          : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
        if (digit < 0 || digits == 8) {
            digits = 9;
            break;
        }
        value = (value << 4) | static_cast<uint32_t>(digit);
    }
    if (digits == 0 || digits > 8 || value > can::CanFrame::kMaxExtendedId) {
        shell.print("error: '%s' is not a CAN identifier in hexadecimal (e.g. 7E0 or 18DA00F1)\r\n", text);
        return false;
    }
    id = value;
    extended = value > can::CanFrame::kMaxStandardId || digits == 8;
    return true;
}

// The channel, source and destination of an isotp subcommand (argv[2..4]).
bool isoTpConnection(shell::Shell& shell, char** argv, unsigned& channel, can::IsoTpConfig& config)
{
    bool sourceExtended = false;
    bool destinationExtended = false;
    if (!parseChannel(shell, argv[2], channel) || !requireUp(shell, channel) ||
        !parseIsoTpId(shell, argv[3], config.txId, sourceExtended) ||
        !parseIsoTpId(shell, argv[4], config.rxId, destinationExtended)) {
        return false;
    }
    config.format = sourceExtended || destinationExtended ? can::IdFormat::Extended : can::IdFormat::Standard;
    return true;
}

// Puts one frame of a transfer on the bus and waits until it was sent: the
// confirmation ISO-TP's N_As measures.
bool sendConfirmed(unsigned channel, const can::CanFrame& frame, uint64_t timeoutNs)
{
    (void)taskAgent.ReceiveEvent(kSentEvent, dcos::EventWait::Any, dcos::kPoll); // A stale one means nothing.
    const dcos::Result<size_t> written =
        systemAgent.Write(consoleChannels[channel].id(), 0, &frame, sizeof(can::CanFrame));
    if (!written.ok() || written.value() != sizeof(can::CanFrame)) {
        return false;
    }
    return taskAgent.ReceiveEvent(kSentEvent, dcos::EventWait::Any, timeoutNs).ok();
}

// Takes the next received frame off the channel's queue; false when it is empty.
bool takeFrame(unsigned channel, can::CanFrame& frame)
{
    const dcos::Result<size_t> read =
        systemAgent.Read(consoleChannels[channel].id(), 0, &frame, sizeof(can::CanFrame));
    return read.ok() && read.value() == sizeof(can::CanFrame);
}

// Waits for the next received frame until @p deadlineNs (uptime); false when none came.
bool nextFrame(unsigned channel, uint64_t deadlineNs, can::CanFrame& frame)
{
    for (;;) {
        if (takeFrame(channel, frame)) {
            return true;
        }
        const uint64_t now = dcos::timerAgent.Uptime();
        if (now >= deadlineNs) {
            return false;
        }
        (void)taskAgent.ReceiveEvent(kReceiveEvent, dcos::EventWait::Any, deadlineNs - now);
    }
}

// Empties the channel's receive queue. A transfer begins with it, as a Linux
// can-isotp socket only sees frames that arrive after it was bound: a flow
// control left over from an earlier, timed-out transfer must not let the
// next one send its consecutive frames before the peer asked for them.
void discardReceived(unsigned channel)
{
    can::CanFrame frame;
    while (takeFrame(channel, frame)) {
    }
}

// Frames of other connections read while waiting are dropped: the console's
// transfers own the channel while they run, as isotpsend owns its socket.
CommandResult isoTpSend(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    can::IsoTpConfig config;
    if (argc != 6) {
        shell.print("usage: can isotp-send <channel> <source id> <destination id> <hex bytes, e.g. 0102A0>\r\n");
        return CommandResult::Failed;
    }
    if (!isoTpConnection(shell, argv, channel, config)) {
        return CommandResult::Failed;
    }
    static uint8_t message[4095];
    size_t length = 0;
    for (const char* p = argv[5]; *p != '\0'; p += 2) {
        unsigned long byte = 0;
        char pair[5] = {'0', 'x', p[0], p[1], '\0'};
        if (p[1] == '\0' || length == sizeof message || !shell::Shell::parseUnsigned(pair, byte)) {
            shell.print("error: '%s' is not 1 to 4095 bytes in hexadecimal\r\n", argv[5]);
            return CommandResult::Failed;
        }
        message[length++] = static_cast<uint8_t>(byte);
    }
    const can::LinkResult<can::IsoTpSender> created = can::IsoTpSender::create(config);
    if (!created.ok()) {
        shell.print("error: %s\r\n", can::linkErrorName(created.error()));
        return CommandResult::Failed;
    }
    listenHere(channel);
    discardReceived(channel);
    can::IsoTpSender sender = created.value();
    can::IsoTpStep step = sender.start(message, length, dcos::timerAgent.Uptime());
    while (!step.completed && step.aborted == can::LinkError::Ok &&
           (step.rejected == can::LinkError::Ok || step.transmit || !sender.idle())) {
        if (step.transmit) {
            if (!sendConfirmed(channel, step.frame, config.timeoutAsNs)) {
                step = sender.poll(dcos::timerAgent.Uptime() + config.timeoutAsNs); // N_As has run out.
                continue;
            }
            step = sender.onTransmitConfirmed(dcos::timerAgent.Uptime());
            continue;
        }
        can::CanFrame frame;
        if (nextFrame(channel, sender.nextDeadlineNs(), frame)) {
            step = sender.onFrame(frame, dcos::timerAgent.Uptime());
        } else {
            step = sender.poll(dcos::timerAgent.Uptime());
        }
        if (!step.transmit && !step.completed && step.aborted == can::LinkError::Ok) {
            step.rejected = can::LinkError::Ok; // A frame of another connection: not ours to judge.
        }
    }
    if (!step.completed) {
        const can::LinkError why = step.aborted != can::LinkError::Ok ? step.aborted : step.rejected;
        shell.print("error: ISO-TP transfer failed: %s\r\n", can::linkErrorName(why));
        return CommandResult::Failed;
    }
    shell.print("%s  isotp %lu bytes sent\r\n", kNames[channel], static_cast<unsigned long>(length));
    return CommandResult::Ok;
}

CommandResult isoTpReceive(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    can::IsoTpConfig config;
    unsigned long timeoutMs = kDefaultDumpTimeoutMs;
    if (argc < 5 || argc > 6) {
        shell.print("usage: can isotp-recv <channel> <source id> <destination id> [time-out ms]\r\n");
        return CommandResult::Failed;
    }
    if (!isoTpConnection(shell, argv, channel, config) || (argc == 6 && !parseMilliseconds(shell, argv[5], timeoutMs))) {
        return CommandResult::Failed;
    }
    static uint8_t buffer[4095];
    const can::LinkResult<can::IsoTpReceiver> created = can::IsoTpReceiver::create(config, buffer, sizeof buffer);
    if (!created.ok()) {
        shell.print("error: %s\r\n", can::linkErrorName(created.error()));
        return CommandResult::Failed;
    }
    listenHere(channel);
    discardReceived(channel);
    can::IsoTpReceiver receiver = created.value();
    const uint64_t giveUp = dcos::timerAgent.Uptime() + timeoutMs * kMillisecond;
    for (;;) {
        const uint64_t deadline = receiver.idle() ? giveUp : receiver.nextDeadlineNs();
        can::CanFrame frame;
        can::IsoTpStep step;
        if (nextFrame(channel, deadline, frame)) {
            step = receiver.onFrame(frame, dcos::timerAgent.Uptime());
        } else if (receiver.idle()) {
            shell.print("error: no ISO-TP message began within %lu ms\r\n", timeoutMs);
            return CommandResult::Failed;
        } else {
            step = receiver.poll(dcos::timerAgent.Uptime());
        }
        if (step.transmit && !sendConfirmed(channel, step.frame, config.timeoutAsNs)) {
            shell.print("error: the flow control could not be sent\r\n");
            return CommandResult::Failed;
        }
        if (step.completed) {
            shell.print("%s  isotp %u bytes:", kNames[channel], static_cast<unsigned>(step.length));
            for (uint16_t i = 0; i < step.length; ++i) {
                shell.print(" %02X", receiver.buffer()[i]);
            }
            shell.print("\r\n");
            return CommandResult::Ok;
        }
        if (step.aborted != can::LinkError::Ok) {
            shell.print("error: ISO-TP transfer failed: %s\r\n", can::linkErrorName(step.aborted));
            return CommandResult::Failed;
        }
    }
}

// Queues frames without waiting for them to be sent: what a task does when
// it has several frames for the bus at once.
CommandResult queue(shell::Shell& shell, int argc, char** argv)
{
    constexpr int kMostFrames = static_cast<int>(Sja1000Controller::kTransmitQueueLength);
    unsigned channel;
    if (argc < 4 || argc - 3 > kMostFrames) {
        shell.print("usage: can queue <channel> <id>#<data> ... (1 to %d frames)\r\n", kMostFrames);
        return CommandResult::Failed;
    }
    if (!parseChannel(shell, argv[2], channel) || !requireUp(shell, channel)) {
        return CommandResult::Failed;
    }
    can::CanFrame frames[Sja1000Controller::kTransmitQueueLength];
    const int count = argc - 3;
    for (int i = 0; i < count; ++i) {
        const can::LinkResult<can::CanFrame> frame = can::FrameText::parse(argv[3 + i]);
        if (!frame.ok()) {
            shell.print("error: '%s' is not a frame (%s); nothing was queued\r\n", argv[3 + i],
                        can::linkErrorName(frame.error()));
            return CommandResult::Failed;
        }
        frames[i] = frame.value();
    }
    const dcos::Result<size_t> written = systemAgent.Write(consoleChannels[channel].id(), 0, frames,
                                                           static_cast<size_t>(count) * sizeof(can::CanFrame));
    if (!written.ok()) {
        shell.print("error: %s did not take the frames: %s\r\n", kNames[channel], dcos::statusName(written.status()));
        return CommandResult::Failed;
    }
    const size_t taken = written.value() / sizeof(can::CanFrame);
    shell.print("%s  %lu of %d frames queued\r\n", kNames[channel], static_cast<unsigned long>(taken), count);
    return taken == static_cast<size_t>(count) ? CommandResult::Ok : CommandResult::Failed;
}

// Prints the state changes the driver reported to its owner, the console
// task, oldest first; with a count, waits for that many (a time-out bounds it).
CommandResult events(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    unsigned long wanted = 0;
    unsigned long timeoutMs = kDefaultDumpTimeoutMs;
    if (!channelCountTimeout(shell, argc, argv, "can events", 0, channel, wanted, timeoutMs)) {
        return CommandResult::Failed;
    }
    listenHere(channel);
    const uint64_t deadline = dcos::timerAgent.Uptime() + timeoutMs * kMillisecond;
    unsigned long shown = 0;
    for (;;) {
        static StateChanges log;
        (void)systemAgent.Control(consoleChannels[channel].id(), Sja1000Controller::kReadStateChanges, &log,
                                  sizeof log); // Cannot fail: the channel is up and the argument is right.
        if (log.lost != 0) {
            shell.print("%s  %lu earlier state changes lost\r\n", kNames[channel], static_cast<unsigned long>(log.lost));
        }
        for (uint32_t i = 0; i < log.count; ++i, ++shown) {
            const StateChange& change = log.changes[i];
            if (change.holdChanged != 0) {
                shell.print("%s  %s  %s  rx errors %u  tx errors %u\r\n", kNames[channel],
                            change.noAcknowledge != 0 ? "no acknowledge: held" : "acknowledge hold released",
                            stateName(change.to), change.receiveErrors, change.transmitErrors);
                continue;
            }
            shell.print("%s  %s  was %s  rx errors %u  tx errors %u\r\n", kNames[channel], stateName(change.to),
                        stateName(change.from), change.receiveErrors, change.transmitErrors);
        }
        const uint64_t now = dcos::timerAgent.Uptime();
        if (shown >= wanted || now >= deadline) {
            break;
        }
        // A change reported between the read and this wait has posted the
        // event already, so the wait returns at once for it.
        (void)taskAgent.ReceiveEvent(kStateEvent, dcos::EventWait::Any, deadline - now);
    }
    if (shown < wanted) {
        shell.print("%lu of %lu state changes within %lu ms\r\n", shown, wanted, timeoutMs);
        return CommandResult::Failed;
    }
    return CommandResult::Ok;
}

CommandResult policy(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    const bool automatic = argc == 4 && runtime::textEquals(argv[3], "auto");
    const bool manual = argc == 4 && runtime::textEquals(argv[3], "manual");
    if (!automatic && !manual) {
        shell.print("usage: can policy <channel> auto|manual  (after bus-off: recover at once, or on 'can restart')\r\n");
        return CommandResult::Failed;
    }
    if (!parseChannel(shell, argv[2], channel) || !requireUp(shell, channel)) {
        return CommandResult::Failed;
    }
    uint32_t value = static_cast<uint32_t>(automatic ? BusOffPolicy::RestartAtOnce : BusOffPolicy::WaitForRestart);
    const Status set = systemAgent.Control(consoleChannels[channel].id(), Sja1000Controller::kSetBusOffPolicy, &value,
                                           sizeof value);
    if (set != Status::Ok) {
        shell.print("error: %s\r\n", dcos::statusName(set));
        return CommandResult::Failed;
    }
    shell.print("%s  after bus-off: %s\r\n", kNames[channel],
                automatic ? "recover at once" : "wait for 'can restart'");
    return CommandResult::Ok;
}

CommandResult restart(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    if (!soleUpChannel(shell, argc, argv, "can restart <channel>", channel)) {
        return CommandResult::Failed;
    }
    const Status restarted = systemAgent.Control(consoleChannels[channel].id(), Sja1000Controller::kRestart, nullptr, 0);
    if (restarted != Status::Ok) {
        shell.print("error: cannot restart %s: %s\r\n", kNames[channel], dcos::statusName(restarted));
        return CommandResult::Failed;
    }
    shell.print("%s  restarted\r\n", kNames[channel]);
    return CommandResult::Ok;
}

// Parses a hexadecimal number up to @p limit; prints why not.
bool parseHex(shell::Shell& shell, const char* text, uint32_t limit, uint32_t& value)
{
    // parseUnsigned reads hexadecimal after "0x"; an identifier is written without it, as cansend takes it.
    unsigned long parsed = 0;
    char prefixed[2 + 8 + 1] = {'0', 'x'};
    const size_t length = runtime::textLength(text);
    for (size_t i = 0; i < length && i < 8; ++i) {
        prefixed[2 + i] = text[i];
    }
    prefixed[2 + (length < 8 ? length : 8)] = '\0';
    if (length == 0 || length > 8 || !shell::Shell::parseUnsigned(prefixed, parsed) || parsed > limit) {
        shell.print("error: '%s' is not a hexadecimal number up to %lX\r\n", text, static_cast<unsigned long>(limit));
        return false;
    }
    value = static_cast<uint32_t>(parsed);
    return true;
}

CommandResult filter(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    const bool all = argc == 4 && runtime::textEquals(argv[3], "all");
    const bool extendedOnly = argc == 6 && runtime::textEquals(argv[3], "ext");
    const bool standardOnly = argc == 6 && runtime::textEquals(argv[3], "std");
    if (!all && !extendedOnly && !standardOnly) {
        shell.print("usage: can filter <channel> all | ext <id> <mask> | std <id> <mask>  (hexadecimal; a mask bit "
                    "set must match)\r\n");
        return CommandResult::Failed;
    }
    if (!parseChannel(shell, argv[2], channel) || !requireUp(shell, channel)) {
        return CommandResult::Failed;
    }
    AcceptanceFilter wanted = AcceptanceFilter::all();
    if (!all) {
        const uint32_t limit = extendedOnly ? can::CanFrame::kMaxExtendedId : can::CanFrame::kMaxStandardId;
        uint32_t id = 0;
        uint32_t mask = 0;
        if (!parseHex(shell, argv[4], limit, id) || !parseHex(shell, argv[5], limit, mask)) {
            return CommandResult::Failed;
        }
        wanted = extendedOnly ? AcceptanceFilter::extended(id, mask) : AcceptanceFilter::standard(id, mask);
    }
    const Status set = systemAgent.Control(consoleChannels[channel].id(), Sja1000Controller::kSetFilter, &wanted,
                                           sizeof wanted);
    if (set != Status::Ok) {
        shell.print("error: cannot set the filter: %s\r\n", dcos::statusName(set));
        return CommandResult::Failed;
    }
    shell.print("%s  filter %s\r\n", kNames[channel], all ? "takes every frame" : extendedOnly ? "extended only"
                                                                                                 : "standard only");
    return CommandResult::Ok;
}

void printState(shell::Shell& shell, unsigned channel)
{
    if (!consoleChannels[channel].installed()) {
        shell.print("%s  down\r\n", kNames[channel]);
        return;
    }
    const BusState state = stateOf(channel);
    shell.print("%s  %s  %lu bit/s  rx errors %u  tx errors %u  queued %u%s\r\n", kNames[channel],
                stateName(state.errorState), static_cast<unsigned long>(state.bitRate), state.receiveErrors,
                state.transmitErrors, state.queued, state.noAcknowledge ? "  no acknowledge: held" : "");
}

CommandResult state(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    if (argc == 2) {
        for (unsigned i = 0; i < kChannels; ++i) {
            printState(shell, i);
        }
        return CommandResult::Ok;
    }
    if (argc != 3 || !parseChannel(shell, argv[2], channel)) {
        if (argc != 3) {
            shell.print("usage: can state [channel]\r\n");
        }
        return CommandResult::Failed;
    }
    printState(shell, channel);
    return CommandResult::Ok;
}

CommandResult statistics(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    if (!soleUpChannel(shell, argc, argv, "can stats <channel>", channel, true)) {
        return CommandResult::Failed;
    }
    ChannelStatistics s{};
    (void)systemAgent.Control(consoleChannels[channel].id(), Sja1000Controller::kGetStatistics, &s, sizeof s);
    shell.print("%s sent=%lu received=%lu rx_queue_overruns=%lu chip_overruns=%lu malformed=%lu bad_ids=%lu "
                "bus_errors=%lu ack_errors=%lu arbitration_lost=%lu warnings=%lu passives=%lu bus_offs=%lu "
                "restarts=%lu recoveries=%lu actives=%lu aborts=%lu lone_node_holds=%lu state_changes_lost=%lu "
                "interrupts=%lu interrupt_loop_limits=%lu receive_interrupt_instructions=%lu\r\n",
                kNames[channel], static_cast<unsigned long>(s.framesSent),
                static_cast<unsigned long>(s.framesReceived), static_cast<unsigned long>(s.receiveQueueOverruns),
                static_cast<unsigned long>(s.chipOverruns), static_cast<unsigned long>(s.malformedFrames),
                static_cast<unsigned long>(s.badIdentifiers), static_cast<unsigned long>(s.busErrors),
                static_cast<unsigned long>(s.acknowledgeErrors), static_cast<unsigned long>(s.arbitrationLost),
                static_cast<unsigned long>(s.errorWarnings), static_cast<unsigned long>(s.errorPassives),
                static_cast<unsigned long>(s.busOffs), static_cast<unsigned long>(s.restarts),
                static_cast<unsigned long>(s.recoveries), static_cast<unsigned long>(s.errorActives),
                static_cast<unsigned long>(s.aborts), static_cast<unsigned long>(s.loneNodeHolds),
                static_cast<unsigned long>(s.stateChangesLost), static_cast<unsigned long>(s.interrupts),
                static_cast<unsigned long>(s.interruptLoopLimits),
                static_cast<unsigned long>(s.receiveInterruptInstructions));
    if (networkLinks[channel].started()) {
        // What the network link did with the channel's frames (can attach).
        const CanLinkStatistics l = networkLinks[channel].statistics();
        shell.print("%s link interface=%u sent=%lu received=%lu foreign=%lu other_nodes=%lu queue_full=%lu "
                    "stale=%lu echoes=%lu\r\n",
                    kNames[channel], attachedInterface[channel], static_cast<unsigned long>(l.sent),
                    static_cast<unsigned long>(l.received), static_cast<unsigned long>(l.foreign),
                    static_cast<unsigned long>(l.otherNodes), static_cast<unsigned long>(l.queueFull),
                    static_cast<unsigned long>(l.stale), static_cast<unsigned long>(l.echoes));
    }
    return CommandResult::Ok;
}

// The network interface of kind CAN on controller @p channel, if any.
bool findInterfaceOfChannel(unsigned channel, uint8_t& interface, dcos::NetworkInterface& entry)
{
    for (unsigned i = 0; i < dcos::internal::kNetworkInterfaces; ++i) {
        const dcos::Result<dcos::NetworkInterface> found = dcos::NetworkInterfacesManager::GetInterface(
            static_cast<uint8_t>(i));
        if (found.ok() && found.value().kind == dcos::InterfaceKind::Can && found.value().channel == channel) {
            interface = static_cast<uint8_t>(i);
            entry = found.value();
            return true;
        }
    }
    return false;
}

// Gives network interface @p interface (@p entry) the channel's link, and
// prints what it carries; says why not on @p out.
bool attachChannel(runtime::CharacterSink& out, unsigned channel, uint8_t interface,
                   const dcos::NetworkInterface& entry)
{
    networkLinks[channel].bind(consoleChannels[channel].id());
    const Status attached = dcos::NetworkInterfacesManager::AttachLink(interface, networkLinks[channel]);
    if (attached != Status::Ok) {
        runtime::format(out, "error: cannot attach %s to interface %u: %s\r\n", kNames[channel], interface,
                        dcos::statusName(attached));
        return false;
    }
    attachedInterface[channel] = interface;
    char address[dcos::NetworkAddress::kTextSize];
    entry.address.format(address);
    runtime::format(out, "%s carries interface %u: %s/%u, CAN node %lu\r\n", kNames[channel], interface, address,
                    entry.prefixLength, static_cast<unsigned long>(entry.physical));
    return true;
}

CommandResult attach(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    if (!soleUpChannel(shell, argc, argv, "can attach <channel>", channel)) {
        return CommandResult::Failed;
    }
    uint8_t interface;
    dcos::NetworkInterface entry;
    if (!findInterfaceOfChannel(channel, interface, entry)) {
        shell.print("error: no network interface is on %s; add one with 'net interface can %u <address>/<length> "
                    "<node number>'\r\n",
                    kNames[channel], channel);
        return CommandResult::Failed;
    }
    return attachChannel(shell.output(), channel, interface, entry) ? CommandResult::Ok : CommandResult::Failed;
}

CommandResult detach(shell::Shell& shell, int argc, char** argv)
{
    unsigned channel;
    if (!soleUpChannel(shell, argc, argv, "can detach <channel>", channel, true)) {
        return CommandResult::Failed;
    }
    if (!networkLinks[channel].started()) {
        shell.print("error: %s carries no network interface\r\n", kNames[channel]);
        return CommandResult::Failed;
    }
    const Status detached = dcos::NetworkInterfacesManager::DetachLink(attachedInterface[channel]);
    if (detached != Status::Ok) {
        shell.print("error: cannot detach %s: %s\r\n", kNames[channel], dcos::statusName(detached));
        return CommandResult::Failed;
    }
    listenHere(channel);
    shell.print("%s detached from interface %u\r\n", kNames[channel], attachedInterface[channel]);
    return CommandResult::Ok;
}

// Brings channel @p channel up at the rate in @p rateText and attaches it
// as a network interface by the boot rule (NetworkBootHooks.hpp); says on
// @p out what it did or why not.
void startAtBoot(runtime::CharacterSink& out, unsigned channel, const char* rateText)
{
    uint32_t rate = 0;
    if (!parseBitRate(out, rateText, rate)) {
        runtime::format(out, "%s: not started\r\n", kNames[channel]);
        return;
    }
    const uint16_t node = dcos::internal::localNode();
    if (node > can::MessageIdentifier::kMaxNodeNumber) {
        runtime::format(out, "error: node %u is no CAN node number (1 to %u); %s: not started\r\n", unsigned(node),
                        unsigned(can::MessageIdentifier::kMaxNodeNumber), kNames[channel]);
        return;
    }
    if (!install(out, channel) || !setBitRate(out, channel, rate)) {
        runtime::format(out, "%s: not started\r\n", kNames[channel]);
        return;
    }
    uint8_t interface = 0;
    dcos::NetworkInterface entry;
    if (!findInterfaceOfChannel(channel, interface, entry)) {
        const dcos::NetworkAddress address = dcos::NetworkAddress::fromOctets(
            130, static_cast<uint8_t>(channel + 1), 0, static_cast<uint8_t>(node));
        const dcos::Result<uint8_t> added = dcos::NetworkInterfacesManager::AddInterface(
            dcos::InterfaceKind::Can, static_cast<uint8_t>(channel), address, 16, node);
        if (!added.ok() || !findInterfaceOfChannel(channel, interface, entry)) {
            runtime::format(out, "error: cannot add a network interface on %s: %s; it stays up, not attached\r\n",
                            kNames[channel], dcos::statusName(added.status()));
            return;
        }
    }
    if (!attachChannel(out, channel, interface, entry)) {
        runtime::format(out, "%s: up, not attached\r\n", kNames[channel]);
    }
}

constexpr shell::Subcommand kSubcommands[] = {
    {"up", up},       {"down", down},   {"send", send},           {"dump", dump},
    {"state", state}, {"stats", statistics}, {"isotp-send", isoTpSend}, {"isotp-recv", isoTpReceive},
    {"queue", queue}, {"events", events}, {"policy", policy}, {"restart", restart}, {"filter", filter},
    {"attach", attach}, {"detach", detach},
};

CommandResult canCommand(shell::Shell& shell, int argc, char** argv)
{
    placeChannels(shell.output());
    return shell::runSubcommand(shell, argc, argv, kSubcommands);
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(canShellCommand, "can", "bring CAN channels up and down, send, dump, show their state",
                            "can up <channel> [bit rate] | down <channel> | send <channel> <id>#<data> [ms] | "
                            "dump <channel> [count] [ms] | state [channel] | stats <channel> | "
                            "isotp-send <channel> <src> <dst> <hex> | isotp-recv <channel> <src> <dst> [ms] | "
                            "queue <channel> <id>#<data>... | events <channel> [count] [ms] | "
                            "policy <channel> auto|manual | restart <channel> | filter <channel> all|ext|std [id mask] | "
                            "attach <channel> | detach <channel>",
                            "  channels: can0 (0x280, irq 10) and can1 (0x2a0, irq 11) of the ISA SJA1000 card;\r\n"
                            "  on a node with a PCI bus the Kvaser PCIcan chips first ('can up' says where)\r\n"
                            "  frames: <id>#<data> as can-utils' cansend writes them: 3 hex digits for a standard\r\n"
                            "  identifier, 8 for an extended one; <id>#R[n] is a remote frame\r\n"
                            "  dump prints frames as candump does; send waits for the frame to be acknowledged\r\n"
                            "  isotp-send and isotp-recv move one ISO 15765-2 message, as can-utils' isotpsend\r\n"
                            "  and isotprecv do: src is the identifier this end sends on, dst the one it receives on\r\n"
                            "  queue puts frames in the transmit queue without waiting; events shows the error-state\r\n"
                            "  changes the driver reported to the console (and waits for count of them)\r\n"
                            "  policy: after bus-off recover at once (auto, the default) or on 'can restart' (manual)\r\n"
                            "  attach makes the channel carry the network interface on it ('net interface can'):\r\n"
                            "  remote transactions then go over it, and its frames belong to the network",
                            canCommand);

} // namespace sja1000

namespace dcos::internal {

void networkBootStart()
{
    sja1000::placeChannels(bsp::console());
    char rate[16];
    for (unsigned channel = 0; channel < sja1000::kChannels; ++channel) {
        if (boot::findCommandLineOption(dcos::bootInfo().commandLine, sja1000::kNames[channel], rate, sizeof rate)) {
            sja1000::startAtBoot(bsp::console(), channel, rate);
        }
    }
}

void switchCanBitRate(uint32_t rate)
{
    for (unsigned channel = 0; channel < sja1000::kChannels; ++channel) {
        // A channel already at the rate is left alone: resetting its chip
        // would only drop the frames under way.
        if (!sja1000::consoleChannels[channel].installed() || sja1000::stateOf(channel).bitRate == rate) {
            continue;
        }
        runtime::format(bsp::console(), "%s: switching to %lu bit/s, as a configuration host asked\r\n",
                        sja1000::kNames[channel], static_cast<unsigned long>(rate));
        (void)sja1000::setBitRate(bsp::console(), channel, rate);
    }
}

} // namespace dcos::internal
