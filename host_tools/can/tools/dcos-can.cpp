// dcos-can: see, send and measure CAN traffic from a Linux host, in the
// conventions of can-utils (candump's columns, cansend's frames, -i to name
// the interface), with the DCOS identifier decoded (docs/guide/host-can.md).
//
//     dcos-can -i can0 dump [-n N] [-t MS] [--decode] [--json]
//     dcos-can -i slcan:/dev/ttyACM0@500000 send 1ABCDEF0#0102 [123#R ...]
//     dcos-can -i can0 stats [-s SECONDS] [--bitrate B] [--json]
//     dcos-can -i can0 isotp-send -s 7E0 -d 7E8 "01 02 03 ..."   (as can-utils' isotpsend)
//     dcos-can -i can0 isotp-recv -s 7E8 -d 7E0 [-t MS]          (as isotprecv)
//     ... isotp-send/isotp-recv --kernel: through the kernel's ISO-TP socket
//     dcos-can -i gsusb:<serial>@500000 dump      a gs_usb adapter (candleLight) through libusb
//     dcos-can list [--json]                       the SocketCAN interfaces and gs_usb adapters present
//
// Exit status: 0 done (list: always, adapters or none); 1 dump ended before
// -n frames, or send was refused; 2 bad arguments; 3 the interface kind is
// not available here (no SocketCAN in this kernel, no such device, no such
// gs_usb adapter); 4 the interface failed (open, I/O, the other end went
// away, the adapter was unplugged).
#include <hostcan/IsoTpEndpoint.hpp>
#include <hostcan/KernelIsoTp.hpp>
#include <hostcan/LibUsbGsDevice.hpp>
#include <hostcan/Transport.hpp>

#include <can/FrameText.hpp>
#include <can/FrameTiming.hpp>
#include <can/MessageIdentifier.hpp>

#include <dcos/Version.hpp>
#include <dcos/internal/PublicationMessage.hpp>
#include <dcos/internal/RemoteMessage.hpp>
#include <dcos/internal/TimeSyncMessage.hpp>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace {

using hostcan::Received;
using hostcan::TransportError;
using Clock = std::chrono::steady_clock;

constexpr int kExitOk = 0;
constexpr int kExitIncomplete = 1;
constexpr int kExitUsage = 2;
constexpr int kExitNotAvailable = 3;
constexpr int kExitFailed = 4;

int exitCodeOf(const TransportError& error)
{
    switch (error.kind) {
    case TransportError::Kind::None: return kExitOk;
    case TransportError::Kind::BadArgument: return kExitUsage;
    case TransportError::Kind::NotAvailable: return kExitNotAvailable;
    case TransportError::Kind::Refused: return kExitIncomplete;
    default: return kExitFailed;
    }
}

int fail(const TransportError& error)
{
    fmt::print(stderr, "dcos-can: {}\n", error.message);
    return exitCodeOf(error);
}

std::string hex(const can::CanFrame& frame)
{
    std::string text;
    for (uint8_t i = 0; !frame.isRemote() && i < frame.length(); ++i) {
        text += fmt::format("{:02X}", frame.byte(i));
    }
    return text;
}

// What a DCOS frame's data says, for the frame types that carry a system
// message: a remote transaction (docs/protocols/remote-transactions.md) or
// a publication (docs/protocols/publications.md); the decoder's refusal for
// a frame no node should send.
struct DataDecoding {
    const char* key = nullptr; // "remote" or "publication"; null for other frames.
    std::string text;
    nlohmann::json json;
};

// A frame of a DCOS type whose data its decoder refused, and why.
DataDecoding malformed(DataDecoding out, const char* reason)
{
    out.text = fmt::format("malformed: {}", reason);
    out.json = {{"malformed", reason}};
    return out;
}

// What a frame's decoding needs of the frames before it: each sender's
// publications, put back together as a receiving node does, so that the
// third part of one shows the whole page; and the service of each sender's
// request of several frames, which its continuations do not name (a port
// send's and an alarm's are laid out alike).
class FrameHistory {
public:
    /// Notes the service of a request's part 0 from @p source.
    void started(uint8_t source, uint8_t transaction, dcos::internal::RemoteService service)
    {
        continued_[(uint32_t{source} << 4) | (transaction & 0x0F)] = service;
    }

    /// The service whose continuation @p source sent on @p slot: a port
    /// send when its part 0 was not seen.
    dcos::internal::RemoteService continuing(uint8_t source, uint8_t slot) const
    {
        const auto found = continued_.find((uint32_t{source} << 4) | slot);
        return found == continued_.end() ? dcos::internal::RemoteService::PortSend : found->second;
    }

    DataDecoding decode(const can::MessageIdentifier& id, const can::CanFrame& frame)
    {
        return decodePart(uint32_t{id.source()}, frame);
    }

