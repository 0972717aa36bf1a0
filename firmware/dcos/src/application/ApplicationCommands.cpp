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
    return shell::CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND(applicationCommand, "app", "show the application, its state and its objects", "app",
                   showApplication);

} // namespace dcos::internal
