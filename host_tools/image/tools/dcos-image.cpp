// dcos-image: make and check signed controller images (docs/boot.md,
// "Controller images"; docs/guide/signing-images.md).
//
//     dcos-image keygen -o KEY.pem [--public PUB.pem] [--force]
//     dcos-image sign -k KEY.pem --board isa486 --version 1.2.3[+BUILD] -o IMAGE.dcos FIRMWARE.elf
//     dcos-image verify -p PUB.pem [--installed VERSION] [--allow-downgrade] IMAGE.dcos
//     dcos-image info IMAGE.dcos
//
// Every command takes --json (one JSON object on standard output).
//
// Exit status: 0 done (verify: the image is valid); 1 the image is
// refused (verify: the reason is printed); 2 bad arguments; 3 a file
// cannot be read or written (or the key file exists, without --force);
// 4 a key is not a P-256 key, or the cryptography failed.
#include <hostimage/ElfPayload.hpp>
#include <hostimage/ImageSigner.hpp>
#include <hostimage/SigningKey.hpp>
#include <hostimage/ToolFiles.hpp>

#include <image/ImageHeader.hpp>
#include <image/ImageVerifier.hpp>
#include <image/Sha256.hpp>

#include <dcos/Version.hpp>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace {

constexpr int kExitOk = 0;
constexpr int kExitRefused = 1;
constexpr int kExitUsage = 2;
constexpr int kExitFile = 3;
constexpr int kExitKey = 4;

int fail(int code, const std::string& message)
{
    fmt::print(stderr, "dcos-image: {}\n", message);
    return code;
}

std::string keyIdOf(const hostimage::SigningKey::PublicPoint& point)
{
    uint8_t id[image::ImageHeader::kDigestSize];
    image::Sha256::digest(point.data(), point.size(), id);
    return hostimage::hexText(id, sizeof id);
}

nlohmann::json headerJson(const image::ImageHeader& header)
{
    return {{"board", image::boardName(header.board)},
            {"version", hostimage::versionText(header.version)},
            {"payload_size", header.payloadSize},
            {"memory_size", header.memorySize},
            {"load_address", header.loadAddress},
            {"entry", header.entry},
            {"payload_sha256", hostimage::hexText(header.payloadDigest, sizeof header.payloadDigest)},
            {"key_id", hostimage::hexText(header.keyId, sizeof header.keyId)}};
}

void printHeader(const image::ImageHeader& header)
{
    fmt::print("board         {}\n", image::boardName(header.board));
    fmt::print("version       {}\n", hostimage::versionText(header.version));
    fmt::print("payload       {} bytes\n", header.payloadSize);
    fmt::print("memory        {} bytes (0x{:08x} to 0x{:08x})\n", header.memorySize, header.loadAddress,
               uint64_t{header.loadAddress} + header.memorySize);
    fmt::print("entry         0x{:08x}\n", header.entry);
    fmt::print("payload hash  {}\n", hostimage::hexText(header.payloadDigest, sizeof header.payloadDigest));
    fmt::print("key id        {}\n", hostimage::hexText(header.keyId, sizeof header.keyId));
}

int keygen(const std::string& keyPath, std::string publicPath, bool force, bool json)
{
    if (publicPath.empty()) {
        publicPath = keyPath + ".pub";
    }
    std::string error;
    const std::optional<hostimage::SigningKey> key = hostimage::SigningKey::generate(error);
    if (!key) {
        return fail(kExitKey, error);
    }
    const std::string privatePem = key->privatePem();
    const std::string publicPem = key->publicPem();
    if (privatePem.empty() || publicPem.empty()) {
        return fail(kExitKey, "cannot write the new key as PEM");
    }
    if (!hostimage::writeWholeFile(keyPath, privatePem.data(), privatePem.size(), true, force, error) ||
        !hostimage::writeWholeFile(publicPath, publicPem.data(), publicPem.size(), false, force, error)) {
        return fail(kExitFile, error);
    }
    const std::string id = keyIdOf(key->publicPoint());
    if (json) {
        fmt::print("{}\n", nlohmann::json{{"private_key", keyPath}, {"public_key", publicPath}, {"key_id", id}}.dump());
    } else {
        fmt::print("private key   {} (keep it secret: it signs images every controller with its public key takes)\n",
                   keyPath);
        fmt::print("public key    {} (for the controllers)\n", publicPath);
        fmt::print("key id        {}\n", id);
    }
    return kExitOk;
}

std::optional<std::string> readText(const std::string& path, std::string& error)
{
    const std::optional<std::vector<uint8_t>> bytes = hostimage::readWholeFile(path, error);
    if (!bytes) {
        return std::nullopt;
    }
    return std::string(bytes->begin(), bytes->end());
}