    /// A relayed publication's frame (docs/protocols/publications.md,
    /// "Across a gateway"): a relay header, or the frame it names the node of.
    DataDecoding decodeRelayed(const can::MessageIdentifier& id, const can::CanFrame& frame)
    {
        using namespace dcos::internal;
        uint16_t node = 0;
        uint8_t crossed = 0;
        if (decodeRelayHeader(frame.data(), frame.length(), node, &crossed)) {
            relayed_[id.source()] = node;
            DataDecoding out;
            out.key = "publication";
            out.text = crossed == 0 ? fmt::format("relay header: node {}", node)
                                    : fmt::format("relay header: node {}, {} gateways before", node, crossed);
            out.json = {{"relay_node", node}};
            if (crossed != 0) {
                out.json["gateways_before"] = crossed;
            }
            return out;
        }
        const auto found = relayed_.find(id.source());
        if (found == relayed_.end()) {
            DataDecoding out;
            out.key = "publication";
            return malformed(out, "relayed frame without its header");
        }
        node = found->second;
        relayed_.erase(found);
        // Put together apart from the gateway's own publications: keyed by the node.
        DataDecoding out = decodePart(0x10000u | node, frame);
        if (!out.json.contains("malformed")) {
            out.text = fmt::format("node {} ", node) + out.text;
            out.json["node"] = node;
        }
        return out;
    }

private:
    DataDecoding decodePart(uint32_t sender, const can::CanFrame& frame)
    {
        using namespace dcos::internal;
        DataDecoding out;
        out.key = "publication";
        PublicationPart part;
        const PublicationMessageError error = decodePublicationPart(frame.data(), frame.length(), part);
        if (error != PublicationMessageError::None) {
            return malformed(out, publicationMessageErrorName(error));
        }
        out.json = {{"index", part.index}};
        if (part.kind == PublicationPartKind::Withdrawal) {
            out.text = fmt::format("publisher 0x{:03x} withdrawn", part.index);
            out.json["withdrawn"] = true;
            return out;
        }
        const int number = static_cast<int>(part.kind);
        out.text = fmt::format("publisher 0x{:03x} part {}/3", part.index, number + 1);
        out.json["part"] = number;
        if (part.kind == PublicationPartKind::First) {
            out.text += fmt::format(" seq {}", part.sequence);
            out.json["sequence"] = part.sequence;
        }
        PublicationAssembler& assembler = pages_[(uint64_t{sender} << 12) | part.index];
        const PublicationAssembler::Outcome outcome = assembler.take(part);
        if (outcome == PublicationAssembler::Outcome::Complete) {
            std::string page;
            for (uint8_t byte : assembler.page().bytes) {
                page += fmt::format("{:02X}", byte);
            }
            out.text += fmt::format(" page {} (seq {})", page, assembler.sequence());
            out.json["page"] = page;
            out.json["page_sequence"] = assembler.sequence();
        } else if (outcome == PublicationAssembler::Outcome::Dropped) {
            out.text += " out of turn";
            out.json["out_of_turn"] = true;
        }
        return out;
    }

    std::map<uint64_t, dcos::internal::PublicationAssembler> pages_;
    std::map<uint32_t, dcos::internal::RemoteService> continued_;
    std::map<uint8_t, uint16_t> relayed_; // The node a gateway's last relay header named.
};

// The name of an object type, as a name query carries it.
const char* objectTypeName(uint8_t type)
{
    switch (static_cast<dcos::ObjectType>(type)) {
    case dcos::ObjectType::Task: return "task";
    case dcos::ObjectType::Timer: return "timer";
    case dcos::ObjectType::Device: return "device";
    case dcos::ObjectType::BufferPool: return "pool";
    case dcos::ObjectType::Heap: return "heap";
    case dcos::ObjectType::MessagePort: return "port";
    case dcos::ObjectType::DsmPublisher: return "publisher";
    case dcos::ObjectType::Semaphore: return "semaphore";
    default: return "?";
    }
}

