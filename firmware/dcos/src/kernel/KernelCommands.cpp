// The kernel's own console commands: version, uptime and mem.
#include <dcos/Version.hpp>

#include <boot/BootInfo.hpp>
#include <bsp/Board.hpp>
#include <shell/Shell.hpp>

#include <dcos/GregorianCalendar.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/StackArena.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/TimerManager.hpp>
#include <dcos/internal/IdText.hpp>

namespace dcos {

uintptr_t firstFreeMemory();

namespace {

shell::CommandResult version(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const bsp::BoardIdentity& board = bsp::identity();
    shell.print("DCOS %s (revision %s)\r\n", versionString, buildRevision());
    shell.print("board %s, processor %s, compiler GCC %d.%d.%d\r\n", board.name, board.processor, __GNUC__,
                __GNUC_MINOR__, __GNUC_PATCHLEVEL__);
    shell.print("loaded by %s\r\n", bootInfo().loaderName);
    return shell::CommandResult::Ok;
}

shell::CommandResult uptime(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const uint64_t ticks = internal::TimerManager::ticks();
    const uint64_t nanoseconds = internal::TimerManager::uptimeNs();
    const uint64_t milliseconds = nanoseconds / 1000000u;
    const uint64_t seconds = milliseconds / 1000u;
    shell.print("up %lu d %02lu:%02lu:%02lu.%03lu (%llu ticks at %lu Hz)\r\n",
                static_cast<unsigned long>(seconds / 86400u), static_cast<unsigned long>((seconds / 3600u) % 24u),
                static_cast<unsigned long>((seconds / 60u) % 60u), static_cast<unsigned long>(seconds % 60u),
                static_cast<unsigned long>(milliseconds % 1000u), static_cast<unsigned long long>(ticks),
                static_cast<unsigned long>(bsp::tickRateHz()));
    return shell::CommandResult::Ok;
}

shell::CommandResult mem(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const boot::BootInfo& info = bootInfo();
    const boot::ImageLayout image = boot::imageLayout();
    // Extended memory starts at 1 MiB, where the image is loaded.
    const uintptr_t memoryEnd = 0x100000u + uintptr_t{info.upperMemoryKib} * 1024u;
    shell.print("memory  %lu KiB conventional, %lu KiB extended\r\n", static_cast<unsigned long>(info.lowerMemoryKib),
                static_cast<unsigned long>(info.upperMemoryKib));
    shell.print("image   %08lx-%08lx %6lu KiB\r\n", static_cast<unsigned long>(image.start),
                static_cast<unsigned long>(image.end), static_cast<unsigned long>((image.end - image.start) / 1024u));
    shell.print("  bss   %08lx-%08lx %6lu KiB\r\n", static_cast<unsigned long>(image.bssStart),
                static_cast<unsigned long>(image.bssEnd),
                static_cast<unsigned long>((image.bssEnd - image.bssStart) / 1024u));
    shell.print("  stack %08lx-%08lx %6lu KiB\r\n", static_cast<unsigned long>(image.bootStackBottom),
                static_cast<unsigned long>(image.bootStackTop),
                static_cast<unsigned long>((image.bootStackTop - image.bootStackBottom) / 1024u));
    const uintptr_t freeStart = firstFreeMemory();
    shell.print("paging  %08lx-%08lx %6lu KiB (page tables; page 0 and stack guards not present)\r\n",
                static_cast<unsigned long>(image.end), static_cast<unsigned long>(freeStart),
                static_cast<unsigned long>((freeStart - image.end) / 1024u));
    if (memoryEnd > freeStart) {
        shell.print("free    %08lx-%08lx %6lu KiB\r\n", static_cast<unsigned long>(freeStart),
                    static_cast<unsigned long>(memoryEnd), static_cast<unsigned long>((memoryEnd - freeStart) / 1024u));
    } else {
        shell.print("free    none: the image does not fit the reported memory\r\n");
    }
    return shell::CommandResult::Ok;
}

const char* stateName(TaskState state)
{
    switch (state) {
    case TaskState::NonExistent: return "gone";
    case TaskState::Spawning: return "spawning";
    case TaskState::Ready: return "ready";
    case TaskState::Executing: return "executing";
    case TaskState::Blocked: return "blocked";
    case TaskState::Suspended: return "suspended";
    case TaskState::Terminating: return "terminating";
    }
    return "?";
}

shell::CommandResult tasks(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    shell.print("id           name             prio state      stack   used  flags\r\n");
    internal::TaskManager::forEachTask([&shell](internal::Task& task) {
        const Result<TaskState> state = taskAgent.GetState(task.id);
        shell.print("%-10s   %-16s %4u %-10s %6lu %6lu  %s%s%s%s\r\n", internal::IdText(task.id).c_str(),
                    internal::TaskManager::nameOf(task.id), task.basePriority,
                    state.ok() ? stateName(state.value()) : "?", static_cast<unsigned long>(task.stackSize),
                    static_cast<unsigned long>(internal::TaskManager::stackHighWater(task)),
                    task.superUser ? "S" : "-", task.timeSlicing ? "T" : "-", task.floatingPoint ? "F" : "-",
                    task.inDeadlineScope ? "D" : "-");
    });
    shell.print("%lu tasks, %lu task switches, stack arena %lu bytes free\r\n",
                static_cast<unsigned long>(internal::TaskManager::taskCount()),
                static_cast<unsigned long>(internal::Scheduler::switchCount()),
                static_cast<unsigned long>(internal::StackArena::freeBytes()));
    return shell::CommandResult::Ok;
}

// Parses "YYYY-MM-DD" and "HH:MM:SS" into a DateTime; false on any other text.
bool parseDateTime(const char* date, const char* time, DateTime& out)
{
    unsigned fields[6] = {};
    const char* texts[2] = {date, time};
    const char separators[2] = {'-', ':'};
    for (unsigned part = 0; part < 2; ++part) {
        const char* p = texts[part];
        for (unsigned field = 0; field < 3; ++field) {
            unsigned value = 0;
            unsigned digits = 0;
            while (*p >= '0' && *p <= '9' && digits < 4) {
                value = value * 10 + static_cast<unsigned>(*p - '0');
                ++p;
                ++digits;
            }
            if (digits == 0 || (field < 2 ? *p != separators[part] : *p != '\0')) {
                return false;
            }
            if (field < 2) {
                ++p;
            }
            fields[part * 3 + field] = value;
        }
    }
    out = DateTime{};
    out.year = static_cast<uint16_t>(fields[0]);
    out.month = static_cast<uint8_t>(fields[1]);
    out.day = static_cast<uint8_t>(fields[2]);
    out.hour = static_cast<uint8_t>(fields[3]);
    out.minute = static_cast<uint8_t>(fields[4]);
    out.second = static_cast<uint8_t>(fields[5]);
    return fields[1] <= 255 && fields[2] <= 255 && fields[3] <= 255 && fields[4] <= 255 && fields[5] <= 255;
}

shell::CommandResult date(shell::Shell& shell, int argc, char** argv)
{
    if (argc != 1 && argc != 3) {
        return shell::CommandResult::UsageError;
    }
    if (argc == 3) {
        DateTime time;
        if (!parseDateTime(argv[1], argv[2], time)) {
            return shell::CommandResult::UsageError;
        }
        if (GregorianCalendar::validate(time) != Status::Ok || time.year > TimerAgent::kLastClockYear) {
            shell.print("error: %s %s is not a date and time from 1970-01-01 00:00:00 to %u-12-31 23:59:59\r\n",
                        argv[1], argv[2], static_cast<unsigned>(TimerAgent::kLastClockYear));
            return shell::CommandResult::Failed;
        }
        const Status status = timerAgent.SetSystemClock(time);
        if (status != Status::Ok) {
            shell.print("error: cannot set the clock: %s\r\n", statusName(status));
            return shell::CommandResult::Failed;
        }
    }
    const Result<DateTime> now = timerAgent.GetSystemClock();
    static constexpr const char* weekdays[] = {"Sun", "Mon", "Tue", "Wed", "Thu", "Fri", "Sat"};
    const DateTime& t = now.value();
    shell.print("%s %04u-%02u-%02u %02u:%02u:%02u.%03lu\r\n", weekdays[static_cast<unsigned>(t.weekday) % 7], t.year,
                t.month, t.day, t.hour, t.minute, t.second, static_cast<unsigned long>(t.nanosecond / 1000000u));
    return shell::CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(tasksCommand, "tasks", "list the tasks and their states", "tasks",
                            "  id: the object id, 0x and eight hex digits in every listing and report\r\n"
                            "  prio: the base priority, 0 (most urgent) to 31; inheritance may lend a task more\r\n"
                            "  stack: the stack size in bytes; used: its high-water mark, the most bytes it has held\r\n"
                            "  flags: S super-user, T time slicing, F floating point, D deadline scheduling, - not set",
                            tasks);
DCOS_SHELL_COMMAND(dateCommand, "date", "show or set the time of day", "date [YYYY-MM-DD HH:MM:SS]", date);
DCOS_SHELL_COMMAND(versionCommand, "version", "show the DCOS release, board and build", "version", version);
DCOS_SHELL_COMMAND(uptimeCommand, "uptime", "show the time since the system tick started", "uptime", uptime);
DCOS_SHELL_COMMAND(memCommand, "mem", "show the memory map", "mem", mem);

} // namespace dcos
