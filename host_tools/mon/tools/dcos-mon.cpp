// dcos-mon: follow a node's console output and publications live over CAN
// (seed 7.14, 8.3; docs/protocols/monitor.md), and keep them as a trend
// plot (PNG) and a table (CSV).
//
//     dcos-mon -i IFACE (-n NODE | --serial S) [-K KEYFILE] [--log]
//              [--data PUB[@OFFSET][:FORMAT][=LABEL]]... [--period-ms 100]
//              [--lease-s 30] [--duration S] [--png FILE] [--csv FILE] [--json]
//
// The tool reaches the node as dcos-config does (-n its CAN node number,
// or --serial, selected on the broadcast address), looks up every
// publisher given by name (FindObject), and asks the node with the
// configuration protocol's Monitor command for a stream: a sample of every
// field once a period and, with --log, a copy of its console. It renews
// the stream every third of its lease and stops it (lease 0) when it ends:
// after --duration seconds, on SIGINT or SIGTERM, or when the stream ends.
// A tool killed outright leaves a stream that ends by itself when its lease
// runs out.
//
// Output, one line per event on standard output (JSON Lines with --json):
//     T_SECONDS NODE LABEL VALUE   a sample; T is the node's time since the first sample
//     log: TEXT                    a line of the node's console
//     log: [N frames lost]         console frames that did not arrive
//     log: [N bytes lost]          console bytes the node dropped (its ring was full)
//
// Exit status: 0 done; 1 refused by the node (its status, the kernel's for
// a publisher it cannot sample) or the stream taken over by another host;
// 2 bad arguments (also -K missing for a node whose queries are closed);
// 3 the interface or a file is not available; 4 no answer, or the stream
// stopped arriving.
#include <hostmon/ChannelSpec.hpp>
#include <hostmon/StreamDecoder.hpp>
#include <hostmon/StreamLink.hpp>
#include <hostmon/TrendPlot.hpp>

#include <hostconfig/ConfigClient.hpp>
#include <hostconfig/ConfigRequest.hpp>
#include <hostconfig/NodeObjects.hpp>
#include <hostconfig/NodeSession.hpp>
#include <hostimage/ConfigurationKeyFile.hpp>

#include <can/MessageIdentifier.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Version.hpp>
#include <sei/CanSeiServer.hpp>
#include <sei/SeiMessage.hpp>
#include <sei/SeiMonitor.hpp>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace {

using hostconfig::ConfigClient;
using hostconfig::ConfigError;
using hostconfig::ConfigurationKey;
using hostconfig::LinkError;
using hostconfig::NodeIdentity;
using Clock = std::chrono::steady_clock;

using hostconfig::kExitNoAnswer;
using hostconfig::kExitNotAvailable;
using hostconfig::kExitOk;
using hostconfig::kExitRefused;
using hostconfig::kExitUsage;

// A console line begun and left unended this long (a prompt) is shown as
// it is.
constexpr auto kPartialLineQuiet = std::chrono::milliseconds(1000);

volatile std::sig_atomic_t interrupted = 0;

void onSignal(int) { interrupted = 1; }

int fail(int code, const std::string& message)
{
    fmt::print(stderr, "dcos-mon: {}\n", message);
    return code;
}

void warn(const std::string& message) { fmt::print(stderr, "dcos-mon: {}\n", message); }

struct Options {
    std::string interface;
    int source = sei::kCanSeiHostNode;
    int priority = sei::kCanSeiPriority;
    long timeoutMs = 2000;
    int retries = 3;
    int node = -1;
    uint32_t serial = 0;
    bool bySerial = false;
    std::string keyFile;
    bool log = false;
    std::vector<std::string> data;
    int periodMs = 100;
    int leaseSeconds = 30;
    double durationSeconds = 0;
    double silenceSeconds = 0;
    std::string png;
    std::string pngSize = "1000x600";
    std::string csv;
    bool json = false;
};