DataDecoding decodedData(const can::MessageIdentifier& id, const can::CanFrame& frame, FrameHistory& pages)
{
    using namespace dcos::internal;
    if (id.type() == can::MessageType::DsmPublication) {
        return pages.decode(id, frame);
    }
    if (id.type() == can::MessageType::RelayedPublication) {
        return pages.decodeRelayed(id, frame);
    }
    DataDecoding out;
    if (id.type() == can::MessageType::TimeSync) {
        out.key = "time";
        TimeSyncFrame time;
        const TimeSyncError error = decodeTimeSync(frame.data(), frame.length(), time);
        if (error != TimeSyncError::None) {
            return malformed(out, timeSyncErrorName(error));
        }
        switch (time.kind) {
        case TimeSyncKind::Sync:
            out.text = fmt::format("sync seq {} second {} rank {} every {} ms", time.sequence, time.seconds, time.rank,
                                   time.intervalMs);
            out.json = {{"kind", "sync"},
                        {"sequence", time.sequence},
                        {"seconds", time.seconds},
                        {"rank", time.rank},
                        {"interval_ms", time.intervalMs}};
            break;
        case TimeSyncKind::FollowUp:
            // The low 56 bits of the master's nanoseconds: the Sync before it says which 2.28 years.
            out.text = fmt::format("follow-up seq {} ns-low56 {}", time.sequence, time.nanosecondsLow);
            out.json = {{"kind", "follow-up"}, {"sequence", time.sequence}, {"nanoseconds_low56", time.nanosecondsLow}};
            break;
        case TimeSyncKind::Probe:
            out.text = fmt::format("probe seq {}", time.sequence);
            out.json = {{"kind", "probe"}, {"sequence", time.sequence}};
            break;
        }
        return out;
    }
    if (id.type() == can::MessageType::NodeStarted) {
        out.key = "node_started";
        NodeStarted announcement;
        const RemoteMessageError error = decodeNodeStarted(frame.data(), frame.length(), announcement);
        if (error != RemoteMessageError::None) {
            return malformed(out, remoteMessageErrorName(error));
        }
        out.text = fmt::format("node {} started", announcement.node);
        out.json = {{"node", announcement.node}};
        return out;
    }
    if (id.type() == can::MessageType::NameQuery) {
        out.key = "name_query";
        NameQueryPart part;
        const NameQueryError error = decodeNameQueryPart(frame.data(), frame.length(), part);
        if (error != NameQueryError::None) {
            return malformed(out, nameQueryErrorName(error));
        }
        // The name bytes this part carries, up to the first NUL.
        std::string bytes;
        for (uint8_t byte : part.bytes) {
            if (byte == 0) {
                break;
            }
            bytes += static_cast<char>(byte);
        }
        out.text = fmt::format("{} part {}/3 txn 0x{:02x} \"{}\"", objectTypeName(part.type), part.part + 1,
                               part.transaction, bytes);
        out.json = {{"type", objectTypeName(part.type)},
                    {"part", part.part},
                    {"transaction", part.transaction},
                    {"name_bytes", bytes}};
        return out;
    }
    // A routed request's frames are a request's, behind a route header
    // (docs/protocols/remote-transactions.md, "Gateways").
    const bool isRequest = id.type() == can::MessageType::RemoteRequest || id.type() == can::MessageType::RoutedRequest;
    if (id.type() == can::MessageType::RoutedRequest && isRouteHeader(frame.data(), frame.length())) {
        out.key = "remote";
        RouteHeader header;
        const RemoteMessageError error = decodeRouteHeader(frame.data(), frame.length(), header);
        if (error != RemoteMessageError::None) {
            return malformed(out, remoteMessageErrorName(error));
        }
        out.text = fmt::format("route to node {} hops {} txn 0x{:02x}", header.destination, header.hopsLeft,
                               header.transaction);
        out.json = {{"route_to", header.destination}, {"hops_left", header.hopsLeft}, {"transaction", header.transaction}};
        return out;
    }
    if (isRequest && isContinuation(frame.data(), frame.length())) {
        // Parts 1 and 2 of a port send, part 3 of a held acquire
        // (docs/protocols/remote-transactions.md, "Port sends", "Binary semaphores").
        out.key = "remote";
        Continuation part;
        const RemoteMessageError error = decodeContinuation(frame.data(), frame.length(), part);
        if (error != RemoteMessageError::None) {
            return malformed(out, remoteMessageErrorName(error));
        }
        if (part.part == 3) {
            const uint32_t holder = (uint32_t{part.bytes[0]} << 24) | (uint32_t{part.bytes[1]} << 16) |
                                    (uint32_t{part.bytes[2]} << 8) | part.bytes[3];
            out.text = fmt::format("held-acquire holder 0x{:08x} slot {}", holder, part.slot);
            out.json = {{"service", "held-acquire"}, {"part", part.part}, {"slot", part.slot}, {"holder", holder}};
            return out;
        }
        const char* const service = remoteServiceName(pages.continuing(id.source(), part.slot));
        out.text = fmt::format("{} part {}/3 slot {}", service, part.part + 1, part.slot);
        out.json = {{"service", service}, {"part", part.part}, {"slot", part.slot}};
        return out;
    }
    if (isRequest) {
        out.key = "remote";
        RemoteRequest request;
        const RemoteMessageError error = decodeRequest(frame.data(), frame.length(), request);
        if (error != RemoteMessageError::None) {
            return malformed(out, remoteMessageErrorName(error));
        }
        pages.started(id.source(), request.transaction, request.service);
        out.text = fmt::format("{} txn 0x{:02x} object 0x{:04x} argument {}", remoteServiceName(request.service),
                               request.transaction, request.object, request.argument);
        out.json = {{"service", remoteServiceName(request.service)},
                    {"transaction", request.transaction},
                    {"object", request.object},
                    {"argument", request.argument}};
    } else if (id.type() == can::MessageType::RemoteReply) {
        out.key = "remote";
        RemoteReply reply;
        const RemoteMessageError error = decodeReply(frame.data(), frame.length(), reply);
        if (error != RemoteMessageError::None) {
            return malformed(out, remoteMessageErrorName(error));
        }
        out.text = fmt::format("{} txn 0x{:02x} {}{} value {}", remoteServiceName(reply.service), reply.transaction,
                               dcos::statusName(reply.status), reply.pending ? " pending" : "", reply.value);
        out.json = {{"service", remoteServiceName(reply.service)},
                    {"transaction", reply.transaction},
                    {"status", dcos::statusName(reply.status)},
                    {"pending", reply.pending},
                    {"value", reply.value}};
    }
    return out;
}

