// How the kernel compiles its configuration services.
#pragma once

// The seed divides the agents' services into real-time services, which must
// be O(1), and configuration services (Create, Delete, NameToObject,
// XferOwnership, AddObjects, Open and Close, resource recovery), which may
// be O(N) because an application calls them while it sets itself up or
// tears itself down, never inside a control loop (seed 6.4, 7.1). Marking a
// configuration service cold makes GCC compile it, and the helpers only it
// calls, for size rather than speed, and place it apart from the real-time
// paths, so that those stay dense in the 486's cache. `make bench` reports
// what each class costs (docs/performance.md, "Footprint").
#define DCOS_CONFIGURATION_SERVICE [[gnu::cold]]
