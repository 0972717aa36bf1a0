// The console command `counter`: the publisher's and the subscriber's
// statistics, and faults injected on request to show that the subscriber
// really detects them.
//
//     counter          prints the statistics (two lines)
//     counter skip     the publisher skips one value once
//     counter repeat   the publisher publishes one value twice
#include "Counter.hpp"

#include <dcos/TaskAgent.hpp>
#include <runtime/Text.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace counter {

namespace {

using shell::CommandResult;

CommandResult printStatistics(shell::Shell& shell)
{
    PublisherStatistics publisher;
    SubscriberStatistics subscriber;
    if (!readStatistics(publisher, subscriber)) {
        shell.print("counter: the statistics are locked; try again\r\n");
        return CommandResult::Failed;
    }
    shell.print("publisher: period %llu ns, published %lu, last value %lu at uptime %llu ns, write errors %lu, "
                "faults injected %lu\r\n",
                static_cast<unsigned long long>(kPeriodNs), static_cast<unsigned long>(publisher.published),
                static_cast<unsigned long>(publisher.lastValue),
                static_cast<unsigned long long>(publisher.lastUptimeNs),
                static_cast<unsigned long>(publisher.writeErrors),
                static_cast<unsigned long>(publisher.faultsInjected));
    shell.print("subscriber: received %lu, last value %lu, data id %lu, skipped %lu, out of order %lu, "
                "missed pages %lu, read errors %lu, stalls %lu\r\n",
                static_cast<unsigned long>(subscriber.received), static_cast<unsigned long>(subscriber.lastValue),
                static_cast<unsigned long>(subscriber.lastDataId), static_cast<unsigned long>(subscriber.skipped),
                static_cast<unsigned long>(subscriber.outOfOrder), static_cast<unsigned long>(subscriber.missedPages),
                static_cast<unsigned long>(subscriber.readErrors), static_cast<unsigned long>(subscriber.stalls));
    return CommandResult::Ok;
}

CommandResult requestFault(shell::Shell& shell, uint32_t request, const char* what)
{
    const dcos::Status posted = dcos::taskAgent.PostEvent(publisherTask, request);
    if (posted != dcos::Status::Ok) {
        shell.print("counter: cannot reach the publisher: %s\r\n", dcos::statusName(posted));
        return CommandResult::Failed;
    }
    shell.print("counter: the publisher will %s in its next period\r\n", what);
    return CommandResult::Ok;
}

CommandResult counterCommand(shell::Shell& shell, int argc, char** argv)
{
    if (argc == 1) {
        return printStatistics(shell);
    }
    if (argc == 2 && runtime::textEquals(argv[1], "skip")) {
        return requestFault(shell, kSkipRequest, "skip one value");
    }
    if (argc == 2 && runtime::textEquals(argv[1], "repeat")) {
        return requestFault(shell, kRepeatRequest, "publish its last value again");
    }
    return CommandResult::UsageError;
}

} // namespace

DCOS_SHELL_COMMAND(counterShellCommand, "counter", "the counter publisher's and subscriber's statistics",
                   "counter [skip|repeat]", counterCommand);

} // namespace counter