// What the DCOS identifier layout says of a frame, or an empty string for a
// frame that is not a DCOS frame (standard, remote, unassigned type); for a
// remote transaction or a publication, what its data says too.
std::string decoded(const can::CanFrame& frame, FrameHistory& pages)
{
    const can::LinkResult<can::MessageIdentifier> id = can::MessageIdentifier::fromFrame(frame);
    if (!id.ok()) {
        return {};
    }
    const can::MessageIdentifier& m = id.value();
    std::string text = fmt::format("prio {} {} {}->{}", m.priority(), can::messageTypeName(m.type()), m.source(),
                                   m.isBroadcast() ? std::string("all") : std::to_string(m.destination()));
    const DataDecoding data = decodedData(m, frame, pages);
    if (data.key != nullptr) {
        text += ": " + data.text;
    }
    return text;
}

nlohmann::json frameJson(const Received& r, const std::string& interface, bool decode, FrameHistory& pages)
{
    nlohmann::json j{{"interface", interface},
                     {"timestamp_ns", r.timestamp.count()},
                     {"emulated_time", r.emulatedTime}};
    if (r.kind == Received::Kind::Event) {
        j["event"] = hostcan::busEventName(r.event);
        j["detail"] = r.detail;
        return j;
    }
    j["id"] = r.frame.id();
    j["extended"] = r.frame.isExtended();
    j["remote"] = r.frame.isRemote();
    j["dlc"] = r.frame.length();
    j["data"] = hex(r.frame);
    if (decode) {
        const can::LinkResult<can::MessageIdentifier> id = can::MessageIdentifier::fromFrame(r.frame);
        if (id.ok()) {
            j["dcos"] = {{"priority", id.value().priority()},
                         {"type", can::messageTypeName(id.value().type())},
                         {"source", id.value().source()},
                         {"destination", id.value().destination()}};
            const DataDecoding data = decodedData(id.value(), r.frame, pages);
            if (data.key != nullptr) {
                j["dcos"][data.key] = data.json;
            }
        }
    }
    return j;
}

struct DumpOptions {
    long count = 0;          // 0: until the time-out or for ever.
    long timeoutMs = 0;      // 0: no time-out.
    bool decode = false;
    bool errors = true;
};

int dump(hostcan::Transport& transport, const DumpOptions& options, bool json)
{
    const auto deadline = Clock::now() + std::chrono::milliseconds(options.timeoutMs);
    long shown = 0;
    FrameHistory pages;
    while (options.count == 0 || shown < options.count) {
        auto wait = std::chrono::milliseconds(200);
        if (options.timeoutMs > 0) {
            const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
            if (left.count() <= 0) {
                break;
            }
            wait = std::min(wait, left);
        }
        TransportError error;
        const Received r = transport.receive(wait, error);
        if (error) {
            return fail(error);
        }
        if (r.kind == Received::Kind::Timeout || (r.kind == Received::Kind::Event && !options.errors)) {
            continue;
        }
        const double seconds = std::chrono::duration<double>(r.timestamp).count();
        if (json) {
            fmt::print("{}\n", frameJson(r, transport.name(), options.decode, pages).dump());
        } else if (r.kind == Received::Kind::Event) {
            fmt::print(" ({:.6f})  {}  ERROR  {}  {}\n", seconds, transport.name(), hostcan::busEventName(r.event),
                       r.detail);
        } else {
            char text[can::FrameText::kMaxFormattedLength + 1];
            (void)can::FrameText::format(r.frame, text, sizeof text);
            const std::string annotation = options.decode ? decoded(r.frame, pages) : std::string();
            fmt::print(" ({:.6f})  {}  {}{}{}\n", seconds, transport.name(), text, annotation.empty() ? "" : "  ; ",
                       annotation);
        }
        std::fflush(stdout);
        if (r.kind == Received::Kind::Frame) {
            ++shown;
        }
    }
    if (options.count > 0 && shown < options.count) {
        fmt::print(stderr, "dcos-can: {} of {} frames within {} ms\n", shown, options.count, options.timeoutMs);
        return kExitIncomplete;
    }
    return kExitOk;
}

