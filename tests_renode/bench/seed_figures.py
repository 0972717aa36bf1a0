"""The seed's service primitive times (dissertation 9.3.7, Tables 9.2-9.11).

Every figure in these tables was measured on controller node 2, a 150 MHz
Pentium (seed 9.3.6: TSC at 6.67 ns resolution, all interrupts enabled, a
100 us clock tick, averaged over many calls). The seed gives no per-primitive
times for the 486DX-33 node. The figures are microseconds, end to end
including argument passing and the privilege and stack switches of the trap
interface, so they are not directly comparable to the instruction counts of
`make bench`; run_benchmarks.py prints them side by side as orientation.

Keys follow the benchmark naming rule "<Agent>.<Primitive>": the seed's agent
name without "Agent", with the memory agents spelled out (BPMemAgent ->
BufferPool, SHMemAgent -> Heap, DSMemAgent -> Dsm) and SEIAgent -> Sei. The
rows of Table 9.11 that belong to no agent use "Kernel". A benchmark that
measures one of these primitives should use exactly this key.

The source text is an OCR scan; where it is damaged the entry says so:
`microseconds` is None when the digit is illegible, and `uncertain` marks a
value whose row had to be reconstructed.
"""

from collections import namedtuple

SeedFigure = namedtuple("SeedFigure", "microseconds remark table seed_name uncertain")

# Processor the figures were measured on (seed 9.3.6).
SEED_PROCESSOR = "Pentium-150 (controller node 2)"


def _figure(microseconds, table, seed_name, remark="", uncertain=False):
    return SeedFigure(microseconds, remark, table, seed_name, uncertain)


