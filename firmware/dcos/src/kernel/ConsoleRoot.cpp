// The root task of the full kernel configuration (dcos/internal/KernelConfiguration.hpp).
//
// The root task starts the application linked into the image, if any,
// through the application loader, then the console shell, which it starts
// again if it ends. It needs the semaphore agent (the shell's life
// semaphore), the loader and the shell, which is why it is the full
// configuration's: the minimal one has kernel/MinimalRoot.cpp instead.
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/ApplicationLoader.hpp>
#include <dcos/internal/FlashServiceHooks.hpp>
#include <dcos/internal/KernelConfiguration.hpp>
#include <dcos/internal/NetworkBootHooks.hpp>

#include <boot/Panic.hpp>
#include <bsp/Board.hpp>
#include <shell/Shell.hpp>

namespace dcos::internal {

const char* const kKernelConfiguration = "full";

namespace {

// The shell task sleeps on this event until the console has input.
constexpr uint32_t consoleInputEvent = 1u << 0;
ObjectId shellTask;

// Between two shells there is none to wake: the new one reads what came.
void onConsoleInput(void*) { (void)taskAgent.PostEvent(shellTask, consoleInputEvent); }

// The console shell. It holds its life semaphore (the argument) for as long
// as it runs, so that the root task learns of its end, whatever the cause.
void shellTaskEntry(uintptr_t lifeSemaphore)
{
    shellTask = taskAgent.IdOfSelf();
    // The root task released the semaphore before it started this shell, so
    // the poll takes it; were it refused, the root task would only learn of
    // this shell's end later, when it next polls.
    if (semaphoreAgent.Acquire(ObjectId::fromRaw(static_cast<uint32_t>(lifeSemaphore)), kPoll) != Status::Ok) {
        runtime::format(bsp::console(), "console: the shell could not take its life semaphore\r\n");
    }
    bsp::setConsoleInputNotifier(onConsoleInput, nullptr);
    // A new shell, with an empty line, each time the task starts.
    shell::Shell shell(bsp::console(), "dcos> ");
    shell.start();
    for (;;) {
        char character;
        while (bsp::consoleRead(character)) {
            shell.feed(character);
        }
        // The only event is console input, read at the top of the loop
        // whatever the wait answered.
        (void)taskAgent.ReceiveEvent(consoleInputEvent, EventWait::Any, kWaitForever);
    }
}

Result<ObjectId> startShell(ObjectId lifeSemaphore)
{
    TaskAttributes attributes;
    attributes.name = kShellTaskName;
    attributes.priority = kShellTaskPriority;
    attributes.stackSize = kShellStackSize;
    attributes.superUser = true;
    return taskAgent.Create(attributes, shellTaskEntry, lifeSemaphore.raw());
}

} // namespace

// The root task. It starts the application linked into the image, then the
// console shell, and starts the shell again when it ends (a fatal exception
// in a command, or KillTask): the console is how an engineer reaches the
// node, so it must outlive a fault in it. The shell holds a binary
// semaphore while it lives; when it ends, resource recovery frees the
// semaphore and wakes this task with Abandoned (seed 7.11).
void rootTaskEntry(uintptr_t)
{
    // The flash service, in an image that has it, is up before any
    // application task runs: an application that faults at once can still
    // be replaced over the bus.
    if (flashServiceStart != nullptr) {
        flashServiceStart();
    }
    // The links the command line names (the card's configuration puts its
    // bit rate there) are up before the application, which may use them.
    if (networkBootStart != nullptr) {
        networkBootStart();
    }
    if (boardNetworkStart != nullptr) {
        boardNetworkStart();
    }
    ApplicationLoader::startLinked();
    SemaphoreAttributes life;
    life.name = "shell-life";
    const Result<ObjectId> lifeSemaphore = semaphoreAgent.Create(life);
    if (!lifeSemaphore.ok()) {
        dcosPanic("cannot create the shell's life semaphore: %s", statusName(lifeSemaphore.status()));
    }
    for (unsigned started = 0;; ++started) {
        const Result<ObjectId> shell = startShell(lifeSemaphore.value());
        if (!shell.ok()) {
            runtime::format(bsp::console(), "console: cannot start the shell: %s\r\n", statusName(shell.status()));
            break;
        }
        // The shell, more urgent, holds the semaphore by now; this waits for its end.
        const Status ended = semaphoreAgent.Acquire(lifeSemaphore.value(), kWaitForever);
        if (ended == Status::Ok) {
            // Cannot fail: this task holds it, and the next shell takes it.
            (void)semaphoreAgent.Release(lifeSemaphore.value());
        }
        if (started + 1 >= kShellRestartLimit) {
            runtime::format(bsp::console(), "console: the shell ended %u times; not starting it again\r\n",
                            started + 1);
            break;
        }
        runtime::format(bsp::console(), "console: the shell ended; starting it again\r\n");
    }
    // Nothing is left to do: wait for an event nobody posts to this task.
    for (;;) {
        (void)taskAgent.ReceiveEvent(consoleInputEvent, EventWait::Any, kWaitForever);
    }
}

} // namespace dcos::internal