// A failure said as "<who>: <what> failed: <why>", with the exit status the
// tools document.
int failWith(const ConfigError& error, const std::string& who, const std::string& what)
{
    return fail(hostconfig::exitCodeOf(error), fmt::format("{} ({})", hostconfig::describe(error, who), what));
}

// One field followed: what the user asked, and the id it has on the node.
struct Channel {
    hostmon::ChannelSpec spec;
    uint32_t publisher = 0;
    hostmon::TrendSeries series;
};

sei::SeiMessage monitorRequest(const Options& options, const std::vector<Channel>& channels, uint16_t leaseSeconds)
{
    sei::SeiMessage request = hostconfig::requestOf(sei::SeiCommand::Monitor);
    request.leaseSeconds = leaseSeconds;
    request.periodMs = static_cast<uint16_t>(options.periodMs);
    request.monitorFlags = options.log ? sei::kSeiMonitorLog : 0;
    request.channelCount = static_cast<uint8_t>(channels.size());
    for (size_t i = 0; i < channels.size(); ++i) {
        request.channels[i].publisher = channels[i].publisher;
        request.channels[i].offset = channels[i].spec.offset;
        request.channels[i].format = channels[i].spec.format;
    }
    return request;
}

std::string endText(sei::MonitorEndReason reason)
{
    switch (reason) {
    case sei::MonitorEndReason::LeaseExpired: return "lease expired";
    case sei::MonitorEndReason::Stopped: return "stopped";
    case sei::MonitorEndReason::Replaced: return "replaced by another host";
    }
    return "ended";
}