struct SignOptions {
    std::string key;
    std::string board;
    std::string version;
    std::string output;
    std::string input;
};

int sign(const SignOptions& options, bool json)
{
    image::BoardType board{};
    if (!image::boardFromName(options.board.c_str(), board)) {
        return fail(kExitUsage, fmt::format("unknown board '{}' (boards: isa486)", options.board));
    }
    image::ImageVersion version;
    if (!image::ImageVersion::parse(options.version.c_str(), version)) {
        return fail(kExitUsage, fmt::format("version '{}' is not MAJOR.MINOR.PATCH[+BUILD] "
                                            "(major and minor 0 to 255, patch 0 to 65535)",
                                            options.version));
    }
    std::string error;
    const std::optional<std::string> pem = readText(options.key, error);
    if (!pem) {
        return fail(kExitFile, error);
    }
    const std::optional<hostimage::SigningKey> key = hostimage::SigningKey::fromPem(*pem, error);
    if (!key) {
        return fail(kExitKey, fmt::format("{}: {}", options.key, error));
    }
    const std::optional<std::vector<uint8_t>> elf = hostimage::readWholeFile(options.input, error);
    if (!elf) {
        return fail(kExitFile, error);
    }
    const std::optional<hostimage::ElfPayload> payload = hostimage::ElfPayload::fromElf(*elf, error);
    if (!payload) {
        return fail(kExitRefused, fmt::format("{}: {}", options.input, error));
    }
    const std::optional<std::vector<uint8_t>> signedImage =
        hostimage::ImageSigner::sign(*payload, board, version, *key, error);
    if (!signedImage) {
        return fail(kExitKey, error);
    }
    // The policy the board's controllers apply, so that an image they would
    // refuse for its size or addresses is refused here, not after a transfer.
    const image::TrustedKey trusted = hostimage::trustedKeyOf(key->publicPoint());
    const image::ImageResult<image::ImageHeader> check = image::ImageVerifier::verify(
        signedImage->data(), signedImage->size(), &trusted, 1, image::ImagePolicy::forBoard(board));
    if (!check.ok()) {
        return fail(kExitRefused, fmt::format("{}: {}", options.input, image::imageErrorText(check.error())));
    }
    if (!hostimage::writeWholeFile(options.output, signedImage->data(), signedImage->size(), false, true, error)) {
        return fail(kExitFile, error);
    }
    if (json) {
        nlohmann::json out = headerJson(check.value());
        out["image"] = options.output;
        out["image_size"] = signedImage->size();
        fmt::print("{}\n", out.dump());
    } else {
        fmt::print("image         {} ({} bytes)\n", options.output, signedImage->size());
        printHeader(check.value());
    }
    return kExitOk;
}

struct VerifyOptions {
    std::vector<std::string> keys;
    std::string installed;
    bool allowDowngrade = false;
    std::string input;
};

int verify(const VerifyOptions& options, bool json)
{
    image::ImageVersion installed;
    if (!options.installed.empty() && !image::ImageVersion::parse(options.installed.c_str(), installed)) {
        return fail(kExitUsage, fmt::format("installed version '{}' is not MAJOR.MINOR.PATCH[+BUILD]",
                                            options.installed));
    }
    std::string error;
    std::vector<image::TrustedKey> keys;
    for (const std::string& path : options.keys) {
        bool unreadable = false;
        const std::optional<hostimage::SigningKey::PublicPoint> point = hostimage::readPublicKey(path, error, unreadable);
        if (!point) {
            return fail(unreadable ? kExitFile : kExitKey, error);
        }
        keys.push_back(hostimage::trustedKeyOf(*point));
    }
    const std::optional<std::vector<uint8_t>> bytes = hostimage::readWholeFile(options.input, error);
    if (!bytes) {
        return fail(kExitFile, error);
    }
    // The board is the image's own: a controller checks it against itself,
    // and this tool checks everything else as that controller would.
    const image::ImageResult<image::ImageHeader> header = image::ImageHeader::decode(bytes->data(), bytes->size());
    image::ImagePolicy policy = image::ImagePolicy::forBoard(header.ok() ? header.value().board
                                                                           : image::BoardType::Isa486);
    policy.installed = options.installed.empty() ? nullptr : &installed;
    policy.allowDowngrade = options.allowDowngrade;
    const image::ImageResult<image::ImageHeader> result =
        image::ImageVerifier::verify(bytes->data(), bytes->size(), keys.data(), keys.size(), policy);
    if (json) {
        nlohmann::json out = result.ok() ? headerJson(result.value()) : nlohmann::json::object();
        out["image"] = options.input;
        out["valid"] = result.ok();
        if (!result.ok()) {
            out["reason"] = image::imageErrorText(result.error());
        }
        fmt::print("{}\n", out.dump());
    } else if (result.ok()) {
        fmt::print("{}: valid, {} {} signed by key {}\n", options.input, image::boardName(result.value().board),
                   hostimage::versionText(result.value().version),
                   hostimage::hexText(result.value().keyId, sizeof result.value().keyId));
    } else {
        fmt::print(stderr, "dcos-image: {}: refused: {}\n", options.input, image::imageErrorText(result.error()));
    }
    return result.ok() ? kExitOk : kExitRefused;
}

