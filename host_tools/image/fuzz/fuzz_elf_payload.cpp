// Fuzz target: the ELF reader of dcos-image sign (host_tools/image), which
// takes whatever file the user names as firmware.
//
// The input is the file. Checks: a payload read from it has at least one
// byte and stays within the limits; its memory holds the payload and ends
// at or below 4 GiB; the entry lies within the payload; and the payload
// signs into an image whose header decodes (the image format can describe
// every payload the reader gives).
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <hostimage/ElfPayload.hpp>

#include <image/ImageHeader.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const std::vector<uint8_t> file(data, data + size);
    std::string error;
    const std::optional<hostimage::ElfPayload> payload = hostimage::ElfPayload::fromElf(file, error);
    if (!payload) {
        FUZZ_CHECK(!error.empty());
        return 0;
    }
    const size_t bytes = payload->bytes().size();
    FUZZ_CHECK(bytes > 0 && bytes <= hostimage::ElfPayload::kMaximumPayload);
    FUZZ_CHECK(payload->memorySize() >= bytes && payload->memorySize() <= hostimage::ElfPayload::kMaximumMemory);
    FUZZ_CHECK(uint64_t{payload->loadAddress()} + payload->memorySize() <= (uint64_t{1} << 32));
    FUZZ_CHECK(payload->entry() >= payload->loadAddress() && payload->entry() - payload->loadAddress() < bytes);

    image::ImageHeader header;
    header.payloadSize = static_cast<uint32_t>(bytes);
    header.memorySize = payload->memorySize();
    header.loadAddress = payload->loadAddress();
    header.entry = payload->entry();
    uint8_t encoded[image::ImageHeader::kSize];
    header.encode(encoded);
    FUZZ_CHECK(image::ImageHeader::decode(encoded, sizeof encoded).ok());
    return 0;
}
