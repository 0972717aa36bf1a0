// Starts node 3 on the dual-Pentium board's second processor (seed 9.2):
// node 3's kernel image is loaded into the upper half of the board's memory
// and the processor is sent through INIT and STARTUP inter-processor
// interrupts (MP spec, appendix B.4) to the start-up code (ApTrampoline.S),
// which enters protected mode and calls the image's Multiboot entry with
// the information a loader would give it. From there node 3 is a node of
// its own: its own kernel, tables, stacks, tick and console.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <bsp/LocalApic.hpp>

namespace bsp {

class SecondProcessor {
public:
    /// Where node 3 lives: its image is linked at 16 MiB (mk/board_p5smp.mk),
    /// and the board needs at least this much memory for it.
    static constexpr uint32_t kNodeBase = 0x0100'0000u;
    static constexpr uint32_t kMinimumMemoryEnd = kNodeBase + 0x0080'0000u;

    /// Why node 3 did not start, or Started.
    enum class Outcome : uint8_t { Started, NoImage, BadImage, NoMemory, NoDelivery, NoAnswer };
    /// A sentence for the boot report.
    static const char* describe(Outcome outcome);

    /// Checks the ELF image at [@p image, @p image + @p bytes) (32-bit,
    /// i386, executable; every loadable segment within [kNodeBase,
    /// @p memoryEnd) and within the file; the entry inside a segment) and
    /// copies its segments into place, zeroing what the file leaves out.
    /// Nothing is written unless every check passes. Sets @p entry.
    static Outcome load(const uint8_t* image, size_t bytes, uint32_t memoryEnd, uint32_t& entry);

    /// What start() needs beside the loaded image.
    struct Launch {
        uint32_t entry;              ///< node 3's Multiboot entry
        uint8_t apicId;              ///< the second processor's APIC id
        uint32_t lowerMemoryKib;     ///< for node 3's Multiboot information
        uint32_t upperMemoryKib;
        const char* commandLine;     ///< node 3's kernel command line
        void (*delayMicroseconds)(uint32_t microseconds);
    };

    /// Copies the start-up code and its parameters below 1 MiB, sends INIT,
    /// waits 10 ms, sends STARTUP twice 200 us apart as the MP spec's
    /// universal algorithm does, and waits at most @p answerMicroseconds for
    /// the processor to report from protected mode.
    static Outcome start(const LocalApic& localApic, const Launch& launch, uint32_t answerMicroseconds);
};

} // namespace bsp