int info(const std::string& path, bool json)
{
    std::string error;
    const std::optional<std::vector<uint8_t>> bytes = hostimage::readWholeFile(path, error);
    if (!bytes) {
        return fail(kExitFile, error);
    }
    const image::ImageResult<image::ImageHeader> header = image::ImageHeader::decode(bytes->data(), bytes->size());
    if (!header.ok()) {
        return fail(kExitRefused, fmt::format("{}: {}", path, image::imageErrorText(header.error())));
    }
    // What can be told without a key: whether the payload is complete and
    // matches the header. Only verify tells whether the header is genuine.
    const image::ImageError payload = image::ImageVerifier::checkPayload(
        header.value(), bytes->data() + image::ImageHeader::kSize, bytes->size() - image::ImageHeader::kSize);
    if (json) {
        nlohmann::json out = headerJson(header.value());
        out["image"] = path;
        out["image_size"] = bytes->size();
        out["payload_matches"] = payload == image::ImageError::Ok;
        fmt::print("{}\n", out.dump());
    } else {
        fmt::print("image         {} ({} bytes)\n", path, bytes->size());
        printHeader(header.value());
        fmt::print("payload check {}\n", payload == image::ImageError::Ok
                                             ? "matches the header (verify checks the signature)"
                                             : image::imageErrorText(payload));
    }
    return kExitOk;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"dcos-image: make and check signed DCOS controller images", "dcos-image"};
    app.set_version_flag("--version", std::string("dcos-image ") + dcos::versionString);
    app.require_subcommand(1);
    app.footer("exit status: 0 done (verify: valid), 1 image refused, 2 bad arguments, "
               "3 file not readable or writable, 4 key or cryptography failure");
    bool json = false;
    app.add_flag("--json", json, "machine-readable output: one JSON object");

    std::string keyPath;
    std::string publicPath;
    bool force = false;
    CLI::App* keygenCommand = app.add_subcommand("keygen", "generate an ECDSA P-256 signing key");
    keygenCommand->add_option("-o,--output", keyPath, "the private key's PEM file (written mode 0600)")->required();
    keygenCommand->add_option("--public", publicPath, "the public key's PEM file (default: the private key's name + .pub)");
    keygenCommand->add_flag("--force", force, "replace existing key files");

    SignOptions signOptions;
    CLI::App* signCommand = app.add_subcommand("sign", "make a signed image from a linked firmware ELF file");
    signCommand->add_option("-k,--key", signOptions.key, "the private key's PEM file")->required();
    signCommand->add_option("--board", signOptions.board, "the board the image is for: isa486")->required();
    signCommand->add_option("--version", signOptions.version, "the image's version, MAJOR.MINOR.PATCH[+BUILD]")
        ->required();
    signCommand->add_option("-o,--output", signOptions.output, "the image file to write")->required();
    signCommand->add_option("firmware", signOptions.input, "the firmware's ELF file")->required();

    VerifyOptions verifyOptions;
    CLI::App* verifyCommand = app.add_subcommand("verify", "check an image as a controller does");
    verifyCommand->add_option("-p,--public", verifyOptions.keys, "a trusted public key's PEM file (repeatable)")
        ->required();
    verifyCommand->add_option("--installed", verifyOptions.installed,
                              "the version the controller runs: an older image is refused");
    verifyCommand->add_flag("--allow-downgrade", verifyOptions.allowDowngrade, "take an image older than --installed");
    verifyCommand->add_option("image", verifyOptions.input, "the image file")->required();

    std::string infoPath;
    CLI::App* infoCommand = app.add_subcommand("info", "show an image's header (no key needed)");
    infoCommand->add_option("image", infoPath, "the image file")->required();

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int code = app.exit(error);
        return code == 0 ? kExitOk : kExitUsage;
    }
    if (*keygenCommand) {
        return keygen(keyPath, publicPath, force, json);
    }
    if (*signCommand) {
        return sign(signOptions, json);
    }
    if (*verifyCommand) {
        return verify(verifyOptions, json);
    }
    return info(infoPath, json);
}
