#include <bsp/ApTrampoline.h>
#include <bsp/SecondProcessor.hpp>

#include <boot/Multiboot.hpp>

#include <string.h>

extern "C" const uint8_t apTrampolineStart[];
extern "C" const uint8_t apTrampolineEnd[];

namespace bsp {

namespace {

// ELF (System V ABI, "Object Files", and its i386 supplement): the fields
// the loader reads, at their offsets in a 32-bit file.
constexpr uint8_t kElfMagic[4] = {0x7F, 'E', 'L', 'F'};
constexpr size_t kClassOffset = 4;
constexpr uint8_t kClass32 = 1;
constexpr size_t kDataOffset = 5;
constexpr uint8_t kLittleEndian = 1;
constexpr size_t kTypeOffset = 16;
constexpr uint16_t kTypeExecutable = 2;
constexpr size_t kMachineOffset = 18;
constexpr uint16_t kMachine386 = 3;
constexpr size_t kEntryOffset = 24;
constexpr size_t kProgramHeaderOffset = 28;
constexpr size_t kProgramHeaderSizeOffset = 42;
constexpr size_t kProgramHeaderCountOffset = 44;
constexpr size_t kHeaderBytes = 52;
constexpr uint16_t kProgramHeaderBytes = 32;
constexpr uint32_t kSegmentLoad = 1;
// Program header fields.
constexpr size_t kSegmentType = 0;
constexpr size_t kSegmentFileOffset = 4;
constexpr size_t kSegmentPhysical = 12;
constexpr size_t kSegmentFileBytes = 16;
constexpr size_t kSegmentMemoryBytes = 20;
// An image has a handful of segments; more is not an image of ours.
constexpr uint16_t kMaximumSegments = 16;

uint16_t read16(const uint8_t* at)
{
    uint16_t value;
    memcpy(&value, at, sizeof value);
    return value;
}

uint32_t read32(const uint8_t* at)
{
    uint32_t value;
    memcpy(&value, at, sizeof value);
    return value;
}

struct Segment {
    uint32_t fileOffset;
    uint32_t physical;
    uint32_t fileBytes;
    uint32_t memoryBytes;
};

// The segment at @p index, checked against the file and node 3's memory;
// false for a loadable segment that does not fit. @p load says whether it is one.
bool segmentAt(const uint8_t* image, size_t bytes, uint32_t headers, uint16_t index, uint32_t memoryEnd,
               Segment& segment, bool& load)
{
    const uint8_t* header = image + headers + uint32_t{index} * kProgramHeaderBytes;
    load = read32(header + kSegmentType) == kSegmentLoad;
    segment = {read32(header + kSegmentFileOffset), read32(header + kSegmentPhysical),
               read32(header + kSegmentFileBytes), read32(header + kSegmentMemoryBytes)};
    if (!load) {
        return true;
    }
    return segment.fileBytes <= segment.memoryBytes && segment.fileOffset <= bytes &&
           segment.fileBytes <= bytes - segment.fileOffset && segment.physical >= SecondProcessor::kNodeBase &&
           segment.physical < memoryEnd && segment.memoryBytes <= memoryEnd - segment.physical;
}

} // namespace

const char* SecondProcessor::describe(Outcome outcome)
{
    switch (outcome) {
    case Outcome::Started: return "started";
    case Outcome::NoImage: return "this image carries no node 3 image";
    case Outcome::BadImage: return "node 3's image is not a 32-bit i386 executable that fits its memory";
    case Outcome::NoMemory: return "the board has too little memory for node 3";
    case Outcome::NoDelivery: return "the local APIC could not deliver the start-up interrupts";
    case Outcome::NoAnswer: return "the second processor did not answer STARTUP";
    }
    return "unknown";
}

SecondProcessor::Outcome SecondProcessor::load(const uint8_t* image, size_t bytes, uint32_t memoryEnd, uint32_t& entry)
{
    if (image == nullptr || bytes == 0) {
        return Outcome::NoImage;
    }
    if (memoryEnd < kMinimumMemoryEnd) {
        return Outcome::NoMemory;
    }
    if (bytes < kHeaderBytes || memcmp(image, kElfMagic, sizeof kElfMagic) != 0 || image[kClassOffset] != kClass32 ||
        image[kDataOffset] != kLittleEndian || read16(image + kTypeOffset) != kTypeExecutable ||
        read16(image + kMachineOffset) != kMachine386 ||
        read16(image + kProgramHeaderSizeOffset) != kProgramHeaderBytes) {
        return Outcome::BadImage;
    }
    const uint32_t headers = read32(image + kProgramHeaderOffset);
    const uint16_t count = read16(image + kProgramHeaderCountOffset);
    if (count == 0 || count > kMaximumSegments || headers > bytes ||
        uint32_t{count} * kProgramHeaderBytes > bytes - headers) {
        return Outcome::BadImage;
    }
    // Every check first, so that a bad image writes nothing.
    entry = read32(image + kEntryOffset);
    bool entryInside = false;
    for (uint16_t i = 0; i < count; ++i) {
        Segment segment{};
        bool loadable = false;
        if (!segmentAt(image, bytes, headers, i, memoryEnd, segment, loadable)) {
            return Outcome::BadImage;
        }
        if (loadable && entry >= segment.physical && entry - segment.physical < segment.fileBytes) {
            entryInside = true;
        }
    }
    if (!entryInside) {
        return Outcome::BadImage;
    }
    for (uint16_t i = 0; i < count; ++i) {
        Segment segment{};
        bool loadable = false;
        (void)segmentAt(image, bytes, headers, i, memoryEnd, segment, loadable);
        if (!loadable) {
            continue;
        }
        auto* to = reinterpret_cast<uint8_t*>(static_cast<uintptr_t>(segment.physical));
        memcpy(to, image + segment.fileOffset, segment.fileBytes);
        memset(to + segment.fileBytes, 0, segment.memoryBytes - segment.fileBytes);
    }
    return Outcome::Started;
}

SecondProcessor::Outcome SecondProcessor::start(const LocalApic& localApic, const Launch& launch,
                                                uint32_t answerMicroseconds)
{
    // The start-up code and its parameters, and node 3's Multiboot
    // information and command line, in the page the STARTUP vector names.
    auto* page = reinterpret_cast<uint8_t*>(uintptr_t{AP_TRAMPOLINE_BASE});
    const size_t codeBytes = static_cast<size_t>(apTrampolineEnd - apTrampolineStart);
    static_assert(AP_TRAMPOLINE_MULTIBOOT_INFO >= AP_TRAMPOLINE_INFO + 4);
    memcpy(page, apTrampolineStart, codeBytes);
    boot::multiboot::Info info{};
    info.flags = boot::multiboot::kInfoMemory | boot::multiboot::kInfoCommandLine | boot::multiboot::kInfoLoaderName;
    info.memLower = launch.lowerMemoryKib;
    info.memUpper = launch.upperMemoryKib;
    info.cmdline = AP_TRAMPOLINE_BASE + AP_TRAMPOLINE_COMMAND_LINE;
    // Node 3's version report names who started it.
    static constexpr char loaderName[] = "node 2 (second processor start)";
    static_assert(AP_TRAMPOLINE_LOADER_NAME + sizeof loaderName <= 0x1000);
    memcpy(page + AP_TRAMPOLINE_LOADER_NAME, loaderName, sizeof loaderName);
    info.bootLoaderName = AP_TRAMPOLINE_BASE + AP_TRAMPOLINE_LOADER_NAME;
    memcpy(page + AP_TRAMPOLINE_MULTIBOOT_INFO, &info, sizeof info);
    char* commandLine = reinterpret_cast<char*>(page + AP_TRAMPOLINE_COMMAND_LINE);
    size_t length = strlen(launch.commandLine);
    length = length < AP_TRAMPOLINE_COMMAND_LINE_BYTES - 1 ? length : AP_TRAMPOLINE_COMMAND_LINE_BYTES - 1;
    memcpy(commandLine, launch.commandLine, length);
    commandLine[length] = '\0';
    const uint32_t entry = launch.entry;
    const uint32_t infoAddress = AP_TRAMPOLINE_BASE + AP_TRAMPOLINE_MULTIBOOT_INFO;
    memcpy(page + AP_TRAMPOLINE_ENTRY, &entry, sizeof entry);
    memcpy(page + AP_TRAMPOLINE_INFO, &infoAddress, sizeof infoAddress);
    volatile uint32_t* alive = reinterpret_cast<volatile uint32_t*>(page + AP_TRAMPOLINE_ALIVE);
    *alive = 0;

    // MP spec B.4.1 and B.4.2: INIT, 10 ms, then STARTUP, 200 us, and a
    // second STARTUP, which a processor already started ignores.
    constexpr uint32_t kSpins = 100'000;
    if (!localApic.sendInit(launch.apicId, kSpins)) {
        return Outcome::NoDelivery;
    }
    launch.delayMicroseconds(10'000);
    for (unsigned attempt = 0; attempt < 2 && *alive != AP_TRAMPOLINE_ALIVE_MAGIC; ++attempt) {
        if (!localApic.sendStartup(launch.apicId, AP_TRAMPOLINE_PAGE, kSpins)) {
            return Outcome::NoDelivery;
        }
        launch.delayMicroseconds(200);
    }
    for (uint32_t waited = 0; *alive != AP_TRAMPOLINE_ALIVE_MAGIC && waited < answerMicroseconds; waited += 100) {
        launch.delayMicroseconds(100);
    }
    return *alive == AP_TRAMPOLINE_ALIVE_MAGIC ? Outcome::Started : Outcome::NoAnswer;
}

} // namespace bsp
