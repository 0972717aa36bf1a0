// Creates an application's declared objects (dcos/Application.hpp) on this node.
//
// The root task calls startLinked() at boot, before the console shell, for
// the application linked into the image, if any. start() is the same work for
// any configuration; the on-target tests call it with configurations built at
// run time, which the compiler never checked.
//
// Creation is all or nothing. The loader first checks the configuration's
// rules again and that no declared name is already used on the node, then
// creates semaphores, ports, publishers, pools and heaps, then the tasks,
// with dispatching held so that no new task runs before every object exists
// and every id is stored. Then, still before any task runs, the drivers that
// serve declarations of their own (the Modbus map and schedule) take them
// up (internal/ApplicationService.hpp). When any step fails it deletes what
// it created, in reverse, and reports the object that failed. These are configuration
// services: O(N) in the declarations (O(N^2) for the name checks), at boot.
#pragma once

#include <dcos/ApplicationDeclarations.hpp>
#include <dcos/ConfigurationRules.hpp>

namespace dcos::internal {

class ApplicationLoader {
public:
    enum class State : uint8_t {
        None,     ///< No application is linked into the image.
        Running,  ///< Every object was created and the tasks were started.
        Rejected, ///< The configuration was refused; lastError() says why.
    };

    /// Creates every object of @p application, or none. Must run in a task
    /// that is a super user (it activates table slots and may grant
    /// super-user tasks). Returns the first error (rule None on success).
    static app::ConfigurationError start(const app::Application& application);

    /// Deletes every object of a started application (for the tests: an
    /// application normally lives as long as the node). Tasks are killed
    /// first. Returns how many objects it deleted.
    static unsigned stop(const app::Application& application);

    /// Starts the application linked into the image and prints one line on
    /// the console saying what was started, or why not.
    static void startLinked();

    /// The id of the node's object of @p kind named @p name (NameToObject of its agent).
    static Result<ObjectId> find(app::ObjectKind kind, const char* name);

    /// The application linked into the image, or null.
    static const app::Application* linked();
    static State state() { return state_; }
    static const app::ConfigurationError& lastError() { return lastError_; }

private:
    static State state_;
    static app::ConfigurationError lastError_;
};

} // namespace dcos::internal