// Parses every frame before anything is opened or sent: a typo in the
// third frame must not leave the first two on the bus.
bool parseFrames(const std::vector<std::string>& texts, std::vector<can::CanFrame>& parsed)
{
    for (const std::string& text : texts) {
        const can::LinkResult<can::CanFrame> frame = can::FrameText::parse(text.c_str());
        if (!frame.ok()) {
            fmt::print(stderr,
                       "dcos-can: '{}' is not a frame ({}): write <id>#<data> as cansend does, 3 hex digits for a "
                       "standard identifier, 8 for an extended one, e.g. 123#DEADBEEF\n",
                       text, can::linkErrorName(frame.error()));
            return false;
        }
        parsed.push_back(frame.value());
    }
    return true;
}

int send(hostcan::Transport& transport, const std::vector<can::CanFrame>& parsed, long timeoutMs, bool json)
{
    nlohmann::json sent = nlohmann::json::array();
    for (const can::CanFrame& frame : parsed) {
        if (TransportError error = transport.send(frame, std::chrono::milliseconds(timeoutMs))) {
            return fail(error);
        }
        sent.push_back({{"id", frame.id()}, {"extended", frame.isExtended()}, {"data", hex(frame)}});
    }
    // Sent means on the bus: a USB adapter confirms each frame, and ending
    // before it did could take the last ones off the bus.
    if (TransportError error = transport.drain(std::chrono::milliseconds(timeoutMs))) {
        return fail(error);
    }
    if (json) {
        fmt::print("{}\n", nlohmann::json{{"interface", transport.name()}, {"sent", sent}}.dump());
    }
    return kExitOk;
}

int stats(hostcan::Transport& transport, double seconds, uint32_t bitRate, bool json)
{
    const uint32_t rate = bitRate != 0 ? bitRate : transport.bitRate().value_or(0);
    const auto start = Clock::now();
    const auto end = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    uint64_t frames = 0;
    uint64_t extended = 0;
    uint64_t busyNs = 0;
    std::map<std::string, uint64_t> events;
    std::string lastState = "error-active";
    while (Clock::now() < end) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - Clock::now());
        TransportError error;
        const Received r = transport.receive(std::max(left, std::chrono::milliseconds(1)), error);
        if (error) {
            return fail(error);
        }
        if (r.kind == Received::Kind::Frame) {
            ++frames;
            extended += r.frame.isExtended() ? 1 : 0;
            busyNs += can::frameNanoseconds(r.frame, rate);
        } else if (r.kind == Received::Kind::Event) {
            ++events[hostcan::busEventName(r.event)];
            switch (r.event) {
            case hostcan::BusEventKind::ErrorWarning:
            case hostcan::BusEventKind::ErrorPassive:
            case hostcan::BusEventKind::BusOff:
            case hostcan::BusEventKind::ErrorActive:
                lastState = hostcan::busEventName(r.event);
                break;
            case hostcan::BusEventKind::Restarted:
                lastState = "error-active";
                break;
            default:
                break;
            }
        }
    }
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    const double load = rate != 0 && elapsed > 0 ? 100.0 * static_cast<double>(busyNs) / (elapsed * 1e9) : -1.0;
    if (json) {
        nlohmann::json j{{"interface", transport.name()}, {"seconds", elapsed},  {"frames", frames},
                         {"extended_frames", extended},   {"frames_per_second", frames / elapsed},
                         {"state", lastState},            {"events", events}};
        j["bit_rate"] = rate != 0 ? nlohmann::json(rate) : nlohmann::json(nullptr);
        j["bus_load_percent"] = load >= 0 ? nlohmann::json(load) : nlohmann::json(nullptr);
        fmt::print("{}\n", j.dump());
        return kExitOk;
    }
    fmt::print("{}: {} frames in {:.1f} s ({:.1f}/s, {} extended), state {}\n", transport.name(), frames, elapsed,
               frames / elapsed, extended, lastState);
    if (load >= 0) {
        fmt::print("bus load {:.1f} % at {} bit/s (worst-case bit stuffing)\n", load, rate);
    } else {
        fmt::print("bus load unknown: give --bitrate\n");
    }
    for (const auto& [name, count] : events) {
        fmt::print("{}: {}\n", name, count);
    }
    return kExitOk;
}

// An ISO-TP identifier as isotpsend takes it: hexadecimal, extended when it
// does not fit 11 bits or is written with 8 digits.
bool parseIsoTpId(const std::string& text, uint32_t& id, bool& extended)
{
    if (text.empty() || text.size() > 8) {
        return false;
    }
    size_t used = 0;
    unsigned long value = 0;
    try {
        value = std::stoul(text, &used, 16);
    } catch (const std::exception&) {
        return false;
    }
    if (used != text.size() || value > can::CanFrame::kMaxExtendedId) {
        return false;
    }
    id = static_cast<uint32_t>(value);
    extended = value > can::CanFrame::kMaxStandardId || text.size() == 8;
    return true;
}

