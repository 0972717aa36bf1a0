// Prints far more than the console's transmit ring holds, in a pattern the
// harness checks byte for byte, to show that output waits rather than drops.
#include "TargetTest.hpp"

#include <bsp/Uart16550.hpp>

namespace {

constexpr unsigned lineCount = 64;
constexpr unsigned lineLength = 70;

bool floodConsole(shell::Shell& shell)
{
    static_assert(lineCount * lineLength > 4 * bsp::Uart16550::transmitRingSize,
                  "the flood must exceed the transmit ring several times");
    for (unsigned line = 0; line < lineCount; ++line) {
        shell.print("%04u:", line);
        for (unsigned column = 5; column < lineLength; ++column) {
            shell.output().put(static_cast<char>('A' + (line + column) % 26));
        }
        shell.print("\r\n");
    }
    return true;
}

} // namespace

DCOS_TARGET_TEST(consoleFloodTest, "txflood", "print 4480 characters in a checkable pattern", floodConsole);
