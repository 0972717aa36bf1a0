// dcos-flash: put a signed image on a controller over CAN or its serial
// line (docs/guide/flashing.md, docs/protocols/flash.md).
//
//     dcos-flash -i IFACE -n NODE -k KEY.pem IMAGE.dcos [--no-restart] [--no-wait] [--resume]
//     dcos-flash -d DEVICE -k KEY.pem [-n NODE] IMAGE.dcos [--no-restart] [--resume]
//     dcos-flash (-i IFACE -n NODE | -d DEVICE) info
//     dcos-flash (-i IFACE -n NODE | -d DEVICE) -k KEY.pem restart [--recovery]
//     dcos-flash (-i IFACE -n NODE | -d DEVICE) --recover [--bridge SERIAL|/dev/hidrawN]
//                [--reset-pin N] [--strap-pin N] [-k KEY.pem IMAGE.dcos]
//
// IFACE is a CAN interface as every DCOS tool takes it (can0,
// slcan:/dev/ttyACM0, lab:/hub.sock:can0), NODE the node's CAN node
// number; the running application's flash service answers there, and so
// does the stage loader in recovery. DEVICE is a serial device
// (/dev/ttyUSB0, 115200 bit/s 8N1) or a Unix socket (unix:/path, the
// emulated board's console), which carries the protocol in recovery. The
// session is authenticated with KEY.pem, a signing key the node's card
// trusts. The transfer resumes by itself where an interrupted one stopped,
// if the node still holds it. After the image is verified on the node and
// marked pending, the node restarts into it as a trial (unless
// --no-restart); the image must then confirm (boot confirm), or the node
// reverts. On CAN the tool then waits for that outcome (unless --no-wait).
//
// --recover first brings the node into the stage loader's recovery through
// its reset line and recovery strap, wired to two GPIO pins of a Microchip
// MCP2221A USB bridge (hidapi): it pulls the strap low, pulses reset, waits
// until the node answers in recovery, releases the strap, and then goes on
// with the command (an image to flash, info), or stops there.
//
// Every command takes --json. Exit status: 0 done (and, when waited for,
// confirmed); 1 refused by the node (authentication, the image, the node
// id), or the trial reverted, with the reason; 2 bad arguments; 3 the
// device, interface or a file is not available; 4 the link failed (no
// answer, the line closed), the key is not P-256, or the trial's outcome
// did not come in time. With --recover: 3 no MCP2221A found, 4 it answered
// nonsense or the node did not come up in recovery in time.
#include <hostflash/CanFlashLink.hpp>
#include <hostflash/FlashLink.hpp>
#include <hostflash/HidapiDevice.hpp>
#include <hostflash/Mcp2221Lines.hpp>
#include <hostflash/SerialFlashLink.hpp>

#include <hostimage/SigningKey.hpp>
#include <hostimage/ToolFiles.hpp>

#include <boot/BootState.hpp>
#include <boot/Crc32.hpp>
#include <can/MessageIdentifier.hpp>
#include <flash/FlashMessage.hpp>
#include <image/ImageHeader.hpp>
#include <image/Sha256.hpp>

#include <dcos/Version.hpp>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

namespace {

using flash::FlashMessage;
using flash::FlashStatus;
using flash::MessageType;
using hostflash::LinkError;

constexpr int kExitOk = 0;
constexpr int kExitRefused = 1;
constexpr int kExitUsage = 2;
constexpr int kExitNotAvailable = 3;
constexpr int kExitFailed = 4;

int fail(int code, const std::string& message)
{
    fmt::print(stderr, "dcos-flash: {}\n", message);
    return code;
}

struct Options {
    std::string device;
    std::string interface;
    std::string key;
    std::string image;
    int node = -1;
    int source = flash::kCanHostNode;
    int priority = flash::kCanFlashPriority;
    bool kernelIsoTp = false;
    bool noRestart = false;
    bool noWait = false;
    long confirmTimeoutS = 120;
    bool resumeOnly = false;
    bool recovery = false;
    long timeoutMs = 2000;
    int retries = 3;
    bool json = false;
    // --recover: the reset and strap lines on an MCP2221A.
    bool recover = false;
    std::string bridge;
    unsigned resetPin = 0;
    unsigned strapPin = 1;
    long resetMs = 100;
    long recoveryTimeoutS = 60;
    bool recovered = false; // Set once the node answered in recovery.
};

// One request and its reply, sent again on silence up to the retry count.
class Conversation {
public:
    Conversation(hostflash::FlashLink& link, const Options& options) : link_(link), options_(options) {}