struct IsoTpOptions {
    std::string source;
    std::string destination;
    std::string data;
    long timeoutMs = 10'000;
    bool padding = false;
    bool kernel = false; // through the kernel's ISO-TP sockets rather than our own state machines
};

bool isoTpConfig(const IsoTpOptions& options, can::IsoTpConfig& config)
{
    bool sourceExtended = false;
    bool destinationExtended = false;
    if (!parseIsoTpId(options.source, config.txId, sourceExtended) ||
        !parseIsoTpId(options.destination, config.rxId, destinationExtended)) {
        fmt::print(stderr, "dcos-can: '{}' and '{}' must be CAN identifiers in hexadecimal, e.g. 7E0 or 18DA00F1\n",
                   options.source, options.destination);
        return false;
    }
    config.format = sourceExtended || destinationExtended ? can::IdFormat::Extended : can::IdFormat::Standard;
    config.padding.enabled = options.padding;
    return true;
}

int isoTpResult(const hostcan::IsoTpOutcome& outcome)
{
    if (outcome.transport) {
        return fail(outcome.transport);
    }
    if (outcome.error != can::LinkError::Ok) {
        fmt::print(stderr, "dcos-can: ISO-TP transfer failed: {}\n", can::linkErrorName(outcome.error));
        return kExitIncomplete;
    }
    return kExitOk;
}

int isoTpSent(const hostcan::IsoTpOutcome& outcome, const std::string& interface, const std::vector<uint8_t>& message,
              bool json)
{
    const int status = isoTpResult(outcome);
    if (status == kExitOk && json) {
        fmt::print("{}\n", nlohmann::json{{"interface", interface}, {"sent_bytes", message.size()}}.dump());
    }
    return status;
}

int isoTpSend(hostcan::Transport& transport, const can::IsoTpConfig& config, const std::vector<uint8_t>& message,
              bool json)
{
    return isoTpSent(hostcan::isoTpSend(transport, config, message), transport.name(), message, json);
}

int isoTpReceived(const hostcan::IsoTpOutcome& outcome, const std::string& interface, bool json)
{
    const int status = isoTpResult(outcome);
    if (status != kExitOk) {
        return status;
    }
    std::string text;
    for (uint8_t byte : outcome.message) {
        text += fmt::format("{}{:02X}", text.empty() ? "" : " ", byte);
    }
    if (json) {
        fmt::print("{}\n", nlohmann::json{{"interface", interface}, {"length", outcome.message.size()},
                                          {"data", text}}.dump());
    } else {
        fmt::print("{} \n", text); // isotprecv's form: bytes, then a space before the line end.
    }
    return kExitOk;
}

int isoTpReceive(hostcan::Transport& transport, const can::IsoTpConfig& config, long timeoutMs, bool json)
{
    return isoTpReceived(hostcan::isoTpReceive(transport, config, std::chrono::milliseconds(timeoutMs)),
                         transport.name(), json);
}

// "01 02 ff" or "0102ff" into bytes; false for anything else.
bool parseBytes(const std::string& text, std::vector<uint8_t>& bytes)
{
    std::string digits;
    for (char c : text) {
        if (c == ' ') {
            continue;
        }
        if (!std::isxdigit(static_cast<unsigned char>(c))) {
            return false;
        }
        digits += c;
    }
    if (digits.empty() || digits.size() % 2 != 0 || digits.size() / 2 > 4095) {
        return false;
    }
    for (size_t i = 0; i < digits.size(); i += 2) {
        bytes.push_back(static_cast<uint8_t>(std::stoul(digits.substr(i, 2), nullptr, 16)));
    }
    return true;
}

// The CAN network interfaces Linux has: those whose /sys/class/net/<name>/type
// is ARPHRD_CAN (280, include/uapi/linux/if_arp.h), sorted by name.
constexpr int kArphrdCan = 280;

std::vector<std::string> socketCanInterfaces()
{
    std::vector<std::string> names;
    std::error_code problem;
    for (std::filesystem::directory_iterator entry("/sys/class/net", problem), end; !problem && entry != end;
         entry.increment(problem)) {
        std::ifstream typeFile(entry->path() / "type");
        int type = 0;
        if (typeFile >> type && type == kArphrdCan) {
            names.push_back(entry->path().filename().string());
        }
    }
    std::sort(names.begin(), names.end());
    return names;
}