SEED_FIGURES = {
    # Table 9.2 - System Agent Primitives
    "System.MapDualPortMem": _figure(11, "9.2", "SystemAgent.MapDualPortMem", "Variable"),
    "System.UnmapDualPortMem": _figure(19, "9.2", "SystemAgent.UnmapDualPortMem", "Variable"),
    "System.AddObjectIds": _figure(7, "9.2", "SystemAgent.AddObjectIds", "Variable"),
    "System.AddObjects": _figure(6, "9.2", "SystemAgent.AddObjects", "Variable"),
    "System.XferOwnership": _figure(6, "9.2", "SystemAgent.XferOwnership"),
    "System.Create": _figure(3, "9.2", "SystemAgent.Create"),
    "System.Delete": _figure(5, "9.2", "SystemAgent.Delete"),
    "System.Probe": _figure(6, "9.2", "SystemAgent.Probe", "Overhead Only"),
    "System.Open": _figure(5, "9.2", "SystemAgent.Open", "Overhead Only"),
    "System.Close": _figure(5, "9.2", "SystemAgent.Close", "Overhead Only"),
    "System.Control": _figure(7, "9.2", "SystemAgent.Control", "Overhead Only"),
    "System.Read": _figure(7, "9.2", "SystemAgent.Read", "Overhead Only"),
    "System.Write": _figure(9, "9.2", "SystemAgent.Write", "Overhead Only"),
    "System.InstallISR": _figure(3, "9.2", "SystemAgent.InstallISR"),
    # The table has two SetInterruptLevel rows, both 3 us; the second is
    # remarked "Legal Limit" (setting the legal limit rather than a level).
    "System.SetInterruptLevel": _figure(3, "9.2", "SystemAgent.SetInterruptLevel",
                                        "second row, also 3 us: Legal Limit"),
    # Table 9.3 - Scheduler Agent Primitives
    "Scheduler.Yield": _figure(6, "9.3", "SchedulerAgent.Yield", "Overhead Only"),
    "Scheduler.SetDeadline": _figure(12, "9.3", "SchedulerAgent.SetDeadline", "Set Now Option"),
    "Scheduler.ClearDeadline": _figure(5, "9.3", "SchedulerAgent.ClearDeadline"),
    "Scheduler.GetTimingInfo": _figure(7, "9.3", "SchedulerAgent.GetTimingInfo"),
    "Scheduler.StartProfiling": _figure(3, "9.3", "SchedulerAgent.StartProfiling"),
    "Scheduler.StopProfiling": _figure(4, "9.3", "SchedulerAgent.StopProfiling"),
    # Table 9.4 - Timer Agent Primitives
    "Timer.GetSystemClock": _figure(11, "9.4", "TimerAgent.GetSystemClock"),
    "Timer.SetSystemClock": _figure(8, "9.4", "TimerAgent.SetSystemClock"),
    "Timer.NameToObject": _figure(5, "9.4", "TimerAgent.NameToObject"),
    "Timer.AddObjects": _figure(8, "9.4", "TimerAgent.AddObjects", "Variable"),
    "Timer.XferOwnership": _figure(5, "9.4", "TimerAgent.XferOwnership"),
    "Timer.Create": _figure(6, "9.4", "TimerAgent.Create"),
    "Timer.Delete": _figure(7, "9.4", "TimerAgent.Delete"),
    "Timer.SetWatchDogAlarm": _figure(7, "9.4", "TimerAgent.SetWatchDogAlarm"),
    "Timer.SetDayClockAlarm": _figure(10, "9.4", "TimerAgent.SetDayClockAlarm"),
    "Timer.SetPeriodicAlarm": _figure(7, "9.4", "TimerAgent.SetPeriodicAlarm"),
    "Timer.CancelAlarm": _figure(3, "9.4", "TimerAgent.CancelAlarm"),
    # Table 9.5 - Task Agent Primitives. The table breaks across a page after
    # SleepTill; the OCR puts SendSignal's time on the line before its name
    # (as it does for GetUsageInfo in Tables 9.6 and 9.7) and the remaining
    # nine times and three remarks in one column, matched here in order.
    "Task.NameToObject": _figure(5, "9.5", "TaskAgent.NameToObject"),
    "Task.AddProxyTasks": _figure(7, "9.5", "TaskAgent.AddProxyTasks", "Variable"),
    "Task.AddObjects": _figure(17, "9.5", "TaskAgent.AddObjects", "Variable"),
    "Task.Create": _figure(200, "9.5", "TaskAgent.Create", "Variable"),
    "Task.Delete": _figure(180, "9.5", "TaskAgent.Delete", "Variable"),
    "Task.ChangePriority": _figure(17, "9.5", "TaskAgent.ChangePriority"),
    "Task.SleepFor": _figure(15, "9.5", "TaskAgent.SleepFor", "Overhead Only"),
    "Task.SleepTill": _figure(17, "9.5", "TaskAgent.SleepTill", "Overhead Only"),
    "Task.SendSignal": _figure(7, "9.5", "TaskAgent.SendSignal", uncertain=True),
    "Task.SetSignalHandler": _figure(3, "9.5", "TaskAgent.SetSignalHandler", uncertain=True),
    "Task.SetSignalMask": _figure(2, "9.5", "TaskAgent.SetSignalMask", uncertain=True),
    "Task.Suspend": _figure(7, "9.5", "TaskAgent.Suspend", "Overhead Only", uncertain=True),
    "Task.PostEvent": _figure(7, "9.5", "TaskAgent.PostEvent", uncertain=True),
    "Task.PendOnEvents": _figure(4, "9.5", "TaskAgent.PendOnEvents", "Available/Polling", uncertain=True),
    "Task.ThrowException": _figure(7, "9.5", "TaskAgent.ThrowException", uncertain=True),
    "Task.SetExceptionHandler": _figure(3, "9.5", "TaskAgent.SetExceptionHandler", uncertain=True),
    "Task.IdOfSelf": _figure(3, "9.5", "TaskAgent.IdOfSelf", uncertain=True),
    "Task.KillTask": _figure(7, "9.5", "TaskAgent.KillTask", "Sending Kill Signal", uncertain=True),
    # Table 9.6 - Buffer Pool Memory Agent Primitives
    "BufferPool.NameToObject": _figure(None, "9.6", "BPMemAgent.NameToObject", "time illegible in the seed text"),
    "BufferPool.AddObjects": _figure(8, "9.6", "BPMemAgent.AddObjects", "Variable"),
    "BufferPool.XferOwnership": _figure(5, "9.6", "BPMemAgent.XferOwnership"),
    "BufferPool.Create": _figure(10, "9.6", "BPMemAgent.Create", "Variable"),
    "BufferPool.Delete": _figure(10, "9.6", "BPMemAgent.Delete"),
    "BufferPool.Allocate": _figure(5, "9.6", "BPMemAgent.Allocate"),
    "BufferPool.Return": _figure(None, "9.6", "BPMemAgent.Return", "time illegible in the seed text"),
    "BufferPool.GetUsageInfo": _figure(6, "9.6", "BPMemAgent.GetUsageInfo"),
    # Table 9.7 - Segmented Heap Memory Agent Primitives
    "Heap.NameToObject": _figure(None, "9.7", "SHMemAgent.NameToObject", "time illegible in the seed text"),
    "Heap.AddObjects": _figure(12, "9.7", "SHMemAgent.AddObjects", "Variable"),
    "Heap.XferOwnership": _figure(5, "9.7", "SHMemAgent.XferOwnership"),
    "Heap.Create": _figure(10, "9.7", "SHMemAgent.Create", "Variable"),
    "Heap.Delete": _figure(10, "9.7", "SHMemAgent.Delete"),
    "Heap.Allocate": _figure(7, "9.7", "SHMemAgent.Allocate", "Variable"),
    "Heap.Return": _figure(6, "9.7", "SHMemAgent.Return"),
    "Heap.GetUsageInfo": _figure(6, "9.7", "SHMemAgent.GetUsageInfo"),
    # Table 9.8 - Distributed Shared Memory Agent Primitives
    "Dsm.NameToObject": _figure(5, "9.8", "DSMemAgent.NameToObject"),
    "Dsm.AddSubscribers": _figure(29, "9.8", "DSMemAgent.AddSubscribers", "Variable"),
    "Dsm.AddObjects": _figure(14, "9.8", "DSMemAgent.AddObjects", "Variable"),
    "Dsm.XferOwnership": _figure(5, "9.8", "DSMemAgent.XferOwnership", "OCR reads 'S'", uncertain=True),
    "Dsm.Create": _figure(35, "9.8", "DSMemAgent.Create"),
    "Dsm.Delete": _figure(40, "9.8", "DSMemAgent.Delete"),
    "Dsm.Open": _figure(10, "9.8", "DSMemAgent.Open"),
    "Dsm.Close": _figure(5, "9.8", "DSMemAgent.Close"),
    "Dsm.Read": _figure(6, "9.8", "DSMemAgent.Read", "Available/Polling"),
    "Dsm.Write": _figure(22, "9.8", "DSMemAgent.Write"),
    # Table 9.9 - Message Port Agent Primitives
    "Port.NameToObject": _figure(5, "9.9", "PortAgent.NameToObject"),
    "Port.AddObjects": _figure(11, "9.9", "PortAgent.AddObjects", "Variable"),
    "Port.XferOwnership": _figure(5, "9.9", "PortAgent.XferOwnership", "OCR reads 'S'", uncertain=True),
    "Port.Create": _figure(34, "9.9", "PortAgent.Create"),
    "Port.Delete": _figure(27, "9.9", "PortAgent.Delete"),
    "Port.Send": _figure(13, "9.9", "PortAgent.Send"),
    "Port.Receive": _figure(7, "9.9", "PortAgent.Receive", "Available/Polling"),
    "Port.AddMsgBufs": _figure(6, "9.9", "PortAgent.AddMsgBufs", "Variable"),
    # Table 9.10 - Semaphore Agent Primitives
    "Semaphore.NameToObject": _figure(5, "9.10", "SemaphoreAgent.NameToObject"),
    "Semaphore.AddObjects": _figure(10, "9.10", "SemaphoreAgent.AddObjects", "Variable"),
    "Semaphore.XferOwnership": _figure(5, "9.10", "SemaphoreAgent.XferOwnership"),
    "Semaphore.Create": _figure(31, "9.10", "SemaphoreAgent.Create"),
    "Semaphore.Delete": _figure(34, "9.10", "SemaphoreAgent.Delete"),
    "Semaphore.Acquire": _figure(8, "9.10", "SemaphoreAgent.Acquire", "Available/Polling"),
    "Semaphore.Release": _figure(7, "9.10", "SemaphoreAgent.Release"),
    # Table 9.11 - Miscellaneous Timing Data
    "Sei.LogMessage": _figure(14, "9.11", "SEIAgent.LogMessage"),
    "Sei.LogData": _figure(20, "9.11", "SEIAgent.LogData"),
    "Kernel.InterruptLatency": _figure(1.3, "9.11", "Interrupt Latency"),
    "Kernel.ContextSwitch": _figure(0.6, "9.11", "Context Switch Time"),
    "Kernel.FloatingPointContext": _figure(1.4, "9.11", "Floating Point Context", "Save and Restore"),
    "Kernel.StaticScheduling": _figure(0.1, "9.11", "Static Scheduling"),
    "Kernel.DynamicScheduling": _figure(2, "9.11", "Dynamic Scheduling"),
    "Kernel.NetworkLatency": _figure(80, "9.11", "Network Latency"),
}


