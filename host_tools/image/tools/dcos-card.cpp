// dcos-card: make a controller's CompactFlash card and put images on it
// (docs/boot.md, "The card"; docs/guide/signing-images.md), for a card
// reader or for the emulated board's card.
//
//     dcos-card create -o CARD --boot-sector BIN --stage BIN -p PUB.pem [-p ...]
//                      [--node N] [--bitrate B] [--append TEXT] [--sectors N] [--force]
//                      [--serial N] [--config-key KEY] [--closed-queries] [--lockout S]
//     dcos-card write CARD --slot A|B IMAGE.dcos [--pending] [--allow-downgrade]
//     dcos-card show CARD
//
// Every command takes --json (one JSON object on standard output).
//
// `write` checks the image as the card's stage loader will (its trusted
// keys, the board's slot and memory) and refuses one it would not boot; it
// refuses to overwrite the confirmed slot, and an image older than the
// confirmed one unless --allow-downgrade. With --pending the next boot
// tries the image as a trial (it must confirm, or the boot after reverts).
// Without it, on a card that confirms nothing yet (a new card), the image
// is confirmed: the card's maker vouches for it.
//
// Exit status: 0 done; 1 the card or the image is refused (the reason is
// printed); 2 bad arguments; 3 a file cannot be read or written; 4 a key is
// not usable (a signing key not on P-256, a configuration key file not 64
// hexadecimal digits).
#include <hostimage/CardFile.hpp>
#include <hostimage/ConfigurationKeyFile.hpp>
#include <hostimage/SigningKey.hpp>
#include <hostimage/ToolFiles.hpp>

#include <boot/CardLayout.hpp>
#include <image/ImageVerifier.hpp>

#include <dcos/Version.hpp>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

