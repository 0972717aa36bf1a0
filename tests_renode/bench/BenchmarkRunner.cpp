// The 'bench' console command: lists and runs the benchmarks registered with DCOS_BENCHMARK.
//
// Every line the command prints starts with "BENCH " and has a fixed form,
// which tests_renode/bench/run_benchmarks.py parses:
//
//   bench list
//     BENCH <name> cost=<constant|log|variable> variable=<0|1> irq=<off|on>
//     BENCH done
//   bench run [<name> | <Agent>] [--repeat <n>]
//     BENCH overhead min=<i> max=<i> warmup=<w> repeat=<n>
//     BENCH <name> objects=<n> min=<i> max=<i> median=<i> variable=<0|1> cost=<...>
//     BENCH <name> objects=<n> error=<status code> <status text>   (setup failed)
//     BENCH done
//   on a refusal instead of "BENCH done":
//     BENCH error <reason>
//
// min, max and median are time-stamp counter differences less the smallest
// cost of timing an empty function, i.e. the instructions (under exact
// counting) the measured call retires beyond a call of an empty function.
// The median (the lower middle value for an even count) is what a run under
// KVM, where the counter counts real cycles, reports (run_benchmarks.py).
// Under exact counting it equals min for every fixed-cost path. For a
// self-timed benchmark (Options::selfTimed) they are the markStart() to
// markEnd() interval less the smallest cost of an empty such interval.
#include "Benchmark.hpp"

#include <arch_x86/Cpu.hpp>
#include <bsp/Board.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

#include <stdint.h>