std::string jsonLine(const nlohmann::json& value)
{
    // Console bytes need not be UTF-8; a byte that is not is shown as U+FFFD
    // rather than ending the tool.
    return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// Prints what the stream said, keeps the samples for the plot; the exit
// status the stream's end asks for in @p endCode (or -1 while it runs).
class Printer {
public:
    Printer(const Options& options, uint16_t nodeId, std::vector<Channel>& channels)
        : options_(options), nodeId_(nodeId), channels_(channels)
    {
    }

    void show(const std::vector<hostmon::StreamEvent>& events)
    {
        for (const hostmon::StreamEvent& event : events) {
            show(event);
        }
        std::fflush(stdout);
    }

    int endCode() const { return endCode_; }
    bool ended() const { return endCode_ >= 0; }
    unsigned samples() const { return samples_; }

private:
    void show(const hostmon::StreamEvent& event)
    {
        using Kind = hostmon::StreamEvent::Kind;
        switch (event.kind) {
        case Kind::Sample: {
            if (event.channel >= channels_.size()) {
                return; // A channel this tool did not ask for: another request's.
            }
            Channel& channel = channels_[event.channel];
            const int64_t value = sei::monitorSampleMeaning(event.value, channel.spec.format);
            channel.series.points.emplace_back(event.seconds, static_cast<double>(value));
            ++samples_;
            if (options_.json) {
                fmt::print("{}\n", jsonLine({{"t", event.seconds},
                                             {"node", nodeId_},
                                             {"label", channel.spec.label},
                                             {"value", value}}));
            } else {
                fmt::print("{:.3f} {} {} {}\n", event.seconds, nodeId_, channel.spec.label, value);
            }
            break;
        }
        case Kind::LogLine:
            if (options_.json) {
                fmt::print("{}\n", jsonLine({{"node", nodeId_}, {"log", event.text}}));
            } else {
                fmt::print("log: {}\n", event.text);
            }
            break;
        case Kind::LogGap:
            if (options_.json) {
                fmt::print("{}\n", jsonLine({{"node", nodeId_}, {"log_frames_lost", event.count}}));
            } else {
                fmt::print("log: [{} frames lost]\n", event.count);
            }
            break;
        case Kind::LogLost:
            if (options_.json) {
                fmt::print("{}\n", jsonLine({{"node", nodeId_}, {"log_bytes_lost", event.count}}));
            } else {
                fmt::print("log: [{} bytes lost]\n", event.count);
            }
            break;
        case Kind::End:
            if (options_.json) {
                fmt::print("{}\n", jsonLine({{"node", nodeId_}, {"end", endText(event.reason)}}));
            }
            switch (event.reason) {
            case sei::MonitorEndReason::LeaseExpired:
                warn("the node ended the stream: its lease expired before a renewal arrived");
                endCode_ = kExitNoAnswer;
                break;
            case sei::MonitorEndReason::Stopped:
                warn("the node ended the stream: a Monitor with lease 0 stopped it");
                endCode_ = kExitRefused;
                break;
            case sei::MonitorEndReason::Replaced:
                warn("the node ended the stream: another host's Monitor took it over");
                endCode_ = kExitRefused;
                break;
            }
            break;
        }
    }

    const Options& options_;
    uint16_t nodeId_;
    std::vector<Channel>& channels_;
    int endCode_ = -1;
    unsigned samples_ = 0;
};

bool parseSize(const std::string& text, int& width, int& height)
{
    unsigned w = 0;
    unsigned h = 0;
    char x = 0;
    char extra = 0;
    if (std::sscanf(text.c_str(), "%u%c%u%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X')) {
        return false;
    }
    if (w < hostmon::kMinPlotWidth || h < hostmon::kMinPlotHeight || w > hostmon::kMaxPlotSide ||
        h > hostmon::kMaxPlotSide) {
        return false;
    }
    width = static_cast<int>(w);
    height = static_cast<int>(h);
    return true;
}

int writeOutputs(const Options& options, const std::vector<Channel>& channels, const std::string& who)
{
    int code = kExitOk;
    if (!options.png.empty()) {
        hostmon::PlotOptions plot;
        (void)parseSize(options.pngSize, plot.width, plot.height); // Checked before the stream started.
        plot.title = fmt::format("{}, every {} ms", who, options.periodMs);
        std::vector<hostmon::TrendSeries> series;
        for (const Channel& channel : channels) {
            hostmon::TrendSeries s = channel.series;
            s.label = channel.spec.label;
            series.push_back(std::move(s));
        }
        std::string why;
        if (!hostmon::writeTrendPlot(options.png, series, plot, why)) {
            code = fail(kExitNotAvailable, why);
        }
    }
    if (!options.csv.empty()) {
        std::ofstream out(options.csv);
        out << "t_seconds,label,value\n";
        for (const Channel& channel : channels) {
            for (const auto& [t, value] : channel.series.points) {
                out << fmt::format("{:.3f},{},{}\n", t, channel.spec.label, static_cast<int64_t>(value));
            }
        }
        out.close();
        if (!out) {
            code = fail(kExitNotAvailable, fmt::format("cannot write {}", options.csv));
        }
    }
    return code;
}

// Looks every publisher given by name up on the node (FindObject).
int resolvePublishers(ConfigClient& client, const NodeIdentity& node, const ConfigurationKey* key,
                      std::vector<Channel>& channels, const std::string& who)
{
    for (Channel& channel : channels) {
        if (channel.spec.publisherName.empty()) {
            channel.publisher = channel.spec.publisherId;
            continue;
        }
        hostconfig::NodeObjects objects(client, node, key);
        if (const ConfigError error =
                objects.find(dcos::ObjectType::DsmPublisher, channel.spec.publisherName, channel.publisher)) {
            return failWith(error, who, fmt::format("to find publisher '{}'", channel.spec.publisherName));
        }
    }
    return kExitOk;
}

int monitor(const Options& options, std::vector<Channel>& channels)
{
    std::optional<ConfigurationKey> key;
    if (!options.keyFile.empty()) {
        std::string error;
        bool unreadable = false;
        key = hostimage::readConfigurationKey(options.keyFile, error, unreadable);
        if (!key) {
            return fail(kExitNotAvailable, error);
        }
    }
    const ConfigurationKey* keyPointer = key ? &*key : nullptr;

    hostmon::StreamAddress address;
    address.node = options.bySerial ? can::MessageIdentifier::kBroadcast : static_cast<uint8_t>(options.node);
    address.host = static_cast<uint8_t>(options.source);
    address.priority = static_cast<uint8_t>(options.priority);
    LinkError linkError = LinkError::None;
    std::string why;
    std::unique_ptr<hostmon::StreamLink> link = hostmon::StreamLink::open(options.interface, address, linkError, why);
    if (!link) {
        return fail(linkError == LinkError::BadArgument ? kExitUsage : kExitNotAvailable, why);
    }
    ConfigClient client(*link, {std::chrono::milliseconds(options.timeoutMs), options.retries});
    hostconfig::Selection selection(client, warn);
    NodeIdentity node;
    std::string who;
    const hostconfig::ReachOutcome reached =
        hostconfig::reachNode(client, selection, {options.bySerial, options.serial, options.node}, node, who);
    if (reached.code != kExitOk) {
        return fail(reached.code, reached.message);
    }
    link->setStreamSource(node.canNode);
    if (!key && node.queriesClosed()) {
        return fail(kExitUsage, fmt::format("{} has closed queries (dcos-card create --closed-queries): give its "
                                            "configuration key with -K KEYFILE to follow it",
                                            who));
    }
    if (const int code = resolvePublishers(client, node, keyPointer, channels, who); code != kExitOk) {
        return code;
    }

    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);

    sei::SeiMessage reply;
    const sei::SeiMessage start = monitorRequest(options, channels, static_cast<uint16_t>(options.leaseSeconds));
    if (const ConfigError error = client.query(node, keyPointer, start, reply)) {
        return failWith(error, who, "Monitor");
    }
    fmt::print(stderr, "dcos-mon: following {}: {} field{} every {} ms{}, lease {} s\n", who, channels.size(),
               channels.size() == 1 ? "" : "s", options.periodMs, options.log ? " and its console" : "",
               options.leaseSeconds);

    Printer printer(options, node.nodeId, channels);
    hostmon::StreamDecoder decoder;
    const auto started = Clock::now();
    const auto renewEvery = std::chrono::milliseconds(options.leaseSeconds * 1000 / 3);
    auto renewedAt = started;
    // The bus's own clock (the lab bus's emulated time) when the transport
    // has one: the lease runs on the node's clock, which may go faster than
    // the host's.
    std::optional<std::chrono::nanoseconds> renewedBusTime;
    auto lastFrameAt = started;
    auto lastSampleAt = started;
    const double silenceSeconds =
        options.silenceSeconds > 0 ? options.silenceSeconds : std::max(5.0, 20.0 * options.periodMs / 1000.0);
    const auto silence = std::chrono::milliseconds(static_cast<long>(silenceSeconds * 1000));
    int code = kExitOk;
    bool stopNeeded = true;

    while (!printer.ended()) {
        const auto now = Clock::now();
        if (interrupted != 0) {
            break;
        }
        if (options.durationSeconds > 0 &&
            now - started >= std::chrono::duration<double>(options.durationSeconds)) {
            break;
        }
        if (!channels.empty() && now - lastSampleAt >= silence) {
            code = fail(kExitNoAnswer, fmt::format("the stream stopped arriving: no sample from {} for {:.1f} s",
                                                   who, silenceSeconds));
            break;
        }
        hostmon::StreamArrival arrival;
        hostcan::TransportError transportError;
        const bool got = link->receive(std::chrono::milliseconds(100), arrival, transportError);
        if (transportError) {
            code = fail(kExitNotAvailable, transportError.message);
            stopNeeded = false;
            break;
        }
        bool busRenewalDue = false;
        if (got) {
            lastFrameAt = Clock::now();
            std::vector<hostmon::StreamEvent> events;
            decoder.onFrame(arrival.frame.data(), arrival.frame.length(), arrival.timestamp.count(), events);
            for (const hostmon::StreamEvent& event : events) {
                if (event.kind == hostmon::StreamEvent::Kind::Sample) {
                    lastSampleAt = lastFrameAt;
                }
            }
            printer.show(events);
            if (arrival.emulatedTime) {
                if (!renewedBusTime) {
                    renewedBusTime = arrival.timestamp;
                }
                busRenewalDue = arrival.timestamp - *renewedBusTime >= renewEvery;
            }
        } else if (decoder.hasPartialLine() && Clock::now() - lastFrameAt >= kPartialLineQuiet) {
            std::vector<hostmon::StreamEvent> events;
            decoder.flush(events);
            printer.show(events);
        }
        if (printer.ended()) {
            stopNeeded = false;
            break;
        }
        if (busRenewalDue || Clock::now() - renewedAt >= renewEvery) {
            if (const ConfigError error = client.query(node, keyPointer, start, reply)) {
                code = failWith(error, who, "the renewal of its Monitor");
                stopNeeded = error.kind == ConfigError::Kind::Refused;
                break;
            }
            renewedAt = Clock::now();
            if (got && arrival.emulatedTime) {
                renewedBusTime = arrival.timestamp;
            }
        }
    }
    if (printer.ended()) {
        code = printer.endCode();
    }
    {
        std::vector<hostmon::StreamEvent> events;
        decoder.flush(events);
        printer.show(events);
    }
    if (stopNeeded) {
        // Lease 0: the node stops at once instead of streaming to nobody
        // until the lease runs out.
        if (const ConfigError error = client.query(node, keyPointer, monitorRequest(options, {}, 0), reply)) {
            warn(fmt::format("could not stop the stream ({}); it ends by itself when its lease of {} s runs out",
                             hostconfig::describe(error, who), options.leaseSeconds));
        }
    }
    if (decoder.malformed() != 0) {
        warn(fmt::format("{} stream frames did not decode and were left out", decoder.malformed()));
    }
    if (link->overflowed() != 0) {
        warn(fmt::format("{} stream frames arrived faster than this tool read them and were dropped",
                         link->overflowed()));
    }
    fmt::print(stderr, "dcos-mon: {} samples from {}{}\n", printer.samples(), who,
               options.log ? fmt::format(", {} console frames lost", decoder.logFramesLost()) : std::string());
    const int written = writeOutputs(options, channels, who);
    return code != kExitOk ? code : written;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"dcos-mon: follow a node's console output and publications live over CAN, and keep them as a trend "
                 "plot",
                 "dcos-mon"};
    app.set_version_flag("--version", std::string("dcos-mon ") + dcos::versionString);
    app.footer("output: one line per event, `T_SECONDS NODE LABEL VALUE` for a sample (T the node's time since the "
               "first sample), `log: TEXT` for a console line (JSON Lines with --json)\n"
               "exit status: 0 done, 1 refused by the node (its status, the kernel's for a publisher it cannot "
               "sample) or the stream taken over by another host, 2 bad arguments, 3 interface or file not "
               "available, 4 no answer or the stream stopped arriving\n"
               "interfaces: can0 (SocketCAN), slcan:/dev/ttyACM0[@bitrate], lab:/path/hub.sock:can0 (the lab bus)");
    Options options;
    app.add_option("-i,--interface", options.interface, "the CAN interface the node is on");
    CLI::Option* nodeOption = app.add_option("-n,--node", options.node, "the node's CAN node number")
                                  ->check(CLI::Range(0, int{can::MessageIdentifier::kMaxNodeNumber}));
    CLI::Option* serialOption =
        app.add_option("--serial", options.serial,
                       "the node's serial number (as dcos-config scan lists it): selects it on the broadcast address");
    nodeOption->excludes(serialOption);
    app.add_option("-K,--key-file", options.keyFile,
                   "the node's configuration key file: needed when its queries are closed");
    app.add_flag("--log", options.log, "follow the node's console output");
    app.add_option("--data", options.data,
                   "a field to follow: PUB[@OFFSET][:FORMAT][=LABEL], PUB a publisher's name or 0x id, OFFSET its "
                   "byte in the 16-byte page (0), FORMAT u8 i8 u16 i16 u32 i32 (i32); up to 8");
    app.add_option("--period-ms", options.periodMs, "how often the node samples the fields")
        ->check(CLI::Range(int{sei::SeiMonitor::kMinPeriodMs}, int{sei::SeiMonitor::kMaxPeriodMs}));
    app.add_option("--lease-s", options.leaseSeconds,
                   "how long the node streams without a renewal (renewed every third of it)")
        ->check(CLI::Range(3, int{sei::SeiMonitor::kMaxLeaseSeconds}));
    app.add_option("--duration", options.durationSeconds, "stop after this many seconds (default: at Ctrl-C)")
        ->check(CLI::Range(0.0, 1e7));
    app.add_option("--silence-s", options.silenceSeconds,
                   "give up (exit 4) when no sample came for this long (default: 20 periods, at least 5 s)")
        ->check(CLI::Range(0.0, 1e6));
    app.add_option("--png", options.png, "write the trend plot of the fields to this PNG file at the end");
    app.add_option("--png-size", options.pngSize, "the plot's size in pixels, WIDTHxHEIGHT");
    app.add_option("--csv", options.csv, "write every sample to this CSV file at the end");
    app.add_flag("--json", options.json, "one JSON object per event (JSON Lines)");
    app.add_option("--source", options.source, "this tool's CAN node number")
        ->check(CLI::Range(0, int{can::MessageIdentifier::kMaxNodeNumber}));
    app.add_option("--priority", options.priority,
                   "the bus priority of the requests, which the node's stream takes too, 0 (most urgent) to 31")
        ->check(CLI::Range(0, int{can::MessageIdentifier::kLowestPriority}));
    app.add_option("--timeout-ms", options.timeoutMs, "how long to wait for each answer")
        ->check(CLI::Range(10L, 600000L));
    app.add_option("--retries", options.retries, "how often to send a request again on silence")
        ->check(CLI::Range(0, 100));

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int code = app.exit(error);
        return code == 0 ? kExitOk : kExitUsage;
    }
    options.bySerial = serialOption->count() != 0;
    if (options.interface.empty()) {
        return fail(kExitUsage, "say which CAN interface the node is on: -i can0, -i slcan:/dev/ttyACM0 or "
                                "-i lab:/path/hub.sock:can0");
    }
    if (options.node < 0 && !options.bySerial) {
        return fail(kExitUsage, "say which node: -n NODE (its CAN node number) or --serial S (its serial number)");
    }
    if (options.node == options.source) {
        return fail(kExitUsage, fmt::format("the node's CAN node number ({}) must differ from the tool's (--source)",
                                            options.node));
    }
    if (options.bySerial && options.serial == 0) {
        return fail(kExitUsage, "serial number 0 is no serial number: reach that node with -n");
    }
    if (!options.log && options.data.empty()) {
        return fail(kExitUsage, "say what to follow: --log for the console, --data PUB for a publication's field");
    }
    if (options.data.size() > sei::kSeiMaxMonitorChannels) {
        return fail(kExitUsage, fmt::format("at most {} --data fields", sei::kSeiMaxMonitorChannels));
    }
    int width = 0;
    int height = 0;
    if (!parseSize(options.pngSize, width, height)) {
        return fail(kExitUsage, fmt::format("--png-size is WIDTHxHEIGHT, {}x{} to {}x{} pixels", hostmon::kMinPlotWidth,
                                            hostmon::kMinPlotHeight, hostmon::kMaxPlotSide, hostmon::kMaxPlotSide));
    }
    if (!options.png.empty() && options.data.empty()) {
        return fail(kExitUsage, "--png plots the --data fields: give at least one");
    }
    std::vector<Channel> channels;
    for (const std::string& text : options.data) {
        std::string why;
        std::optional<hostmon::ChannelSpec> spec = hostmon::parseChannelSpec(text, why);
        if (!spec) {
            return fail(kExitUsage, fmt::format("--data {}", why));
        }
        for (const Channel& other : channels) {
            if (other.spec.label == spec->label) {
                return fail(kExitUsage, fmt::format("two fields are labelled '{}': give one another label with "
                                                    "=LABEL",
                                                    spec->label));
            }
        }
        Channel channel;
        channel.spec = *spec;
        channels.push_back(channel);
    }
    return monitor(options, channels);
}