namespace {

namespace card = boot::card;

constexpr int kExitOk = 0;
constexpr int kExitRefused = 1;
constexpr int kExitUsage = 2;
constexpr int kExitFile = 3;
constexpr int kExitKey = 4;

int fail(int code, const std::string& message)
{
    fmt::print(stderr, "dcos-card: {}\n", message);
    return code;
}

struct CreateOptions {
    std::string output;
    std::string bootSector;
    std::string stage;
    std::vector<std::string> keys;
    uint16_t node = 0;
    uint32_t bitRate = 0;
    std::string append;
    uint32_t sectors = card::kBuiltCardSectors;
    bool force = false;
    uint32_t serial = 0;
    std::string configurationKey;
    bool closedQueries = false;
    uint16_t lockoutSeconds = 0;
};

int create(const CreateOptions& options, bool json)
{
    if (options.keys.size() > boot::ConfigurationBlock::kMaximumKeys) {
        return fail(kExitUsage, "a card trusts at most 4 keys");
    }
    if (options.append.size() >= boot::ConfigurationBlock::kCommandLineSize) {
        return fail(kExitUsage, "the command line takes at most 159 characters");
    }
    for (const char character : options.append) {
        if (character < 0x20 || character > 0x7E) {
            return fail(kExitUsage, "the command line takes printable ASCII only");
        }
    }
    boot::ConfigurationBlock configuration;
    configuration.sequence = 1;
    configuration.nodeId = options.node;
    configuration.canBitRate = options.bitRate;
    std::strncpy(configuration.commandLine, options.append.c_str(), sizeof configuration.commandLine - 1);
    configuration.serialNumber = options.serial;
    configuration.lockoutSeconds = options.lockoutSeconds;
    std::string error;
    if (!options.configurationKey.empty()) {
        bool unreadable = false;
        const std::optional<hostimage::ConfigurationKey> key =
            hostimage::readConfigurationKey(options.configurationKey, error, unreadable);
        if (!key) {
            return fail(unreadable ? kExitFile : kExitKey, error);
        }
        std::copy(key->begin(), key->end(), configuration.configurationKey);
        configuration.flags |= boot::ConfigurationBlock::kHasConfigurationKey;
    }
    if (options.closedQueries) {
        configuration.flags |= boot::ConfigurationBlock::kQueriesClosed;
    }
    nlohmann::json keyIds = nlohmann::json::array();
    for (const std::string& path : options.keys) {
        bool unreadable = false;
        const std::optional<hostimage::SigningKey::PublicPoint> point = hostimage::readPublicKey(path, error, unreadable);
        if (!point) {
            return fail(unreadable ? kExitFile : kExitKey, error);
        }
        std::copy(point->begin(), point->end(), configuration.keys[configuration.keyCount++]);
        const image::TrustedKey key = hostimage::trustedKeyOf(*point);
        keyIds.push_back(hostimage::hexText(key.id, sizeof key.id));
    }
    const std::optional<std::vector<uint8_t>> bootSector = hostimage::readWholeFile(options.bootSector, error);
    if (!bootSector) {
        return fail(kExitFile, error);
    }
    const std::optional<std::vector<uint8_t>> stage = hostimage::readWholeFile(options.stage, error);
    if (!stage) {
        return fail(kExitFile, error);
    }
    const std::optional<hostimage::CardFile> made =
        hostimage::CardFile::create(*bootSector, *stage, configuration, options.sectors, error);
    if (!made) {
        return fail(kExitRefused, error);
    }
    if (!hostimage::writeWholeFile(options.output, made->bytes().data(), made->bytes().size(), false, options.force,
                                   error)) {
        return fail(kExitFile, error);
    }
    if (json) {
        fmt::print("{}\n", nlohmann::json{{"card", options.output},
                                          {"sectors", options.sectors},
                                          {"node", options.node},
                                          {"bitrate", options.bitRate},
                                          {"serial", options.serial},
                                          {"configuration_key", !options.configurationKey.empty()},
                                          {"queries", options.closedQueries ? "closed" : "open"},
                                          {"lockout_seconds", configuration.effectiveLockoutSeconds()},
                                          {"trusted_keys", keyIds}}
                               .dump());
    } else {
        fmt::print("card          {} ({} sectors)\n", options.output, options.sectors);
        fmt::print("trusted keys  {}\n", keyIds.size());
        for (const auto& id : keyIds) {
            fmt::print("              {}\n", id.get<std::string>());
        }
    }
    return kExitOk;
}

std::optional<hostimage::CardFile> openCard(const std::string& path, int& code)
{
    std::string error;
    const std::optional<std::vector<uint8_t>> bytes = hostimage::readWholeFile(path, error);
    if (!bytes) {
        code = fail(kExitFile, error);
        return std::nullopt;
    }
    std::optional<hostimage::CardFile> opened = hostimage::CardFile::open(*bytes, error);
    if (!opened) {
        code = fail(kExitRefused, fmt::format("{}: {}", path, error));
    }
    return opened;
}

std::vector<image::TrustedKey> trustedKeysOf(const boot::ConfigurationBlock& configuration)
{
    std::vector<image::TrustedKey> keys;
    for (size_t i = 0; i < configuration.keyCount; ++i) {
        keys.push_back(image::TrustedKey::fromPoint(configuration.keys[i]));
    }
    return keys;
}

bool slotFromName(const std::string& name, uint32_t& slot)
{
    if (name == "A" || name == "a") {
        slot = 0;
        return true;
    }
    if (name == "B" || name == "b") {
        slot = 1;
        return true;
    }
    return false;
}

struct WriteOptions {
    std::string card;
    std::string slot;
    std::string image;
    bool pending = false;
    bool allowDowngrade = false;
};

int writeImage(const WriteOptions& options, bool json)
{
    uint32_t slot = 0;
    if (!slotFromName(options.slot, slot)) {
        return fail(kExitUsage, fmt::format("slot '{}' is neither A nor B", options.slot));
    }
    int code = kExitOk;
    std::optional<hostimage::CardFile> cardFile = openCard(options.card, code);
    if (!cardFile) {
        return code;
    }
    const std::optional<boot::ConfigurationBlock> configuration = cardFile->configuration();
    if (!configuration) {
        return fail(kExitRefused, fmt::format("{}: no valid configuration on the card", options.card));
    }
    const std::optional<boot::BootState> state = cardFile->bootState();
    const uint8_t confirmed = state ? state->confirmedSlot : boot::BootState::kNoSlot;
    if (slot == confirmed) {
        return fail(kExitRefused, fmt::format("slot {} holds the confirmed image; write the other slot",
                                              card::slotName(slot)));
    }
    std::string error;
    const std::optional<std::vector<uint8_t>> imageBytes = hostimage::readWholeFile(options.image, error);
    if (!imageBytes) {
        return fail(kExitFile, error);
    }
    // The confirmed image's version is the installed one: an older image
    // is a downgrade.
    image::ImageVersion installed;
    image::ImagePolicy policy = image::ImagePolicy::forBoard(image::BoardType::Isa486);
    if (confirmed != boot::BootState::kNoSlot) {
        const std::vector<uint8_t> current = cardFile->slotImage(confirmed);
        const image::ImageResult<image::ImageHeader> header = image::ImageHeader::decode(current.data(), current.size());
        if (header.ok()) {
            installed = header.value().version;
            policy.installed = &installed;
        }
    }
    policy.allowDowngrade = options.allowDowngrade;
    const std::vector<image::TrustedKey> keys = trustedKeysOf(*configuration);
    const image::ImageResult<image::ImageHeader> checked =
        image::ImageVerifier::verify(imageBytes->data(), imageBytes->size(), keys.data(), keys.size(), policy);
    if (!checked.ok()) {
        return fail(kExitRefused, fmt::format("{}: {}", options.image, image::imageErrorText(checked.error())));
    }
    if (!cardFile->writeSlot(slot, *imageBytes, error)) {
        return fail(kExitRefused, error);
    }
    bool confirmedNow = false;
    if (options.pending) {
        boot::BootState next = state.value_or(boot::BootState{});
        next.trialSlot = static_cast<uint8_t>(slot);
        next.trial = boot::TrialState::Pending;
        cardFile->writeBootState(next);
    } else if (state && state->trial != boot::TrialState::None && state->trialSlot == slot) {
        // The slot's trial was another image: what is there now is not on trial.
        boot::BootState next = *state;
        next.trialSlot = boot::BootState::kNoSlot;
        next.trial = boot::TrialState::None;
        cardFile->writeBootState(next);
    } else if (confirmed == boot::BootState::kNoSlot) {
        // A card that confirms nothing yet (a new one): whoever makes it
        // vouches for the image, which is confirmed. The stage loader would
        // otherwise boot it only as a trial, which must confirm.
        boot::BootState next = state.value_or(boot::BootState{});
        next.confirmedSlot = static_cast<uint8_t>(slot);
        if (next.trialSlot == slot) {
            next.trialSlot = boot::BootState::kNoSlot;
            next.trial = boot::TrialState::None;
        }
        cardFile->writeBootState(next);
        confirmedNow = true;
    }
    if (!hostimage::writeWholeFile(options.card, cardFile->bytes().data(), cardFile->bytes().size(), false, true,
                                   error)) {
        return fail(kExitFile, error);
    }
    const std::string version = hostimage::versionText(checked.value().version);
    if (json) {
        fmt::print("{}\n", nlohmann::json{{"card", options.card},
                                          {"slot", card::slotName(slot)},
                                          {"version", version},
                                          {"pending", options.pending},
                                          {"confirmed", confirmedNow}}
                               .dump());
    } else {
        fmt::print("slot {}: {} written{}\n", card::slotName(slot), version,
                   options.pending ? ", pending: the next boot tries it"
                   : confirmedNow  ? ", confirmed (the card confirmed nothing yet)"
                                   : "");
    }
    return kExitOk;
}

const char* trialName(boot::TrialState trial)
{
    switch (trial) {
    case boot::TrialState::None: return "none";
    case boot::TrialState::Pending: return "pending";
    case boot::TrialState::Booting: return "booting";
    }
    return "?";
}

int show(const std::string& path, bool json)
{
    int code = kExitOk;
    std::optional<hostimage::CardFile> cardFile = openCard(path, code);
    if (!cardFile) {
        return code;
    }
    const std::optional<boot::ConfigurationBlock> configuration = cardFile->configuration();
    const std::optional<boot::BootState> state = cardFile->bootState();
    nlohmann::json out{{"card", path}, {"sectors", cardFile->bytes().size() / card::kSectorSize}};
    std::vector<image::TrustedKey> keys;
    if (configuration) {
        keys = trustedKeysOf(*configuration);
        nlohmann::json ids = nlohmann::json::array();
        for (const image::TrustedKey& key : keys) {
            ids.push_back(hostimage::hexText(key.id, sizeof key.id));
        }
        out["configuration"] = {{"sequence", configuration->sequence},
                                {"node", configuration->nodeId},
                                {"bitrate", configuration->canBitRate},
                                {"serial", configuration->serialNumber},
                                {"configuration_key", configuration->hasConfigurationKey()},
                                {"queries", configuration->queriesClosed() ? "closed" : "open"},
                                {"lockout_seconds", configuration->effectiveLockoutSeconds()},
                                {"command_line", configuration->commandLine},
                                {"trusted_keys", ids}};
    } else {
        out["configuration"] = nullptr;
    }
    if (state) {
        out["boot_state"] = {{"sequence", state->sequence},
                             {"confirmed", state->confirmedSlot == boot::BootState::kNoSlot
                                               ? nlohmann::json(nullptr)
                                               : nlohmann::json(card::slotName(state->confirmedSlot))},
                             {"trial", trialName(state->trial)},
                             {"trial_slot", state->trialSlot == boot::BootState::kNoSlot
                                                ? nlohmann::json(nullptr)
                                                : nlohmann::json(card::slotName(state->trialSlot))},
                             {"reverts", state->reverts}};
    } else {
        out["boot_state"] = nullptr;
    }
    nlohmann::json slots = nlohmann::json::object();
    for (uint32_t slot = 0; slot < card::kSlotCount; ++slot) {
        const std::vector<uint8_t> bytes = cardFile->slotImage(slot);
        if (bytes.empty()) {
            slots[card::slotName(slot)] = nullptr;
            continue;
        }
        image::ImagePolicy policy = image::ImagePolicy::forBoard(image::BoardType::Isa486);
        const image::ImageResult<image::ImageHeader> header = image::ImageHeader::decode(bytes.data(), bytes.size());
        const image::ImageResult<image::ImageHeader> verdict =
            image::ImageVerifier::verify(bytes.data(), bytes.size(), keys.data(), keys.size(), policy);
        slots[card::slotName(slot)] = {{"version", hostimage::versionText(header.value().version)},
                                       {"payload_size", header.value().payloadSize},
                                       {"valid", verdict.ok()},
                                       {"reason", image::imageErrorText(verdict.error())}};
    }
    out["slots"] = slots;
    if (json) {
        fmt::print("{}\n", out.dump());
        return kExitOk;
    }
    fmt::print("card          {} ({} sectors)\n", path, out["sectors"].get<size_t>());
    if (configuration) {
        fmt::print("configuration {}: node {}, bit rate {}, {} trusted key(s), command line \"{}\"\n",
                   configuration->sequence, configuration->nodeId, configuration->canBitRate, keys.size(),
                   configuration->commandLine);
        fmt::print("identity      serial {}, configuration key {}, queries {}, lockout {} s\n",
                   configuration->serialNumber, configuration->hasConfigurationKey() ? "set" : "none",
                   configuration->queriesClosed() ? "closed" : "open", configuration->effectiveLockoutSeconds());
    } else {
        fmt::print("configuration none valid\n");
    }
    if (state) {
        fmt::print("boot state    {}: confirmed {}, trial {}{}{}, {} revert(s)\n", state->sequence,
                   card::slotName(state->confirmedSlot), trialName(state->trial),
                   state->trial != boot::TrialState::None ? " in slot " : "",
                   state->trial != boot::TrialState::None ? card::slotName(state->trialSlot) : "", state->reverts);
    } else {
        fmt::print("boot state    none (a new card: the first valid image boots and is confirmed)\n");
    }
    for (uint32_t slot = 0; slot < card::kSlotCount; ++slot) {
        const nlohmann::json& entry = slots[card::slotName(slot)];
        if (entry.is_null()) {
            fmt::print("slot {}        empty\n", card::slotName(slot));
        } else {
            fmt::print("slot {}        {}, {} bytes, {}\n", card::slotName(slot), entry["version"].get<std::string>(),
                       entry["payload_size"].get<uint32_t>(),
                       entry["valid"].get<bool>() ? "valid" : entry["reason"].get<std::string>());
        }
    }
    return kExitOk;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"dcos-card: make a controller's CompactFlash card and put signed images in its slots", "dcos-card"};
    app.set_version_flag("--version", std::string("dcos-card ") + dcos::versionString);
    app.require_subcommand(1);
    app.footer("exit status: 0 done, 1 card or image refused, 2 bad arguments, 3 file not readable or writable, "
               "4 key not usable (a signing key not P-256, a configuration key not 64 hex digits)");
    bool json = false;
    app.add_flag("--json", json, "machine-readable output: one JSON object");

