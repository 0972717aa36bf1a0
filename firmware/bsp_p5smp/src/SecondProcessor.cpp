#include <bsp/ApTrampoline.h>
#include <bsp/ElfImage.hpp>
#include <bsp/SecondProcessor.hpp>

#include <boot/Multiboot.hpp>

#include <string.h>

extern "C" const uint8_t apTrampolineStart[];
extern "C" const uint8_t apTrampolineEnd[];

namespace bsp {

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
    // Every check first, so that a bad image writes nothing.
    if (!ElfImage::check(image, bytes, kNodeBase, memoryEnd, entry)) {
        return Outcome::BadImage;
    }
    ElfImage::forEachLoadable(image, [image](const ElfImage::Segment& segment) {
        auto* to = reinterpret_cast<uint8_t*>(static_cast<uintptr_t>(segment.physical));
        memcpy(to, image + segment.fileOffset, segment.fileBytes);
        memset(to + segment.fileBytes, 0, segment.memoryBytes - segment.fileBytes);
    });
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
