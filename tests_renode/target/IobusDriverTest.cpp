// The I/O board driver (drivers/iobus) on the emulated board: probe present
// and absent, ISA resource conflicts, interrupt-driven and polled
// conversions, the fallback when the interrupt is missing, gain switching,
// saturation and the overrange flag, and Read and Write through the system
// agent from a user task. The board is the emulator's isa-mfio at 0x300,
// IRQ 5, in loopback (DAC n drives ADC n, DO drives DI); the tests that need
// it absent or faulty are booted so by tests_renode/test_iobus_driver.py.
#include "SpareLine.hpp"
#include "KernelTestSupport.hpp"

#include <iobus/AnalogScaling.hpp>
#include <iobus/IsaResourceManager.hpp>
#include <iobus/MfioBoard.hpp>
#include <iobus/MfioClient.hpp>

#include <dcos/SystemAgent.hpp>

namespace target_test {

namespace {

using dcos::ObjectId;
using dcos::Status;
using dcos::systemAgent;
using iobus::MfioBoard;
namespace channel = iobus::channel;

constexpr uint16_t kBase = 0x300;
constexpr uint8_t kIrq = 5;
constexpr const char* kName = "mfio-test";

// The board object the tests install; one at a time.
MfioBoard testBoard(kName, kBase, kIrq);

// Installs testBoard at base and irq, and opens it unless told not to.
bool installBoard(shell::Shell& shell, uint16_t base = kBase, uint8_t irq = kIrq, bool open = true)
{
    bool ok = checkStatus(shell, testBoard.configure(base, irq), Status::Ok, "configure");
    iobus::IsaConflict conflict;
    const dcos::Result<ObjectId> id = testBoard.install(kName, dcos::Visibility::Regional, &conflict);
    ok = checkStatus(shell, id.status(), Status::Ok, "install") && ok;
    if (ok && open) {
        ok = checkStatus(shell, systemAgent.Open(id.value()), Status::Ok, "Open") && ok;
    }
    return ok;
}

bool uninstallBoard(shell::Shell& shell)
{
    while (systemAgent.Close(testBoard.id()) == Status::Ok) {
    }
    bool ok = checkStatus(shell, testBoard.uninstall(), Status::Ok, "uninstall");
    ok = check(shell, iobus::isaResources().release(kName) == 0, "uninstall released the resources") && ok;
    return ok;
}

iobus::BoardStatistics statisticsOf(ObjectId id)
{
    iobus::BoardStatistics statistics{};
    (void)systemAgent.Control(id, MfioBoard::kGetStatistics, &statistics, sizeof statistics);
    return statistics;
}

Status setMode(ObjectId id, iobus::ConversionMode mode)
{
    uint32_t value = static_cast<uint32_t>(mode);
    return systemAgent.Control(id, MfioBoard::kSetMode, &value, sizeof value);
}

// Writes a DAC and converts the same channel; returns the ADC_DATA word or 0xFFFF.
uint16_t loop(shell::Shell& shell, ObjectId id, unsigned input, uint16_t dac)
{
    if (iobus::writeWord(id, channel::kAnalogOutput0 + input, dac) != Status::Ok) {
        shell.print("  cannot write AO%u\r\n", input);
        return 0xFFFF;
    }
    const dcos::Result<uint16_t> word = iobus::readAnalogInput(id, input);
    if (!word.ok()) {
        shell.print("  AI%u: %s\r\n", input, dcos::statusName(word.status()));
        return 0xFFFF;
    }
    return word.value();
}

bool expectCode(shell::Shell& shell, uint16_t word, uint16_t code, bool overrange, const char* what)
{
    const bool ok = (word & iobus::mfio::kAdcDataCodeMask) == code &&
                    ((word & iobus::mfio::kAdcDataOverrange) != 0) == overrange;
    shell.print("  %s: ADC_DATA 0x%04x, expected code %u%s\r\n", what, word, code, overrange ? " overrange" : "");
    return check(shell, ok, what);
}

// Probe of the board that is there, and of an empty slot.
bool probePresent(shell::Shell& shell)
{
    bool ok = installBoard(shell, kBase, kIrq, false);
    ok = checkStatus(shell, systemAgent.Probe(testBoard.id()), Status::Ok, "Probe at 0x300") && ok;
    ok = checkStatus(shell, systemAgent.Open(testBoard.id()), Status::Ok, "Open") && ok;
    iobus::BoardInfo info{};
    ok = checkStatus(shell, systemAgent.Control(testBoard.id(), MfioBoard::kGetInfo, &info, sizeof info), Status::Ok,
                     "kGetInfo") && ok;
    shell.print("  id 0x%04x revision 0x%04x base 0x%03x irq %u\r\n", info.id, info.revision, info.base, info.irq);
    ok = check(shell, info.id == 0x4D46 && info.revision == 0x0100 && info.present == 1, "identity") && ok;
    ok = uninstallBoard(shell) && ok;
    // No board decodes 0x280 on this machine: the bus floats high.
    // On a spare line: line 7 is node 3's console on the dual-Pentium board.
    ok = installBoard(shell, 0x280, static_cast<uint8_t>(target_test::spareLine(1)), false) && ok;
    ok = checkStatus(shell, systemAgent.Probe(testBoard.id()), Status::NotFound, "Probe of an empty slot") && ok;
    ok = checkStatus(shell, systemAgent.Open(testBoard.id()), Status::NotFound, "Open of an empty slot") && ok;
    ok = uninstallBoard(shell) && ok;
    return ok;
}

DCOS_TARGET_TEST(iobusProbeTest, "iobusprobe", "I/O board driver: probe finds the board at 0x300, not an empty slot",
                 probePresent);

// Run with the board left out of the machine.
bool probeAbsent(shell::Shell& shell)
{
    bool ok = installBoard(shell, kBase, kIrq, false);
    ok = checkStatus(shell, systemAgent.Probe(testBoard.id()), Status::NotFound, "Probe without a board") && ok;
    ok = checkStatus(shell, systemAgent.Open(testBoard.id()), Status::NotFound, "Open without a board") && ok;
    uint16_t word = 0;
    ok = checkStatus(shell, systemAgent.Read(testBoard.id(), 0, &word, sizeof word).status(), Status::NotOpen,
                     "Read of a board that could not be opened") && ok;
    ok = uninstallBoard(shell) && ok;
    return ok;
}

DCOS_TARGET_TEST(iobusAbsentTest, "iobusabsent", "I/O board driver: no board at 0x300 fails cleanly (run without it)",
                 probeAbsent);

bool conflicts(shell::Shell& shell)
{
    char text[96];
    iobus::IsaConflict conflict;
    bool ok = checkStatus(shell, testBoard.configure(0x3F8, kIrq), Status::Ok, "configure at COM1's ports");
    ok = checkStatus(shell, testBoard.install(kName, dcos::Visibility::Local, &conflict).status(),
                     Status::AlreadyExists, "install over COM1") && ok;
    iobus::IsaResourceManager::describe(conflict, text, sizeof text);
    shell.print("  %s\r\n", text);
    ok = check(shell, conflict.heldBy[0] == 'c' && conflict.held.first == 0x3F8, "held by com1") && ok;
    ok = checkStatus(shell, testBoard.configure(kBase, 4), Status::Ok, "configure on COM1's line") && ok;
    ok = checkStatus(shell, testBoard.install(kName, dcos::Visibility::Local, &conflict).status(),
                     Status::AlreadyExists, "install on IRQ 4") && ok;
    iobus::IsaResourceManager::describe(conflict, text, sizeof text);
    shell.print("  %s\r\n", text);
    ok = check(shell, conflict.irq && conflict.heldLine == 4, "IRQ 4 held by com1") && ok;
    ok = check(shell, !testBoard.installed() && iobus::isaResources().release(kName) == 0,
               "a refused install reserves nothing") && ok;
    // Two boards set to overlapping switches.
    ok = installBoard(shell, kBase, kIrq, false) && ok;
    static MfioBoard second("mfio-second", 0x320, 9);
    ok = checkStatus(shell, second.install("second", dcos::Visibility::Local, &conflict).status(),
                     Status::AlreadyExists, "a second board over the first") && ok;
    iobus::IsaResourceManager::describe(conflict, text, sizeof text);
    shell.print("  %s\r\n", text);
    static constexpr char kExpected[] = "ports 0x320-0x35f wanted by mfio-second are held by mfio-test (0x300-0x33f)";
    bool same = true;
    for (size_t i = 0; i < sizeof kExpected; ++i) {
        same = same && text[i] == kExpected[i];
    }
    ok = check(shell, same, "the message names both claimants") && ok;
    ok = uninstallBoard(shell) && ok;
    return ok;
}

DCOS_TARGET_TEST(iobusConflictTest, "iobusconflict", "I/O board driver: ISA port and IRQ conflicts name both claimants",
                 conflicts);

bool interruptConversions(shell::Shell& shell)
{
    bool ok = installBoard(shell);
    const ObjectId id = testBoard.id();
    constexpr uint16_t kCodes[] = {0x000, 0x123, 0x800, 0xABC, 0xFFE};
    unsigned conversions = 0;
    for (unsigned input = 0; input < 8; ++input) {
        for (const uint16_t code : kCodes) {
            const uint16_t word = loop(shell, id, input, code);
            ++conversions;
            const bool exact = (word & 0x0FFF) == code && ((word >> 12) & 7) == input;
            if (!exact) {
                shell.print("  AI%u: DAC 0x%03x read 0x%04x\r\n", input, code, word);
            }
            ok = check(shell, exact, "loopback code and channel") && ok;
        }
    }
    const iobus::BoardStatistics statistics = statisticsOf(id);
    shell.print("  %u conversions: %lu interrupts, %lu missed, %lu spurious\r\n", conversions,
                static_cast<unsigned long>(statistics.interrupts), static_cast<unsigned long>(statistics.missedInterrupts),
                static_cast<unsigned long>(statistics.spuriousInterrupts));
    ok = check(shell, statistics.interrupts == conversions, "one interrupt per conversion") && ok;
    ok = check(shell, statistics.missedInterrupts == 0 && statistics.fallbacks == 0, "no interrupt missed") && ok;
    ok = check(shell, statistics.lastInterruptNs >= statistics.lastStartNs + 20000 &&
                          statistics.lastInterruptNs < statistics.lastStartNs + 1000000,
               "the interrupt comes after the 20 us conversion") && ok;
    ok = uninstallBoard(shell) && ok;
    return ok;
}

DCOS_TARGET_TEST(iobusIrqTest, "iobusirq", "I/O board driver: interrupt-driven conversions on every channel",
                 interruptConversions);

bool polledConversions(shell::Shell& shell)
{
    bool ok = installBoard(shell);
    const ObjectId id = testBoard.id();
    ok = checkStatus(shell, setMode(id, iobus::ConversionMode::Polled), Status::Ok, "polled mode") && ok;
    for (unsigned input = 0; input < 8; ++input) {
        const uint16_t code = static_cast<uint16_t>(0x100 + 0x1F0 * input);
        uint16_t word = 0;
        ok = checkStatus(shell, iobus::writeWord(id, channel::kAnalogOutput0 + input, code), Status::Ok, "AO write") && ok;
        const dcos::Result<size_t> read = systemAgent.Read(id, channel::kAnalogInput0 + input, &word, sizeof word);
        ok = check(shell, read.ok() && read.value() == 2, "a polled Read returns the result at once") && ok;
        ok = check(shell, (word & 0x0FFF) == code, "polled loopback code") && ok;
    }
    const iobus::BoardStatistics statistics = statisticsOf(id);
    shell.print("  8 polled conversions, %lu interrupts\r\n", static_cast<unsigned long>(statistics.interrupts));
    ok = check(shell, statistics.interrupts == 0 && statistics.conversions == 8, "no interrupt in polled mode") && ok;
    ok = uninstallBoard(shell) && ok;
    return ok;
}

DCOS_TARGET_TEST(iobusPollTest, "iobuspoll", "I/O board driver: polled conversions", polledConversions);

// Run with the model's no-irq fault: conversions complete, the line stays quiet.
bool missingInterrupt(shell::Shell& shell)
{
    bool ok = installBoard(shell);
    const ObjectId id = testBoard.id();
    const uint16_t word = loop(shell, id, 4, 0x9AB);
    ok = check(shell, (word & 0x0FFF) == 0x9AB, "the result arrives by polling") && ok;
    const iobus::BoardStatistics statistics = statisticsOf(id);
    uint32_t mode = 0;
    (void)systemAgent.Control(id, MfioBoard::kGetMode, &mode, sizeof mode);
    shell.print("  interrupts %lu, missed %lu, fallbacks %lu, mode %s\r\n",
                static_cast<unsigned long>(statistics.interrupts), static_cast<unsigned long>(statistics.missedInterrupts),
                static_cast<unsigned long>(statistics.fallbacks), mode == 1 ? "polled" : "interrupt");
    ok = check(shell, statistics.missedInterrupts == 1 && statistics.fallbacks == 1 && mode == 1,
               "one missed interrupt, then polled mode") && ok;
    ok = check(shell, (loop(shell, id, 5, 0x456) & 0x0FFF) == 0x456, "later reads are polled") && ok;
    ok = check(shell, statisticsOf(id).missedInterrupts == 1, "and miss nothing more") && ok;
    ok = uninstallBoard(shell) && ok;
    return ok;
}

DCOS_TARGET_TEST(iobusFallbackTest, "iobusfallback",
                 "I/O board driver: a missing interrupt falls back to polling (run with no-irq)", missingInterrupt);

bool gainSwitching(shell::Shell& shell)
{
    bool ok = installBoard(shell);
    const ObjectId id = testBoard.id();
    // DAC 2049 is +4.88 mV: 2048 + gain codes at the converter.
    struct Step {
        uint32_t factor;
        uint16_t code;
    };
    constexpr Step kSteps[] = {{1, 2049}, {10, 2058}, {100, 2148}, {1000, 3048}, {1, 2049}};
    for (const Step& step : kSteps) {
        ok = checkStatus(shell, iobus::setGain(id, 6, step.factor), Status::Ok, "setGain") && ok;
        ok = expectCode(shell, loop(shell, id, 6, 2049), step.code, false, "AI6 at DAC 2049") && ok;
    }
    // Gains are per channel.
    ok = checkStatus(shell, iobus::setGain(id, 0, 1000), Status::Ok, "AI0 x1000") && ok;
    ok = checkStatus(shell, iobus::setGain(id, 1, 10), Status::Ok, "AI1 x10") && ok;
    ok = expectCode(shell, loop(shell, id, 0, 2047), 1048, false, "AI0 x1000 at DAC 2047") && ok;
    ok = expectCode(shell, loop(shell, id, 1, 2047), 2038, false, "AI1 x10 at DAC 2047") && ok;
    iobus::GainSetting setting{0, 0};
    ok = checkStatus(shell, systemAgent.Control(id, MfioBoard::kGetGain, &setting, sizeof setting), Status::Ok,
                     "kGetGain") && ok;
    ok = check(shell, setting.gain == 1000, "AI0 reads back x1000") && ok;
    ok = checkStatus(shell, iobus::setGain(id, 0, 20), Status::InvalidArgument, "gain 20") && ok;
    const dcos::Result<iobus::AnalogValue> value = iobus::readAnalogInputMicrovolts(id, 0);
    ok = check(shell, value.ok() && value.value().microvolts == -4883, "AI0 is -4883 uV") && ok;
    ok = uninstallBoard(shell) && ok;
    return ok;
}

DCOS_TARGET_TEST(iobusGainTest, "iobusgain", "I/O board driver: gain switching per channel", gainSwitching);

bool saturation(shell::Shell& shell)
{
    bool ok = installBoard(shell);
    const ObjectId id = testBoard.id();
    ok = checkStatus(shell, iobus::setGain(id, 2, 1000), Status::Ok, "AI2 x1000") && ok;
    ok = expectCode(shell, loop(shell, id, 2, 2060), 4095, true, "+58 mV at x1000") && ok;
    ok = expectCode(shell, loop(shell, id, 2, 2030), 0, true, "-88 mV at x1000") && ok;
    ok = expectCode(shell, loop(shell, id, 2, 2050), 4048, false, "+9.8 mV at x1000") && ok;
    ok = checkStatus(shell, iobus::setGain(id, 2, 100), Status::Ok, "AI2 x100") && ok;
    ok = expectCode(shell, loop(shell, id, 2, 2100), 4095, true, "+254 mV at x100") && ok;
    const dcos::Result<iobus::AnalogValue> value = iobus::readAnalogInputMicrovolts(id, 2);
    ok = check(shell, value.ok() && value.value().overrange, "the scaled value says overrange") && ok;
    ok = checkStatus(shell, iobus::setGain(id, 2, 1), Status::Ok, "AI2 x1") && ok;
    ok = expectCode(shell, loop(shell, id, 2, 2100), 2100, false, "+254 mV at x1") && ok;
    ok = check(shell, statisticsOf(id).overranges == 4, "four overranges counted") && ok;
    ok = uninstallBoard(shell) && ok;
    return ok;
}

DCOS_TARGET_TEST(iobusOverrangeTest, "iobusoverrange", "I/O board driver: saturation and the overrange flag",
                 saturation);

// What the user task saw.
struct UserResults {
    Status found;
    Status opened;
    Status wroteDac;
    Status wroteDo;
    uint16_t digitalInputs;
    uint16_t dacReadBack;
    uint16_t analogInput;
    Status readInput;
    Status closed;
    Status createRefused;
};

UserResults userResults;

void userTaskEntry(uintptr_t)
{
    UserResults& r = userResults;
    const dcos::Result<ObjectId> id = systemAgent.NameToObject(kName);
    r.found = id.status();
    if (id.ok()) {
        r.opened = systemAgent.Open(id.value());
        r.wroteDac = iobus::writeWord(id.value(), channel::kAnalogOutput0 + 3, 0xC0D);
        r.wroteDo = iobus::writeWord(id.value(), channel::kDigitalOutputs, 0xA5C3);
        const dcos::Result<uint16_t> di = iobus::readWord(id.value(), channel::kDigitalInputs);
        r.digitalInputs = di.ok() ? di.value() : 0;
        const dcos::Result<uint16_t> ao = iobus::readWord(id.value(), channel::kAnalogOutput0 + 3);
        r.dacReadBack = ao.ok() ? ao.value() : 0;
        const dcos::Result<uint16_t> ai = iobus::readAnalogInput(id.value(), 3);
        r.readInput = ai.status();
        r.analogInput = ai.ok() ? ai.value() : 0;
        r.closed = systemAgent.Close(id.value());
    }
    static MfioBoard userBoard("mfio-user", 0x340, 10);
    r.createRefused = userBoard.install("user", dcos::Visibility::Local, nullptr).status();
    finished();
}

bool userTask(shell::Shell& shell)
{
    bool ok = installBoard(shell, kBase, kIrq, false);
    userResults = UserResults{};
    spawn("iobus-user", 20, userTaskEntry);
    ok = waitForDone(shell, 1) && ok;
    const UserResults& r = userResults;
    shell.print("  user task: DI 0x%04x, AO3 0x%03x, AI3 0x%04x\r\n", r.digitalInputs, r.dacReadBack, r.analogInput);
    ok = checkStatus(shell, r.found, Status::Ok, "NameToObject") && ok;
    ok = checkStatus(shell, r.opened, Status::Ok, "Open from a user task") && ok;
    ok = checkStatus(shell, r.wroteDac, Status::Ok, "Write AO3") && ok;
    ok = checkStatus(shell, r.wroteDo, Status::Ok, "Write DO") && ok;
    ok = check(shell, r.digitalInputs == 0xA5C3, "DI follows DO") && ok;
    ok = check(shell, r.dacReadBack == 0xC0D, "AO3 reads back") && ok;
    ok = checkStatus(shell, r.readInput, Status::Ok, "Read AI3 (interrupt driven, waited for)") && ok;
    ok = check(shell, (r.analogInput & 0x0FFF) == 0xC0D, "AI3 follows AO3") && ok;
    ok = checkStatus(shell, r.closed, Status::Ok, "Close") && ok;
    ok = checkStatus(shell, r.createRefused, Status::NotPermitted, "a user task cannot install a driver") && ok;
    ok = check(shell, iobus::isaResources().release("mfio-user") == 0, "its refused install reserved nothing") && ok;
    ok = uninstallBoard(shell) && ok;
    return ok;
}

DCOS_TARGET_TEST(iobusUserTest, "iobususer", "I/O board driver: Read and Write through the system agent from a user task",
                 userTask);

} // namespace

} // namespace target_test
