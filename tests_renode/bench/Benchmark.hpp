// Benchmarks of kernel primitives, linked only into the bench image (dcos486-bench.elf).
//
// Each benchmark registers with DCOS_BENCHMARK in its own file under
// tests_renode/bench/, named "<Agent>.<Primitive>" (for example
// "Semaphore.Acquire"; tests_renode/bench/seed_figures.py lists the names the
// seed's timing tables use). The 'bench' console command (BenchmarkRunner.cpp)
// lists and runs them. For each object count in objectCounts the runner
//
//   1. calls setup(objectCount), which creates that many objects of the
//      primitive's type so the measured call runs in a populated system,
//   2. calls measure() warmupCount times unmeasured, then repeatCount times
//      between two reads of the time-stamp counter; after every call it
//      calls options.restore(), if given, unmeasured, so that each
//      measured call starts from the same state,
//   3. calls options.teardown(), if given, which must undo setup so that
//      the next object count starts from nothing,
//
// and prints the smallest and the largest count, less the cost of measuring
// an empty function. Under the benchmark CPU model with exact instruction
// counting (docs/performance.md) the count is the number of instructions
// the primitive retires, so a fixed-cost primitive reports min == max and
// the same figure for 8 and for 4096 objects.
//
// Interrupts are disabled around each measured call, so the system tick
// never lands inside a measurement. A primitive that must run with
// interrupts enabled (one that blocks or switches tasks) sets
// options.interruptsEnabled; its maximum may then include an interrupt.
//
// An interval that does not begin and end in the same task around one call
// (a task switch: from a call in task A to the first instruction of task B;
// an interrupt: from the request to the handler's first instruction) sets
// options.selfTimed: measure() then starts the interval with
// bench::markStart() and something it causes ends it with bench::markEnd()
// (in another task, or in an interrupt handler), and the figure is
// end - start less the cost of an empty markStart(); markEnd() pair.
#pragma once

#include <dcos/Status.hpp>

#include <stdint.h>

namespace bench {

/// How a primitive's cost depends on the number of objects, as its design claims.
///
/// The report flags a Constant benchmark whose figures for 8 and 4096
/// objects differ. Variable is the seed's "Variable" remark: configuration
/// services and the few real-time services whose cost the seed lets grow.
enum class Cost : uint8_t {
    Constant,    ///< O(1): the same instruction count for any number of objects.
    Logarithmic, ///< O(log N), e.g. a binary heap.
    Variable,    ///< Grows with the objects or the arguments (seed: "Variable").
};

/// Optional parts of a benchmark; see DCOS_BENCHMARK for how to give them.
struct Options {
    /// Called, unmeasured, after every call of measure(); null for none.
    void (*restore)() = nullptr;
    /// Called once after the last call for an object count; null for none.
    void (*teardown)() = nullptr;
    /// Leave interrupts enabled around the measured call.
    bool interruptsEnabled = false;
    /// The figure is the interval from bench::markStart() to bench::markEnd(),
    /// which measure() brings about, rather than the duration of measure().
    bool selfTimed = false;
};

struct Benchmark {
    /// "<Agent>.<Primitive>", the key of the report and of seed_figures.py.
    const char* name;
    /// Prepares objectCount objects; a failure skips that object count.
    dcos::Status (*setup)(uint32_t objectCount);
    /// Performs exactly one call of the primitive.
    void (*measure)();
    Cost cost;
    Options options;
};

/// Time-stamp counter values of the current self-timed interval (Options::selfTimed).
extern volatile uint64_t intervalStart;
extern volatile uint64_t intervalEnd;

/// Starts a self-timed interval: the time-stamp counter read is its first instruction.
[[gnu::always_inline]] inline void markStart()
{
    uint64_t value;
    asm volatile("rdtsc" : "=A"(value)::"memory");
    intervalStart = value;
}

/// Ends a self-timed interval: everything before this read counts.
[[gnu::always_inline]] inline void markEnd()
{
    uint64_t value;
    asm volatile("rdtsc" : "=A"(value)::"memory");
    intervalEnd = value;
}

/// The first status other than Ok that a measured call passed to check()
/// since the runner last cleared it; the runner then reports that status
/// instead of figures, so that an error path is never taken for the primitive.
extern volatile dcos::Status measuredFailure;

/// Records the status of the measured call (a compare and, on failure, a store).
[[gnu::always_inline]] inline void check(dcos::Status status)
{
    if (status != dcos::Status::Ok) {
        measuredFailure = status;
    }
}

/// The object counts every benchmark runs with, smallest first.
inline constexpr uint32_t objectCounts[] = {8, 4096};
/// The largest entry of objectCounts, for sizing static storage.
inline constexpr uint32_t maximumObjectCount = 4096;

} // namespace bench

/// Registers a benchmark. Use once per benchmark at namespace scope.
///
///     DCOS_BENCHMARK(resolveIdBench, "Kernel.ResolveId", setupTable, resolveOne, bench::Cost::Constant,
///                    .teardown = clearTable);
///
/// The optional trailing arguments are designated initialisers of
/// bench::Options and must keep its member order: .restore, .teardown,
/// .interruptsEnabled, .selfTimed.
#define DCOS_BENCHMARK(identifier, name, setup, measure, cost, ...)                          \
    [[gnu::used, gnu::section("dcos_benchmarks")]] constinit const ::bench::Benchmark identifier \
    {                                                                                        \
        name, setup, measure, cost, ::bench::Options { __VA_ARGS__ }                         \
    }