    CreateOptions createOptions;
    CLI::App* createCommand = app.add_subcommand("create", "make a new card: boot sector, stage loader, configuration");
    createCommand->add_option("-o,--output", createOptions.output, "the card image to write")->required();
    createCommand->add_option("--boot-sector", createOptions.bootSector, "the boot sector (512 bytes)")->required();
    createCommand->add_option("--stage", createOptions.stage, "the stage loader (flat binary)")->required();
    createCommand->add_option("-p,--public", createOptions.keys, "a public key the card trusts (repeatable, up to 4)")
        ->required();
    createCommand->add_option("--node", createOptions.node, "the node id (0: the kernel's default)")
        ->check(CLI::Range(0, 0xFFFE));
    createCommand->add_option("--bitrate", createOptions.bitRate, "the CAN bit rate: the node starts can0 on the network at it (0: can0 stays down at boot, "
                                      "recovery listens at 125000)");
    createCommand->add_option("--append", createOptions.append, "the kernel command line (up to 159 characters)");
    createCommand->add_option("--sectors", createOptions.sectors, "the card's size in sectors")
        ->check(CLI::Range(card::kMinimumCardSectors, 1u << 22));
    createCommand->add_flag("--force", createOptions.force, "replace an existing card image");
    createCommand->add_option("--serial", createOptions.serial,
                              "the node's serial number, which dcos-config scan finds it by (0: none)");
    createCommand->add_option("--config-key", createOptions.configurationKey,
                              "the node's configuration key (dcos-config keygen): without one nothing can be "
                              "changed over the bus");
    createCommand->add_flag("--closed-queries", createOptions.closedQueries,
                            "dcos-config's queries need the configuration key too");
    createCommand->add_option("--lockout", createOptions.lockoutSeconds,
                              "seconds a node refuses changes after three wrong keys (0: 60)");

    WriteOptions writeOptions;
    CLI::App* writeCommand = app.add_subcommand("write", "write a signed image into a slot");
    writeCommand->add_option("card", writeOptions.card, "the card image")->required();
    writeCommand->add_option("--slot", writeOptions.slot, "A or B")->required();
    writeCommand->add_option("image", writeOptions.image, "the signed image (dcos-image sign)")->required();
    writeCommand->add_flag("--pending", writeOptions.pending, "the next boot tries it as a trial");
    writeCommand->add_flag("--allow-downgrade", writeOptions.allowDowngrade,
                           "take an image older than the confirmed one");

    std::string showPath;
    CLI::App* showCommand = app.add_subcommand("show", "show a card's configuration, boot state and slots");
    showCommand->add_option("card", showPath, "the card image")->required();

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int code = app.exit(error);
        return code == 0 ? kExitOk : kExitUsage;
    }
    if (*createCommand) {
        return create(createOptions, json);
    }
    if (*writeCommand) {
        return writeImage(writeOptions, json);
    }
    return show(showPath, json);
}