# The seed's timing tables in order: (table, title, benchmark agent prefixes).
# A benchmark belongs to the table of its agent, whether or not the seed
# lists its primitive; Table 9.11 also holds the kernel-wide figures.
SEED_TABLES = (
    ("9.2", "System Agent Primitives", ("System",)),
    ("9.3", "Scheduler Agent Primitives", ("Scheduler",)),
    ("9.4", "Timer Agent Primitives", ("Timer",)),
    ("9.5", "Task Agent Primitives", ("Task",)),
    ("9.6", "Buffer Pool Memory Agent Primitives", ("BufferPool",)),
    ("9.7", "Segmented Heap Memory Agent Primitives", ("Heap",)),
    ("9.8", "Distributed Shared Memory Agent Primitives", ("Dsm",)),
    ("9.9", "Message Port Agent Primitives", ("Port",)),
    ("9.10", "Semaphore Agent Primitives", ("Semaphore",)),
    ("9.11", "Miscellaneous Timing Data", ("Kernel", "Sei")),
)


def table_of(name):
    """The seed table a benchmark name belongs to ("9.2" ... "9.11"), or "" for an unknown agent."""
    figure = SEED_FIGURES.get(name)
    if figure is not None:
        return figure.table
    agent = name.split(".", 1)[0]
    for table, _, agents in SEED_TABLES:
        if agent in agents:
            return table
    return ""


def seed_text(name):
    """The seed figure for a benchmark name as a short string, or "" when the seed lists none."""
    figure = SEED_FIGURES.get(name)
    if figure is None:
        return ""
    if figure.microseconds is None:
        return "illegible"
    text = f"{figure.microseconds:g} us"
    if figure.uncertain:
        text += " (?)"
    if figure.remark.startswith(("Variable", "Overhead Only", "Available/Polling")):
        text += f" [{figure.remark}]"
    return text
