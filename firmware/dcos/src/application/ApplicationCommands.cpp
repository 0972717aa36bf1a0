// The 'app' console command: the linked application, its state and its objects.
#include <dcos/internal/ApplicationLoader.hpp>
#include <dcos/internal/ConfigurationReport.hpp>
#include <dcos/internal/IdText.hpp>

#include <shell/Shell.hpp>

namespace dcos::internal {

namespace {

template <class Declaration>
void listObjects(shell::Shell& shell, app::ObjectKind kind, const app::DeclarationList<Declaration>& list)
{
    for (const Declaration& declaration : list) {
        const Result<ObjectId> id = ApplicationLoader::find(kind, declaration.name);
        shell.print("  %-12s %-15s ", app::objectKindName(kind), declaration.name);
        if (id.ok()) {
            shell.print("%s", internal::IdText(id.value()).c_str());
        } else {
            shell.print("%-10s", "(none)");
        }
        const char* owner = app::ownerOf(declaration);
        shell.print("  %s\r\n", owner != nullptr ? owner : "-");
    }
}

const char* modbusTableName(app::ModbusTable table)
{
    switch (table) {
    case app::ModbusTable::Coils: return "coils";
    case app::ModbusTable::DiscreteInputs: return "discrete-inputs";
    case app::ModbusTable::HoldingRegisters: return "holding";
    case app::ModbusTable::InputRegisters: return "input";
    }
    return "?";
}

// The declared Modbus map, checked at build and boot, and the slave that
// serves it from boot on. Without a declared slave the listing says the map
// is not served, rather than let an engineer think a master reaches these
// addresses; `modbus state` says what the line serves now.
void listModbusMap(shell::Shell& shell, const app::Application& application)
{
    const app::DeclarationList<app::ModbusMapEntry>& map = application.modbusMap;
    if (map.count == 0) {
        return;
    }
    const app::ModbusSlaveDeclaration& slave = application.modbusSlave;
    if (slave.address == 0) {
        shell.print("  modbus map, %u entries, checked; not served: no modbusSlave declared ('modbus slave' "
                    "serves the console's data model)\r\n",
                    static_cast<unsigned>(map.count));
    } else {
        shell.print("  modbus map, %u entries, checked; served by slave %lu on the RS-485 port at %lu baud 8%c%c\r\n",
                    static_cast<unsigned>(map.count), static_cast<unsigned long>(slave.address),
                    static_cast<unsigned long>(slave.baud),
                    slave.parity == app::ModbusParity::None  ? 'N'
                    : slave.parity == app::ModbusParity::Odd ? 'O'
                                                             : 'E',
                    slave.parity == app::ModbusParity::None ? '2' : '1');
    }
    for (const app::ModbusMapEntry& entry : map) {
        shell.print("    %-15s %-15s %5lu-%-5lu ", entry.name, modbusTableName(entry.table),
                    static_cast<unsigned long>(entry.address),
                    static_cast<unsigned long>(entry.address + entry.count - 1));
        switch (entry.source) {
        case app::ModbusSource::Publisher:
            shell.print("publisher %s byte %lu\r\n", entry.object, static_cast<unsigned long>(entry.offset));
            break;
        case app::ModbusSource::AnalogInput:
            shell.print("analog inputs from %lu\r\n", static_cast<unsigned long>(entry.offset));
            break;
        case app::ModbusSource::DigitalOutput:
            shell.print("digital outputs from %lu\r\n", static_cast<unsigned long>(entry.offset));
            break;
        }
    }
}

shell::CommandResult showApplication(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const app::Application* application = ApplicationLoader::linked();
    if (application == nullptr) {
        shell.print("no application is linked into this image\r\n");
        return shell::CommandResult::Ok;
    }
    if (ApplicationLoader::state() == ApplicationLoader::State::Rejected) {
        formatConfigurationError(shell.output(), application->name, ApplicationLoader::lastError());
        shell.print("\r\n");
        return shell::CommandResult::Failed;
    }
    shell.print("application '%s': running\r\n", application->name);
    shell.print("  %-12s %-15s %-10s  %s\r\n", "kind", "name", "id", "owner");
    listObjects(shell, app::ObjectKind::Task, application->tasks);
    listObjects(shell, app::ObjectKind::Semaphore, application->semaphores);
    listObjects(shell, app::ObjectKind::MessagePort, application->messagePorts);
    listObjects(shell, app::ObjectKind::Publisher, application->publishers);
    listObjects(shell, app::ObjectKind::BufferPool, application->bufferPools);
    listObjects(shell, app::ObjectKind::Heap, application->heaps);
    listModbusMap(shell, *application);
    return shell::CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND(applicationCommand, "app", "show the application, its state and its objects", "app",
                   showApplication);

} // namespace dcos::internal