// `dcos-can list`: what -i can name here. Finding nothing is an answer,
// not a failure, so the exit status is 0 either way.
int list(bool json)
{
    const std::vector<std::string> interfaces = socketCanInterfaces();
    TransportError usbError;
    const std::vector<hostcan::GsUsbAdapterInfo> adapters = hostcan::LibUsbGsDevice::list(true, usbError);
    if (json) {
        nlohmann::json out = {{"socketcan", interfaces}, {"gsusb", nlohmann::json::array()}};
        for (const hostcan::GsUsbAdapterInfo& a : adapters) {
            nlohmann::json adapter = {{"bus", a.bus},
                                      {"address", a.address},
                                      {"vid", fmt::format("{:04x}", a.vendor)},
                                      {"pid", fmt::format("{:04x}", a.product)},
                                      {"serial", a.serial},
                                      {"product", a.productName},
                                      {"channels", nullptr}};
            if (a.channels) {
                adapter["channels"] = *a.channels;
            }
            if (!a.serial.empty()) {
                adapter["interface"] = "gsusb:" + a.serial;
            }
            if (!a.problem.empty()) {
                adapter["problem"] = a.problem;
            }
            out["gsusb"].push_back(adapter);
        }
        if (usbError) {
            out["usb_error"] = usbError.message;
        }
        fmt::print("{}\n", out.dump());
        return kExitOk;
    }
    if (interfaces.empty()) {
        fmt::print("SocketCAN interfaces: none\n");
    } else {
        fmt::print("SocketCAN interfaces:\n");
        for (const std::string& name : interfaces) {
            fmt::print("  -i {}\n", name);
        }
    }
    if (usbError) {
        fmt::print("gs_usb adapters: cannot look ({})\n", usbError.message);
    } else if (adapters.empty()) {
        fmt::print("gs_usb adapters: none\n");
    } else {
        fmt::print("gs_usb adapters:\n");
        for (const hostcan::GsUsbAdapterInfo& a : adapters) {
            const std::string name = a.serial.empty() ? std::string("(serial unknown)") : "-i gsusb:" + a.serial;
            std::string channels;
            if (a.channels) {
                channels = fmt::format(", {} channel{}", *a.channels, *a.channels == 1 ? "" : "s");
            }
            fmt::print("  {}  bus {:03} address {:03}  {:04x}:{:04x}  {}{}{}\n", name, a.bus, a.address, a.vendor,
                       a.product, a.productName.empty() ? "?" : a.productName, channels,
                       a.problem.empty() ? "" : "  (" + a.problem + ")");
        }
    }
    return kExitOk;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"dcos-can: dump, send and measure CAN traffic (candump/cansend conventions, DCOS frames decoded)",
                 "dcos-can"};
    app.set_version_flag("--version", std::string("dcos-can ") + dcos::versionString);
    app.require_subcommand(1);
    app.footer("exit status: 0 done (list: always), 1 incomplete (dump ended early, send refused), 2 bad arguments, "
               "3 interface not available here, 4 interface failed\n"
               "interfaces: can0 (SocketCAN), slcan:/dev/ttyACM0[@bitrate], slcan-socket:/path[@bitrate], "
               "gsusb[:<serial>][@bitrate] (a gs_usb adapter through libusb), "
               "lab:<hub socket>:<bus> (the emulator lab's CAN bus); `dcos-can list` shows them");
    std::string interface;
    bool json = false;
    // Required by every command but list, which is checked after parsing.
    app.add_option("-i,--interface", interface, "the CAN interface");
    app.add_flag("--json", json, "machine-readable output: one JSON object per line");

    CLI::App* listCommand =
        app.add_subcommand("list", "the SocketCAN interfaces and gs_usb adapters present (-i needs none)");
    listCommand->add_flag("--json", json, "one JSON object");

    DumpOptions dumpOptions;
    CLI::App* dumpCommand = app.add_subcommand("dump", "print frames as candump does");
    dumpCommand->add_option("-n,--count", dumpOptions.count, "stop after this many frames")->check(CLI::PositiveNumber);
    dumpCommand->add_option("-t,--timeout-ms", dumpOptions.timeoutMs, "stop after this long")
        ->check(CLI::Range(1L, 86'400'000L));
    dumpCommand->add_flag("--decode", dumpOptions.decode, "decode the DCOS identifier (priority, type, nodes)");
    bool noErrors = false;
    dumpCommand->add_flag("--no-errors", noErrors, "leave out the bus's error events");

    std::vector<std::string> frames;
    long sendTimeoutMs = 1000;
    CLI::App* sendCommand = app.add_subcommand("send", "send frames written as cansend takes them");
    sendCommand->add_option("frames", frames, "<id>#<data>, e.g. 123#DEADBEEF, 1ABCDEF0#01.02, 123#R")->required();
    sendCommand->add_option("--timeout-ms", sendTimeoutMs, "how long a full interface queue, and at the end a USB adapter's confirmation of the last frames, is waited for")
        ->check(CLI::Range(0L, 600'000L));

    double seconds = 1.0;
    uint32_t bitRate = 0;
    CLI::App* statsCommand = app.add_subcommand("stats", "frame rate, bus load and error events over a time");
    statsCommand->add_option("-s,--seconds", seconds, "how long to listen")->check(CLI::Range(0.01, 86400.0));
    statsCommand->add_option("--bitrate", bitRate, "the bus's bit rate, for the load")
        ->check(CLI::Range(1'000u, 1'000'000u));

    IsoTpOptions isoTp;
    CLI::App* isoTpSendCommand = app.add_subcommand("isotp-send", "send one ISO 15765-2 message, as isotpsend does");
    isoTpSendCommand->add_option("-s,--source", isoTp.source, "the identifier this end sends on (hex)")->required();
    isoTpSendCommand->add_option("-d,--destination", isoTp.destination, "the identifier of the flow control (hex)")
        ->required();
    isoTpSendCommand->add_option("data", isoTp.data, "1 to 4095 bytes in hexadecimal, e.g. \"01 02 03\"")->required();
    isoTpSendCommand->add_flag("-p,--padding", isoTp.padding, "pad every frame to 8 bytes with 0xCC");
    isoTpSendCommand->add_flag("--kernel", isoTp.kernel,
                               "segment with the kernel's ISO-TP socket (can-isotp), not our own; SocketCAN only");
    CLI::App* isoTpReceiveCommand =
        app.add_subcommand("isotp-recv", "receive one ISO 15765-2 message and print it, as isotprecv does");
    isoTpReceiveCommand->add_option("-s,--source", isoTp.source, "the identifier of the flow control this end sends (hex)")
        ->required();
    isoTpReceiveCommand->add_option("-d,--destination", isoTp.destination, "the identifier the message comes on (hex)")
        ->required();
    isoTpReceiveCommand->add_option("-t,--timeout-ms", isoTp.timeoutMs, "how long to wait for the message to begin")
        ->check(CLI::Range(1L, 86'400'000L));
    isoTpReceiveCommand->add_flag("-p,--padding", isoTp.padding, "pad the flow control to 8 bytes with 0xCC");
    isoTpReceiveCommand->add_flag("--kernel", isoTp.kernel,
                                  "reassemble with the kernel's ISO-TP socket (can-isotp), not our own; SocketCAN only");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int code = app.exit(error);
        return code == 0 ? kExitOk : kExitUsage;
    }
    dumpOptions.errors = !noErrors;
    if (*listCommand) {
        return list(json);
    }
    if (interface.empty()) {
        fmt::print(stderr, "dcos-can: -i,--interface is required, e.g. -i can0 or -i gsusb (`dcos-can list` shows "
                           "what is there)\n");
        return kExitUsage;
    }

    std::vector<can::CanFrame> parsed;
    if (*sendCommand && !parseFrames(frames, parsed)) {
        return kExitUsage;
    }
    can::IsoTpConfig isoTpSettings;
    std::vector<uint8_t> message;
    if ((*isoTpSendCommand || *isoTpReceiveCommand) && !isoTpConfig(isoTp, isoTpSettings)) {
        return kExitUsage;
    }
    if (*isoTpSendCommand && !parseBytes(isoTp.data, message)) {
        fmt::print(stderr, "dcos-can: '{}' is not 1 to 4095 bytes in hexadecimal\n", isoTp.data);
        return kExitUsage;
    }
    if ((*isoTpSendCommand || *isoTpReceiveCommand) && isoTp.kernel) {
        // The kernel's sockets exist on SocketCAN interfaces only, named
        // plainly (can0), never behind a transport prefix (lab:, slcan:).
        if (interface.find(':') != std::string::npos) {
            fmt::print(stderr, "dcos-can: --kernel needs a SocketCAN interface such as can0, not '{}'\n", interface);
            return kExitUsage;
        }
        const hostcan::IsoTpOutcome outcome =
            *isoTpSendCommand ? hostcan::kernelIsoTpSend(interface, isoTpSettings, message,
                                                         std::chrono::milliseconds(isoTp.timeoutMs))
                              : hostcan::kernelIsoTpReceive(interface, isoTpSettings,
                                                            std::chrono::milliseconds(isoTp.timeoutMs));
        return *isoTpSendCommand ? isoTpSent(outcome, interface, message, json)
                                 : isoTpReceived(outcome, interface, json);
    }
    TransportError error;
    const std::unique_ptr<hostcan::Transport> transport = hostcan::openTransport(interface, error);
    if (!transport) {
        return fail(error);
    }
    if (*dumpCommand) {
        return dump(*transport, dumpOptions, json);
    }
    if (*sendCommand) {
        return send(*transport, parsed, sendTimeoutMs, json);
    }
    if (*isoTpSendCommand) {
        return isoTpSend(*transport, isoTpSettings, message, json);
    }
    if (*isoTpReceiveCommand) {
        return isoTpReceive(*transport, isoTpSettings, isoTp.timeoutMs, json);
    }
    return stats(*transport, seconds, bitRate, json);
}