namespace bench {

volatile uint64_t intervalStart = 0;
volatile uint64_t intervalEnd = 0;
volatile dcos::Status measuredFailure = dcos::Status::Ok;

namespace {

extern "C" const Benchmark __start_dcos_benchmarks[];
extern "C" const Benchmark __stop_dcos_benchmarks[];

constexpr unsigned warmupCount = 2;
constexpr unsigned defaultRepeatCount = 16;
constexpr unsigned maximumRepeatCount = 10000;

// The measured counts of the current benchmark and object count, for the median.
uint64_t samples[maximumRepeatCount];
unsigned sampleCount = 0;

// The median of samples[0, sampleCount): the lower middle value. Sorts the
// samples in place (Shell sort: no recursion, O(n^1.5) at worst here).
uint64_t medianOfSamples()
{
    if (sampleCount == 0) {
        return 0;
    }
    unsigned gap = 1;
    while (gap < sampleCount / 3) {
        gap = 3 * gap + 1;
    }
    for (; gap > 0; gap /= 3) {
        for (unsigned i = gap; i < sampleCount; ++i) {
            const uint64_t value = samples[i];
            unsigned j = i;
            for (; j >= gap && samples[j - gap] > value; j -= gap) {
                samples[j] = samples[j - gap];
            }
            samples[j] = value;
        }
    }
    return samples[(sampleCount - 1) / 2];
}

// EFLAGS.ID: a CPU that lets software toggle it implements CPUID (Intel SDM Vol. 1, 3.4.3.3).
constexpr uint32_t eflagsId = 1u << 21;
// CPUID.01H:EDX.TSC[bit 4]: the time-stamp counter and RDTSC exist.
constexpr uint32_t cpuidFeatureTsc = 1u << 4;

bool sameText(const char* a, const char* b)
{
    while (*a != '\0' && *a == *b) {
        ++a;
        ++b;
    }
    return *a == *b;
}

// True for the full name, or for its agent part: "Timer" selects "Timer.*".
bool selects(const char* pattern, const char* name)
{
    if (pattern == nullptr) {
        return true;
    }
    while (*pattern != '\0' && *pattern == *name) {
        ++pattern;
        ++name;
    }
    return *pattern == '\0' && (*name == '\0' || *name == '.');
}

bool hasCpuid()
{
    uint32_t original;
    uint32_t toggled;
    asm volatile(
        "pushfl\n\t"
        "popl %0\n\t"
        "movl %0, %1\n\t"
        "xorl %2, %1\n\t"
        "pushl %1\n\t"
        "popfl\n\t"
        "pushfl\n\t"
        "popl %1\n\t"
        "pushl %0\n\t"
        "popfl"
        : "=&r"(original), "=&r"(toggled)
        : "i"(eflagsId)
        : "cc", "memory");
    return ((original ^ toggled) & eflagsId) != 0;
}

bool hasTimeStampCounter()
{
    if (!hasCpuid()) {
        return false; // An i486 without CPUID has no TSC either.
    }
    uint32_t eax = 0;
    uint32_t ebx;
    uint32_t ecx = 0;
    uint32_t edx;
    asm volatile("cpuid" : "+a"(eax), "=b"(ebx), "+c"(ecx), "=d"(edx));
    if (eax < 1) {
        return false;
    }
    eax = 1;
    ecx = 0;
    asm volatile("cpuid" : "+a"(eax), "=b"(ebx), "+c"(ecx), "=d"(edx));
    return (edx & cpuidFeatureTsc) != 0;
}

inline uint64_t readTimeStampCounter()
{
    uint64_t value;
    asm volatile("rdtsc" : "=A"(value)::"memory");
    return value;
}

// Times one call of function. Never inlined or specialised, so the empty
// function used for the overhead goes through exactly the same instructions
// as a real benchmark; the empty asm hides the pointer's value from the
// optimiser for the same reason.
[[gnu::noinline, gnu::noclone]] uint64_t timeOneCall(void (*function)())
{
    asm volatile("" : "+r"(function));
    const uint64_t start = readTimeStampCounter();
    function();
    const uint64_t end = readTimeStampCounter();
    return end - start;
}

[[gnu::noinline]] void emptyFunction()
{
    asm volatile("" ::: "memory");
}

// How far from either end of the tick's period a measured call with
// interrupts disabled starts. A path that reads the clock (Uptime,
// GetSystemClock, the CAN routines' frame stamps) takes one more branch in
// bsp::nanosecondsIntoTick during the 8254's first count after its reload
// (838 ns) and while the tick is pending; without this margin that fell
// inside one call in a few thousand, at a moment set by when the command was
// typed, and a fixed path once counted 9 more (Can.TransmitInterrupt, 251
// against 242). The end margin is ten times the longest fixed path the bench
// has (Modbus.WriteMultipleRegisters, about 7,300 instructions, one a
// nanosecond under exact counting).
constexpr uint32_t clearAfterTickNs = 5000;
constexpr uint32_t clearBeforeTickNs = 100000;
// More than a whole period of attempts (one is some 40 instructions): the
// margin is then found unless the tick has stopped, and the call is
// measured anyway.
constexpr unsigned clearOfTickAttempts = 100000;

// Disables interrupts at a moment clear of the tick (above). Between
// attempts interrupts are enabled, so a pending tick is taken there: STI
// lets one more instruction run before an interrupt is recognised (Intel
// SDM, STI), hence the NOP before CLI.
void disableInterruptsClearOfTick()
{
    const uint64_t period = bsp::tickPeriodNanoseconds();
    for (unsigned attempt = 0;; ++attempt) {
        arch_x86::disableInterrupts();
        const uint32_t into = bsp::nanosecondsIntoTick();
        if (period == 0 || attempt == clearOfTickAttempts ||
            (into >= clearAfterTickNs && into + uint64_t{clearBeforeTickNs} <= period)) {
            return;
        }
        asm volatile("sti\n\tnop" ::: "memory");
    }
}

// One measured call, with interrupts disabled unless the benchmark needs
// them; when they are, at a moment clear of the tick if they were enabled.
uint64_t measureOnce(void (*function)(), bool interruptsEnabled)
{
    const uint32_t flags = arch_x86::readEflags();
    if (!interruptsEnabled) {
        if ((flags & arch_x86::eflagsInterruptEnable) != 0) {
            disableInterruptsClearOfTick();
        } else {
            arch_x86::disableInterrupts();
        }
    }
    const uint64_t count = timeOneCall(function);
    if ((flags & arch_x86::eflagsInterruptEnable) != 0) {
        arch_x86::enableInterrupts();
    }
    return count;
}

// The empty self-timed interval: what markStart() and markEnd() cost when
// nothing happens between them.
[[gnu::noinline]] void emptyInterval()
{
    markStart();
    markEnd();
}

// One call of a self-timed measure(); the interval it marked, or 0 when it
// marked none (its end is missing or precedes its start).
uint64_t measureInterval(void (*function)(), bool interruptsEnabled)
{
    intervalStart = 0;
    intervalEnd = 0;
    measureOnce(function, interruptsEnabled);
    const uint64_t start = intervalStart;
    const uint64_t end = intervalEnd;
    return start != 0 && end > start ? end - start : 0;
}

struct Range {
    uint64_t min = UINT64_MAX;
    uint64_t max = 0;

