// Benchmarks of the system agent's primitives (seed 7.3, Table 9.2).
//
// The object count is the number of installed device drivers, all of them
// NullDevice objects whose functions do nothing, so the device primitives
// show the agent's own cost ("overhead only" in the seed). The measured
// calls use the newest device, "target". InstallISR and SetInterruptLevel
// run with the same device population.
#include "BenchSupport.hpp"

#include <dcos/Device.hpp>
#include <dcos/SystemAgent.hpp>

namespace bench {
namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;
using dcos::systemAgent;

// A driver whose functions return at once.
class NullDevice final : public dcos::Device {
public:
    constexpr NullDevice() = default;

private:
    Status Probe() override { return Status::Ok; }
    Result<size_t> Read(uint32_t, void*, size_t) override { return size_t{0}; }
    Result<size_t> Write(uint32_t, const void*, size_t length) override { return length; }
    Status Control(uint32_t, void*, size_t) override { return Status::Ok; }
};

NullDevice drivers[maximumObjectCount];
ObjectId devices[maximumObjectCount];
uint32_t deviceCount = 0;
ObjectId target;
bool targetOpen = false;
volatile uint32_t lastValue;
uint8_t buffer[4];

Result<ObjectId> install(NullDevice& driver, const char* name)
{
    Result<ObjectId> id = systemAgent.Create(driver, name, dcos::Visibility::Local);
    if (id.status() == Status::TableFull) {
        const Status grown = systemAgent.AddObjects(8);
        if (grown != Status::Ok) {
            return grown;
        }
        id = systemAgent.Create(driver, name, dcos::Visibility::Local);
    }
    return id;
}

// Installs drivers until count devices exist, the last one named "target".
Status populate(uint32_t count)
{
    while (deviceCount < count) {
        const bool last = deviceCount + 1 == count;
        const Result<ObjectId> id = install(drivers[deviceCount], last ? "target" : nullptr);
        if (!id.ok()) {
            return id.status();
        }
        devices[deviceCount++] = id.value();
        if (last) {
            target = id.value();
        }
    }
    return Status::Ok;
}

void clearAll()
{
    if (targetOpen) {
        (void)systemAgent.Close(target);
        targetOpen = false;
    }
    while (deviceCount > 0) {
        (void)systemAgent.Delete(devices[--deviceCount]);
    }
    target = ObjectId::null();
}

// --- System.Create and System.Delete: one more driver installed and removed.

Status populateButOne(uint32_t count) { return populate(count - 1); }

ObjectId created;

void createDevice()
{
    const Result<ObjectId> id = systemAgent.Create(drivers[deviceCount], nullptr, dcos::Visibility::Local);
    check(id.status());
    created = id.ok() ? id.value() : ObjectId::null();
}

void deleteCreated() { (void)systemAgent.Delete(created); }

void deleteTarget() { check(systemAgent.Delete(target)); }

void reinstallTarget()
{
    const Result<ObjectId> id = systemAgent.Create(drivers[deviceCount - 1], "target", dcos::Visibility::Local);
    check(id.status());
    target = id.ok() ? id.value() : ObjectId::null();
    devices[deviceCount - 1] = target;
}

// --- The device primitives on the target.

void probe() { check(systemAgent.Probe(target)); }
void open() { check(systemAgent.Open(target)); }
void close() { check(systemAgent.Close(target)); }

Status populateOpen(uint32_t count)
{
    const Status status = populate(count);
    if (status != Status::Ok) {
        return status;
    }
    targetOpen = true;
    return systemAgent.Open(target);
}

void read()
{
    const Result<size_t> read = systemAgent.Read(target, 0, buffer, sizeof buffer);
    check(read.status());
    lastValue = read.ok() ? static_cast<uint32_t>(read.value()) : 0;
}

void write()
{
    const Result<size_t> written = systemAgent.Write(target, 0, buffer, sizeof buffer);
    check(written.status());
    lastValue = written.ok() ? static_cast<uint32_t>(written.value()) : 0;
}

void control() { check(systemAgent.Control(target, 1, buffer, sizeof buffer)); }

// --- System.NameToObject (configuration) and System.XferOwnership (from the
// shell to the shell: the owner check and the store, as for any transfer).

void nameToObject()
{
    const Result<ObjectId> id = systemAgent.NameToObject("target");
    check(id.status());
    lastValue = id.ok() ? id.value().raw() : 0;
}

void transferOwnership() { check(systemAgent.XferOwnership(target, self())); }

// --- System.InstallISR on the spare line 10, removed again; SetInterruptLevel
// for the shell (level 12: IRQ 5-7 held), back to none; the legal limit of
// priority 31 set to its default.

constexpr unsigned kSpareLine = 10;

void emptyRoutine(void*) {}

void installIsr() { check(systemAgent.InstallISR(kSpareLine, emptyRoutine, nullptr)); }
void removeIsr() { (void)systemAgent.RemoveISR(kSpareLine); }

void setInterruptLevel()
{
    const Result<uint8_t> level = systemAgent.SetInterruptLevel(12);
    check(level.status());
    lastValue = level.ok() ? level.value() : 0;
}

void clearInterruptLevel() { (void)systemAgent.SetInterruptLevel(0xFF); }

void setLegalLimit() { check(systemAgent.SetInterruptLevel(31, 1)); }

} // namespace

DCOS_BENCHMARK(systemCreateBench, "System.Create", populateButOne, createDevice, Cost::Constant,
               .restore = deleteCreated, .teardown = clearAll);
DCOS_BENCHMARK(systemDeleteBench, "System.Delete", populate, deleteTarget, Cost::Constant,
               .restore = reinstallTarget, .teardown = clearAll);
DCOS_BENCHMARK(systemProbeBench, "System.Probe", populate, probe, Cost::Constant, .teardown = clearAll);
DCOS_BENCHMARK(systemOpenBench, "System.Open", populate, open, Cost::Constant, .restore = close,
               .teardown = clearAll);
DCOS_BENCHMARK(systemCloseBench, "System.Close", populateOpen, close, Cost::Constant, .restore = open,
               .teardown = clearAll);
DCOS_BENCHMARK(systemReadBench, "System.Read", populateOpen, read, Cost::Constant, .teardown = clearAll);
DCOS_BENCHMARK(systemWriteBench, "System.Write", populateOpen, write, Cost::Constant, .teardown = clearAll);
DCOS_BENCHMARK(systemControlBench, "System.Control", populateOpen, control, Cost::Constant, .teardown = clearAll);
DCOS_BENCHMARK(systemNameToObjectBench, "System.NameToObject", populate, nameToObject, Cost::Variable,
               .teardown = clearAll);
DCOS_BENCHMARK(systemXferOwnershipBench, "System.XferOwnership", populate, transferOwnership, Cost::Constant,
               .teardown = clearAll);
DCOS_BENCHMARK(systemInstallIsrBench, "System.InstallISR", populate, installIsr, Cost::Constant, .restore = removeIsr,
               .teardown = clearAll);
DCOS_BENCHMARK(systemSetInterruptLevelBench, "System.SetInterruptLevel", populate, setInterruptLevel, Cost::Constant,
               .restore = clearInterruptLevel, .teardown = clearAll);
DCOS_BENCHMARK(systemSetLegalLimitBench, "System.SetInterruptLevelLimit", populate, setLegalLimit, Cost::Constant,
               .teardown = clearAll);

} // namespace bench