    std::optional<FlashMessage> ask(FlashMessage request, std::string& why)
    {
        request.tag = ++tag_;
        for (int attempt = 0; attempt <= options_.retries; ++attempt) {
            FlashMessage reply;
            const LinkError error = link_.exchange(request, reply, std::chrono::milliseconds(options_.timeoutMs), why);
            if (error == LinkError::None) {
                if (reply.type == MessageType::ErrorReply) {
                    why = fmt::format("the node could not read a request: {}", flash::flashStatusText(reply.status));
                    return std::nullopt;
                }
                return reply;
            }
            if (error != LinkError::Timeout) {
                return std::nullopt;
            }
            ++retransmissions_;
        }
        why = fmt::format("no answer from the node after {} attempts ({})", options_.retries + 1, why);
        return std::nullopt;
    }

    unsigned retransmissions() const { return retransmissions_; }
    hostflash::FlashLink& link() { return link_; }

private:
    hostflash::FlashLink& link_;
    const Options& options_;
    uint8_t tag_ = 0;
    unsigned retransmissions_ = 0;
};

std::string versionOf(const FlashMessage& hello, int slot)
{
    return hello.slotHolds[slot] ? hostimage::versionText(hello.slotVersion[slot]) : std::string("empty");
}

// A refusal's text: the status, and for a refused image its reason.
std::string refusal(uint16_t node, const FlashMessage& reply)
{
    return fmt::format("node {}: {}{}", node, flash::flashStatusText(reply.status),
                       reply.status == FlashStatus::ImageRefused
                           ? fmt::format(": {}", image::imageErrorText(reply.imageError))
                           : "");
}

const char* slotText(uint8_t slot) { return slot == 0 ? "A" : slot == 1 ? "B" : "none"; }

nlohmann::json helloJson(const FlashMessage& hello)
{
    static const char* trials[] = {"none", "pending", "booting"};
    return {{"node", hello.node},
            {"mode", hello.mode == flash::NodeMode::Recovery ? "recovery" : "application"},
            {"protocol", hello.protocol},
            {"confirmed", slotText(hello.confirmedSlot)},
            {"trial", hello.trial <= 2 ? trials[hello.trial] : "?"},
            {"trial_slot", slotText(hello.trialSlot)},
            {"slot_a", versionOf(hello, 0)},
            {"slot_b", versionOf(hello, 1)},
            {"transfer_slot", slotText(hello.transferSlot)},
            {"transfer_offset", hello.transferOffset}};
}

std::optional<FlashMessage> sayHello(Conversation& conversation, int& code)
{
    FlashMessage request;
    request.type = MessageType::Hello;
    std::string why;
    std::optional<FlashMessage> reply = conversation.ask(request, why);
    if (!reply || reply->type != MessageType::HelloReply) {
        code = fail(kExitFailed, reply ? "the node answered Hello with something else" : why);
        return std::nullopt;
    }
    if (reply->protocol != flash::kProtocolVersion) {
        code = fail(kExitRefused, fmt::format("the node speaks flash protocol {}, this tool {}", reply->protocol,
                                              flash::kProtocolVersion));
        return std::nullopt;
    }
    return reply;
}

std::optional<hostimage::SigningKey> readKey(const Options& options, int& code)
{
    std::string error;
    const std::optional<std::vector<uint8_t>> pem = hostimage::readWholeFile(options.key, error);
    if (!pem) {
        code = fail(kExitNotAvailable, error);
        return std::nullopt;
    }
    std::optional<hostimage::SigningKey> key = hostimage::SigningKey::fromPem(std::string(pem->begin(), pem->end()), error);
    if (!key) {
        code = fail(kExitFailed, fmt::format("{}: {}", options.key, error));
    }
    return key;
}

// The challenge, signed: the node's proof that this session may write its card.
int authenticateSession(Conversation& conversation, const FlashMessage& hello, const hostimage::SigningKey& key)
{
    std::string error;
    FlashMessage authenticate;
    authenticate.type = MessageType::Authenticate;
    uint8_t digest[32];
    flash::authenticationDigest(hello.node, hello.challenge, digest);
    const image::TrustedKey keyId = hostimage::trustedKeyOf(key.publicPoint());
    std::copy(std::begin(keyId.id), std::end(keyId.id), authenticate.keyId);
    if (!key.sign(digest, authenticate.signature, error)) {
        return fail(kExitFailed, error);
    }
    const std::optional<FlashMessage> reply = conversation.ask(authenticate, error);
    if (!reply) {
        return fail(kExitFailed, error);
    }
    if (reply->status != FlashStatus::Ok) {
        return fail(kExitRefused, fmt::format("node {}: {}", hello.node, flash::flashStatusText(reply->status)));
    }
    return kExitOk;
}

int sendRestart(Conversation& conversation, uint16_t node, flash::RestartTarget target)
{
    std::string error;
    FlashMessage restart;
    restart.type = MessageType::Restart;
    restart.target = target;
    const std::optional<FlashMessage> reply = conversation.ask(restart, error);
    if (!reply) {
        return fail(kExitFailed, error);
    }
    if (reply->status != FlashStatus::Ok) {
        return fail(kExitRefused, fmt::format("node {}: {}", node, flash::flashStatusText(reply->status)));
    }
    return kExitOk;
}

// How a trial ended, as the node's Hello tells it after its restart.
enum class TrialOutcome { Confirmed, Reverted, Recovery, NoAnswer };

const char* trialOutcomeName(TrialOutcome outcome)
{
    switch (outcome) {
    case TrialOutcome::Confirmed: return "confirmed";
    case TrialOutcome::Reverted: return "reverted";
    case TrialOutcome::Recovery: return "recovery";
    case TrialOutcome::NoAnswer: return "no answer";
    }
    return "?";
}

// Asks the node for its Hello reply once a second, up to @p timeout, until
// @p done takes one: what it returned, or @p none when the time ran out.
// Tags count up from @p firstTag, so that a late reply to an earlier Hello
// is not taken for the current one.
template <typename Result, typename Done>
Result pollHello(hostflash::FlashLink& link, std::chrono::seconds timeout, uint8_t firstTag, Result none, Done done)
{
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    uint8_t tag = firstTag;
    while (std::chrono::steady_clock::now() < deadline) {
        FlashMessage hello;
        hello.type = MessageType::Hello;
        hello.tag = ++tag;
        FlashMessage reply;
        std::string why;
        const auto asked = std::chrono::steady_clock::now();
        if (link.exchange(hello, reply, std::chrono::milliseconds(1000), why) == LinkError::None &&
            reply.type == MessageType::HelloReply) {
            if (const std::optional<Result> result = done(reply)) {
                return *result;
            }
        }
        std::this_thread::sleep_until(asked + std::chrono::seconds(1));
    }
    return none;
}

// Asks the restarted node once a second until its boot state says how the
// trial of @p slot ended: confirmed, or reverted by the stage loader.
TrialOutcome waitForTrial(hostflash::FlashLink& link, uint8_t slot, const Options& options)
{
    return pollHello(link, std::chrono::seconds(options.confirmTimeoutS), 0x80, TrialOutcome::NoAnswer,
                     [slot](const FlashMessage& reply) -> std::optional<TrialOutcome> {
                         if (reply.mode == flash::NodeMode::Recovery) {
                             return TrialOutcome::Recovery;
                         }
                         if (static_cast<boot::TrialState>(reply.trial) == boot::TrialState::None) {
                             return reply.confirmedSlot == slot ? TrialOutcome::Confirmed : TrialOutcome::Reverted;
                         }
                         return std::nullopt;
                     });
}

// Hello, the node id checked on a serial line, and Authenticate with the
// key of -k: the session every writing command begins with. The Hello's
// reply, or nothing with @p code set.
std::optional<FlashMessage> openSession(Conversation& conversation, const Options& options, int& code)
{
    const std::optional<hostimage::SigningKey> key = readKey(options, code);
    if (!key) {
        return std::nullopt;
    }
    std::optional<FlashMessage> hello = sayHello(conversation, code);
    if (!hello) {
        return std::nullopt;
    }
    if (options.device.size() != 0 && options.node >= 0 && hello->node != options.node) {
        code = fail(kExitRefused, fmt::format("the device reaches node {}, not node {}", hello->node, options.node));
        return std::nullopt;
    }
    code = authenticateSession(conversation, *hello, *key);
    if (code != kExitOk) {
        return std::nullopt;
    }
    return hello;
}

int restartCommand(Conversation& conversation, const Options& options)
{
    int code = kExitOk;
    const std::optional<FlashMessage> hello = openSession(conversation, options, code);
    if (!hello) {
        return code;
    }
    const flash::RestartTarget target = options.recovery ? flash::RestartTarget::Recovery : flash::RestartTarget::Boot;
    if (const int refused = sendRestart(conversation, hello->node, target); refused != kExitOk) {
        return refused;
    }
    if (options.json) {
        fmt::print("{}\n", nlohmann::json{{"node", hello->node}, {"restarted", true},
                                          {"into", options.recovery ? "recovery" : "boot"}}
                               .dump());
    } else {
        fmt::print("node {}: restarting{}\n", hello->node,
                   options.recovery ? " into the stage loader's recovery (it stays there this once)" : "");
    }
    return kExitOk;
}

int info(Conversation& conversation, const Options& options)
{
    int code = kExitOk;
    const std::optional<FlashMessage> hello = sayHello(conversation, code);
    if (!hello) {
        return code;
    }
    const nlohmann::json out = helloJson(*hello);
    if (options.json) {
        fmt::print("{}\n", out.dump());
        return kExitOk;
    }
    fmt::print("node          {} ({})\n", hello->node, out["mode"].get<std::string>());
    fmt::print("slot A        {}\n", out["slot_a"].get<std::string>());
    fmt::print("slot B        {}\n", out["slot_b"].get<std::string>());
    fmt::print("confirmed     {}\n", out["confirmed"].get<std::string>());
    fmt::print("trial         {}{}\n", out["trial"].get<std::string>(),
               hello->trialSlot <= 1 ? fmt::format(" in slot {}", slotText(hello->trialSlot)) : "");
    if (hello->transferSlot <= 1) {
        fmt::print("transfer      into slot {}, {} bytes acknowledged (run the same image again to resume)\n",
                   slotText(hello->transferSlot), hello->transferOffset);
    }
    return kExitOk;
}

void showProgress(uint32_t done, uint32_t total, double seconds)
{
    const double rate = seconds > 0 ? done / seconds : 0;
    const double left = rate > 0 ? (total - done) / rate : 0;
    const int width = 30;
    const int filled = total != 0 ? static_cast<int>(width * static_cast<double>(done) / total) : width;
    fmt::print(stderr, "\r[{}{}] {:3}% {} of {} KiB, {:.1f} KiB/s, {}:{:02} left ", std::string(filled, '#'),
               std::string(width - filled, '.'), total != 0 ? done * 100 / total : 100, done / 1024, total / 1024,
               rate / 1024, static_cast<int>(left) / 60, static_cast<int>(left) % 60);
}

int flashImage(Conversation& conversation, const Options& options)
{
    std::string error;
    const std::optional<std::vector<uint8_t>> image = hostimage::readWholeFile(options.image, error);
    if (!image) {
        return fail(kExitNotAvailable, error);
    }
    const image::ImageResult<image::ImageHeader> header = image::ImageHeader::decode(image->data(), image->size());
    if (!header.ok() || image->size() != image::ImageHeader::kSize + header.value().payloadSize) {
        return fail(kExitRefused, fmt::format("{}: {}", options.image,
                                              image::imageErrorText(header.ok() ? image::ImageError::Truncated
                                                                                : header.error())));
    }
    int code = kExitOk;
    const std::optional<FlashMessage> hello = openSession(conversation, options, code);
    if (!hello) {
        return code;
    }
    uint8_t headerDigest[32];
    image::Sha256::digest(image->data(), image::ImageHeader::kSize, headerDigest);
    if (options.resumeOnly &&
        (hello->transferSlot > 1 ||
         !std::equal(std::begin(hello->transferDigest), std::end(hello->transferDigest), headerDigest))) {
        return fail(kExitRefused, fmt::format("node {} holds no interrupted transfer of {} (--resume)", hello->node,
                                              options.image));
    }

    FlashMessage begin;
    begin.type = MessageType::Begin;
    std::copy(image->begin(), image->begin() + image::ImageHeader::kSize, begin.header);
    std::optional<FlashMessage> reply = conversation.ask(begin, error);
    if (!reply) {
        return fail(kExitFailed, error);
    }
    if (reply->status != FlashStatus::Ok) {
        return fail(kExitRefused, refusal(hello->node, *reply));
    }
    const uint8_t slot = reply->slot;
    const uint32_t total = header.value().payloadSize;
    const uint32_t resumedFrom = reply->offset;
    const uint32_t block = hello->maxBlock;
    if (resumedFrom > total || resumedFrom % block != 0) {
        return fail(kExitFailed, fmt::format("the node resumes at {}, which is no block of this image", resumedFrom));
    }
    const bool progress = !options.json && isatty(STDERR_FILENO) != 0;
    const auto started = std::chrono::steady_clock::now();
    for (uint32_t offset = resumedFrom; offset < total;) {
        const uint32_t length = total - offset < block ? total - offset : block;
        FlashMessage data;
        data.type = MessageType::Data;
        data.sequence = offset / block;
        data.offset = offset;
        data.length = static_cast<uint16_t>(length);
        data.bytes = image->data() + image::ImageHeader::kSize + offset;
        data.crc = boot::crc32(data.bytes, length);
        reply = conversation.ask(data, error);
        if (!reply) {
            if (progress) {
                fmt::print(stderr, "\n");
            }
            return fail(kExitFailed, fmt::format("{} after {} of {} bytes (run again to resume)", error, offset, total));
        }
        if (reply->status == FlashStatus::OutOfOrder && reply->offset == offset + length) {
            reply->status = FlashStatus::Ok; // Our retransmission of a block the node had taken.
        }
        if (reply->status != FlashStatus::Ok) {
            if (progress) {
                fmt::print(stderr, "\n");
            }
            return fail(kExitRefused, fmt::format("node {} at byte {}: {}", hello->node, offset,
                                                  flash::flashStatusText(reply->status)));
        }
        offset = reply->offset;
        if (progress) {
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
            showProgress(offset - resumedFrom, total - resumedFrom, seconds);
        }
    }
    if (progress) {
        fmt::print(stderr, "\n");
    }
    FlashMessage end;
    end.type = MessageType::End;
    reply = conversation.ask(end, error);
    if (!reply) {
        return fail(kExitFailed, error);
    }
    if (reply->status != FlashStatus::Ok) {
        return fail(kExitRefused, refusal(hello->node, *reply));
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    bool restarted = false;
    if (!options.noRestart) {
        if (const int refused = sendRestart(conversation, hello->node, flash::RestartTarget::Boot); refused != kExitOk) {
            return refused;
        }
        restarted = true;
    }
    // On CAN the restarted node answers again: wait for its trial's end.
    const bool wait = restarted && !options.noWait && conversation.link().reachesRunningNode();
    if (wait && !options.json) {
        fmt::print(stderr, "node {}: restarted into the trial; waiting up to {} s for it to confirm "
                           "('boot confirm' on the node) or revert\n", hello->node, options.confirmTimeoutS);
    }
    const TrialOutcome outcome = wait ? waitForTrial(conversation.link(), slot, options) : TrialOutcome::NoAnswer;
    const std::string version = hostimage::versionText(header.value().version);
    if (options.json) {
        nlohmann::json out{{"node", hello->node},
                           {"slot", slotText(slot)},
                           {"version", version},
                           {"bytes", total},
                           {"resumed_from", resumedFrom},
                           {"seconds", seconds},
                           {"retransmissions", conversation.retransmissions()},
                           {"pending", true},
                           {"restarted", restarted}};
        if (options.recovered) {
            out["recovered"] = true;
        }
        if (wait) {
            out["trial"] = trialOutcomeName(outcome);
        }
        fmt::print("{}\n", out.dump());
    } else {
        fmt::print("node {}: {} written to slot {}{}, verified, pending\n", hello->node, version, slotText(slot),
                   resumedFrom != 0 ? fmt::format(" (resumed at byte {})", resumedFrom) : "");
        if (wait) {
            fmt::print("node {}: trial {}\n", hello->node,
                       outcome == TrialOutcome::Confirmed  ? "confirmed: the node runs it from now on"
                       : outcome == TrialOutcome::Reverted ? "reverted: it did not confirm, the old image runs"
                       : outcome == TrialOutcome::Recovery ? "ended in the stage loader's recovery"
                                                           : "outcome unknown: the node did not answer in time");
        } else {
            fmt::print("{}\n", restarted ? "restarted into the trial: confirm it on the node ('boot confirm') within "
                                           "the watchdog's 30 s, or it reverts"
                                         : "not restarted (--no-restart): the next start tries it");
        }
    }
    if (!wait || outcome == TrialOutcome::Confirmed) {
        return kExitOk;
    }
    return outcome == TrialOutcome::NoAnswer ? kExitFailed : kExitRefused;
}

// Asks the node once a second, up to @p timeout, until it answers Hello
// in the stage loader's recovery: its node id, or nothing.
std::optional<uint16_t> waitForRecovery(hostflash::FlashLink& link, std::chrono::seconds timeout)
{
    return pollHello(link, timeout, 0x40, std::optional<uint16_t>(),
                     [](const FlashMessage& reply) -> std::optional<std::optional<uint16_t>> {
                         if (reply.mode == flash::NodeMode::Recovery) {
                             return std::optional<uint16_t>(reply.node);
                         }
                         return std::nullopt;
                     });
}

int lineFailure(const hostflash::LineResult& result)
{
    return fail(result.error == hostflash::LineError::BadArgument ? kExitUsage : kExitFailed,
                fmt::format("recovery lines: {}", result.message));
}

// --recover: the strap low, a pulse on reset, the node's answer in
// recovery, the strap released. Whatever fails after the strap went low,
// the strap is released again (as far as the bridge still answers), so
// that the node's next start is an ordinary one.
int recoverNode(hostflash::FlashLink& link, Options& options)
{
    hostflash::HidOpenError openError = hostflash::HidOpenError::None;
    std::string why;
    const std::unique_ptr<hostflash::HidapiDevice> device = hostflash::HidapiDevice::open(options.bridge, openError, why);
    if (!device) {
        return fail(kExitNotAvailable,
                    fmt::format("recovery lines: {}", why));
    }
    hostflash::Mcp2221Lines lines(*device, hostflash::LineWiring{options.resetPin, options.strapPin});
    if (const hostflash::LineResult configured = lines.configure(); !configured.ok()) {
        return lineFailure(configured);
    }
    const auto started = std::chrono::steady_clock::now();
    hostflash::LineResult result = lines.setStrap(true);
    if (result.ok()) {
        result = lines.pulseReset(std::chrono::milliseconds(options.resetMs));
    }
    if (!result.ok()) {
        (void)lines.setStrap(false);
        return lineFailure(result);
    }
    if (!options.json) {
        fmt::print(stderr, "recovery strap on GP{} pulled low, reset pulsed on GP{} for {} ms; waiting up to {} s "
                           "for the node in recovery\n",
                   options.strapPin, options.resetPin, options.resetMs, options.recoveryTimeoutS);
    }
    const std::optional<uint16_t> node = waitForRecovery(link, std::chrono::seconds(options.recoveryTimeoutS));
    const hostflash::LineResult released = lines.setStrap(false);
    if (!node) {
        return fail(kExitFailed, fmt::format("the node did not answer in recovery within {} s after the reset",
                                             options.recoveryTimeoutS));
    }
    if (!released.ok()) {
        return lineFailure(released);
    }
    options.recovered = true;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (!options.json) {
        fmt::print(stderr, "node {}: in the stage loader's recovery ({:.1f} s after the reset); strap released\n",
                   *node, seconds);
    } else if (options.image.empty()) {
        fmt::print("{}\n", nlohmann::json{{"node", *node}, {"recovered", true}, {"seconds", seconds}}.dump());
    }
    return kExitOk;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"dcos-flash: put a signed image on a controller over CAN or its serial line", "dcos-flash"};
    app.set_version_flag("--version", std::string("dcos-flash ") + dcos::versionString);
    app.footer("exit status: 0 done (and confirmed, when waited for), 1 refused by the node or the trial reverted, "
               "2 bad arguments, 3 device, interface, file or MCP2221A not available, 4 link failed, key not "
               "P-256, no outcome in time, or (--recover) the MCP2221A answered nonsense or the node did not come "
               "up in recovery\n"
               "interfaces: can0 (SocketCAN), slcan:/dev/ttyACM0[@bitrate], lab:/path/hub.sock:can0 (the lab bus)\n"
               "devices: /dev/ttyUSB0 (115200 bit/s 8N1), unix:/path (the emulated board's console)");
    Options options;
    CLI::Option* interfaceOption =
        app.add_option("-i,--interface", options.interface, "the CAN interface the node is on (needs -n)");
    CLI::Option* deviceOption = app.add_option("-d,--device", options.device, "the node's serial line (in recovery)");
    interfaceOption->excludes(deviceOption);
    app.add_option("-k,--key", options.key, "a signing key the node's card trusts (PEM)");
    app.add_option("-n,--node", options.node,
                   "CAN: the node's CAN node number; serial: the node id expected at the other end")
        ->check(CLI::Range(0, 0xFFFE));
    app.add_option("--source", options.source, "CAN: this tool's CAN node number")
        ->check(CLI::Range(0, int{can::MessageIdentifier::kMaxNodeNumber}));
    app.add_option("--priority", options.priority, "CAN: the bus priority of the transfer, 0 (most urgent) to 31")
        ->check(CLI::Range(0, 31));
    app.add_flag("--kernel-isotp", options.kernelIsoTp,
                 "CAN: segment with the Linux kernel's ISO-TP socket (can-isotp), not our own; SocketCAN only");
    app.add_option("--timeout-ms", options.timeoutMs, "how long to wait for each answer")
        ->check(CLI::Range(10L, 600000L));
    app.add_option("--retries", options.retries, "how often to send a request again on silence")
        ->check(CLI::Range(0, 100));
    app.add_flag("--no-restart", options.noRestart, "leave the image pending without restarting the node");
    app.add_flag("--no-wait", options.noWait, "CAN: do not wait for the trial to confirm or revert");
    app.add_option("--confirm-timeout", options.confirmTimeoutS, "CAN: seconds to wait for the trial's outcome")
        ->check(CLI::Range(1L, 3600L));
    app.add_flag("--resume", options.resumeOnly,
                 "only go on with the node's interrupted transfer of this image, never start one over "
                 "(without it, a transfer resumes by itself when the node still holds it)");
    app.add_flag("--json", options.json, "machine-readable output: one JSON object");
    app.add_option("image", options.image, "the signed image to flash (dcos-image sign)");
    CLI::App* infoCommand = app.add_subcommand("info", "show the node's slots, versions and boot state");
    CLI::App* restartCommandLine =
        app.add_subcommand("restart", "restart the node (needs -k): into its image, or with --recovery into the "
                                      "stage loader's recovery");
    restartCommandLine->add_flag("--recovery", options.recovery, "stay in the stage loader's recovery on this start");
    app.add_flag("--recover", options.recover,
                 "first bring the node into recovery through its reset line and recovery strap on an MCP2221A "
                 "(then flash IMAGE if given)");
    app.add_option("--bridge", options.bridge,
                   "--recover: the MCP2221A, by USB serial number or hidraw path (default: the first one)");
    app.add_option("--reset-pin", options.resetPin, "--recover: the MCP2221A's GP pin on the reset line")
        ->check(CLI::Range(0u, 3u));
    app.add_option("--strap-pin", options.strapPin, "--recover: the MCP2221A's GP pin on the recovery strap")
        ->check(CLI::Range(0u, 3u));
    app.add_option("--reset-ms", options.resetMs, "--recover: how long reset is held low")
        ->check(CLI::Range(1L, 10000L));
    app.add_option("--recovery-timeout", options.recoveryTimeoutS,
                   "--recover: seconds to wait for the node to answer in recovery after the reset")
        ->check(CLI::Range(1L, 3600L));

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int code = app.exit(error);
        return code == 0 ? kExitOk : kExitUsage;
    }
    if (options.interface.empty() && options.device.empty()) {
        return fail(kExitUsage, "say how to reach the node: -i INTERFACE -n NODE (CAN) or -d DEVICE (serial)");
    }
    if (!options.interface.empty() && options.node < 0) {
        return fail(kExitUsage, "on CAN, -n names the node's CAN node number");
    }
    const bool recoverOnly = options.recover && !*infoCommand && !*restartCommandLine && options.image.empty();
    if (!*infoCommand && !*restartCommandLine && !recoverOnly && (options.image.empty() || options.key.empty())) {
        return fail(kExitUsage, "flashing needs an image and -k KEY.pem (or the 'info' command)");
    }
    if (options.recover && options.resetPin == options.strapPin) {
        return fail(kExitUsage, "--reset-pin and --strap-pin name the same pin");
    }
    if (*restartCommandLine && options.key.empty()) {
        return fail(kExitUsage, "restart needs -k KEY.pem: only an authenticated session restarts a node");
    }
    LinkError error = LinkError::None;
    std::string why;
    std::unique_ptr<hostflash::FlashLink> link;
    if (!options.interface.empty()) {
        if (options.node > can::MessageIdentifier::kMaxNodeNumber) {
            return fail(kExitUsage, fmt::format("CAN node numbers are 0 to {}", can::MessageIdentifier::kMaxNodeNumber));
        }
        hostflash::CanFlashAddress address;
        address.node = static_cast<uint8_t>(options.node);
        address.host = static_cast<uint8_t>(options.source);
        address.priority = static_cast<uint8_t>(options.priority);
        address.kernelIsoTp = options.kernelIsoTp;
        link = hostflash::CanFlashLink::open(options.interface, address, error, why);
    } else {
        link = hostflash::SerialFlashLink::open(options.device, error, why);
    }
    if (!link) {
        return fail(error == LinkError::BadArgument ? kExitUsage
                    : error == LinkError::NotAvailable ? kExitNotAvailable
                                                       : kExitFailed,
                    why);
    }
    if (options.recover) {
        if (const int recovered = recoverNode(*link, options); recovered != kExitOk || recoverOnly) {
            return recovered;
        }
    }
    Conversation conversation(*link, options);
    if (*infoCommand) {
        return info(conversation, options);
    }
    return *restartCommandLine ? restartCommand(conversation, options) : flashImage(conversation, options);
}