    void add(uint64_t value)
    {
        min = value < min ? value : min;
        max = value > max ? value : max;
    }
};

uint64_t lessOverhead(uint64_t value, uint64_t overhead) { return value > overhead ? value - overhead : 0; }

const char* costName(Cost cost)
{
    switch (cost) {
    case Cost::Constant: return "constant";
    case Cost::Logarithmic: return "log";
    case Cost::Variable: return "variable";
    }
    return "unknown";
}

unsigned variableFlag(const Benchmark& benchmark) { return benchmark.cost == Cost::Variable ? 1u : 0u; }

shell::CommandResult refuse(shell::Shell& shell, const char* reason)
{
    shell.print("BENCH error %s\r\n", reason);
    return shell::CommandResult::Failed;
}

void runOne(shell::Shell& shell, const Benchmark& benchmark, unsigned repeatCount, uint64_t overhead,
            uint64_t intervalOverhead)
{
    for (const uint32_t objects : objectCounts) {
        const dcos::Status status = benchmark.setup(objects);
        if (status != dcos::Status::Ok) {
            shell.print("BENCH %s objects=%lu error=%u %s\r\n", benchmark.name, static_cast<unsigned long>(objects),
                        static_cast<unsigned>(status), dcos::statusName(status));
            if (benchmark.options.teardown != nullptr) {
                benchmark.options.teardown();
            }
            continue;
        }
        Range range;
        sampleCount = 0;
        measuredFailure = dcos::Status::Ok;
        for (unsigned i = 0; i < warmupCount + repeatCount; ++i) {
            const bool selfTimed = benchmark.options.selfTimed;
            const uint64_t count = selfTimed ? measureInterval(benchmark.measure, benchmark.options.interruptsEnabled)
                                             : measureOnce(benchmark.measure, benchmark.options.interruptsEnabled);
            // A self-timed call that marked no interval (0) is left out; see below.
            if (i >= warmupCount && (!selfTimed || count != 0)) {
                const uint64_t figure = lessOverhead(count, selfTimed ? intervalOverhead : overhead);
                range.add(figure);
                samples[sampleCount++] = figure;
            }
            if (benchmark.options.restore != nullptr) {
                benchmark.options.restore();
            }
        }
        if (benchmark.options.teardown != nullptr) {
            benchmark.options.teardown();
        }
        if (measuredFailure != dcos::Status::Ok) {
            shell.print("BENCH %s objects=%lu error=%u measured call failed: %s\r\n", benchmark.name,
                        static_cast<unsigned long>(objects), static_cast<unsigned>(measuredFailure),
                        dcos::statusName(measuredFailure));
            continue;
        }
        if (range.min == UINT64_MAX) {
            shell.print("BENCH %s objects=%lu error=%u no interval was marked\r\n", benchmark.name,
                        static_cast<unsigned long>(objects), static_cast<unsigned>(dcos::Status::NotFound));
            continue;
        }
        const uint64_t median = medianOfSamples();
        shell.print("BENCH %s objects=%lu min=%llu max=%llu median=%llu variable=%u cost=%s\r\n", benchmark.name,
                    static_cast<unsigned long>(objects), static_cast<unsigned long long>(range.min),
                    static_cast<unsigned long long>(range.max), static_cast<unsigned long long>(median),
                    variableFlag(benchmark), costName(benchmark.cost));
    }
}

shell::CommandResult list(shell::Shell& shell)
{
    for (const Benchmark* benchmark = __start_dcos_benchmarks; benchmark != __stop_dcos_benchmarks; ++benchmark) {
        shell.print("BENCH %s cost=%s variable=%u irq=%s\r\n", benchmark->name, costName(benchmark->cost),
                    variableFlag(*benchmark), benchmark->options.interruptsEnabled ? "on" : "off");
    }
    shell.print("BENCH done\r\n");
    return shell::CommandResult::Ok;
}

shell::CommandResult run(shell::Shell& shell, const char* pattern, unsigned repeatCount)
{
    if (!hasTimeStampCounter()) {
        return refuse(shell, "no time-stamp counter: boot the bench image on the board's benchmark_cpu");
    }
    bool found = false;
    for (const Benchmark* benchmark = __start_dcos_benchmarks; benchmark != __stop_dcos_benchmarks; ++benchmark) {
        found = found || selects(pattern, benchmark->name);
    }
    if (!found) {
        shell.print("error: no benchmark '%s'; 'bench list' shows them\r\n", pattern);
        return refuse(shell, "no such benchmark");
    }

    Range overhead;
    for (unsigned i = 0; i < warmupCount + repeatCount; ++i) {
        const uint64_t count = measureOnce(emptyFunction, false);
        if (i >= warmupCount) {
            overhead.add(count);
        }
    }
    Range intervalOverhead;
    for (unsigned i = 0; i < warmupCount + repeatCount; ++i) {
        const uint64_t count = measureInterval(emptyInterval, false);
        if (i >= warmupCount) {
            intervalOverhead.add(count);
        }
    }
    shell.print("BENCH overhead min=%llu max=%llu warmup=%u repeat=%u\r\n",
                static_cast<unsigned long long>(overhead.min), static_cast<unsigned long long>(overhead.max),
                warmupCount, repeatCount);

    for (const Benchmark* benchmark = __start_dcos_benchmarks; benchmark != __stop_dcos_benchmarks; ++benchmark) {
        if (selects(pattern, benchmark->name)) {
            runOne(shell, *benchmark, repeatCount, overhead.min, intervalOverhead.min);
        }
    }
    shell.print("BENCH done\r\n");
    return shell::CommandResult::Ok;
}

shell::CommandResult benchCommand(shell::Shell& shell, int argc, char** argv)
{
    if (argc == 2 && sameText(argv[1], "list")) {
        return list(shell);
    }
    if (argc < 2 || !sameText(argv[1], "run")) {
        return shell::CommandResult::UsageError;
    }
    const char* pattern = nullptr;
    unsigned repeatCount = defaultRepeatCount;
    for (int i = 2; i < argc; ++i) {
        if (sameText(argv[i], "--repeat")) {
            unsigned long value = 0;
            if (i + 1 >= argc || !shell::Shell::parseUnsigned(argv[i + 1], value) || value == 0
                || value > maximumRepeatCount) {
                return shell::CommandResult::UsageError;
            }
            repeatCount = static_cast<unsigned>(value);
            ++i;
        } else if (pattern == nullptr) {
            pattern = argv[i];
        } else {
            return shell::CommandResult::UsageError;
        }
    }
    return run(shell, pattern, repeatCount);
}

} // namespace

DCOS_SHELL_COMMAND(benchShellCommand, "bench", "measure kernel primitives (bench image only)",
                   "bench list | bench run [<Agent>[.<Primitive>]] [--repeat <n>]", benchCommand);

} // namespace bench
