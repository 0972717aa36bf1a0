# The kernel's sources, by kernel configuration (docs/guide/kernel-configurations.md).
#
# The core is what every configuration links: the system, scheduler, task
# and timer agents and what boot needs. The full configuration adds the
# memory, port, DSM and semaphore agents, the network interfaces manager,
# the application loader and the console commands, with its root task (kernel/ConsoleRoot.cpp); the minimal
# one adds only its own root task (kernel/MinimalRoot.cpp). Every source is
# compiled once: an image's configuration is the set of objects it links.

# Kernel sources with no hardware access: built for the host tests and the firmware.
DCOS_PORTABLE_SRCS := \
	firmware/dcos/src/GregorianCalendar.cpp \
	firmware/dcos/src/ObjectTableCore.cpp \
	firmware/dcos/src/ResourceRecovery.cpp \
	firmware/dcos/src/StackArena.cpp \
	firmware/dcos/src/memory/BufferPool.cpp \
	firmware/dcos/src/memory/SegmentedHeap.cpp \
	firmware/dcos/src/MessageBufferPool.cpp \
	firmware/dcos/src/MessageQueue.cpp \
	firmware/dcos/src/application/ConfigurationReport.cpp \
	firmware/dcos/src/system/DeviceManager.cpp \
	firmware/dcos/src/system/DeviceCommands.cpp \
	firmware/dcos/src/network/NetworkAddress.cpp \
	firmware/dcos/src/network/RemoteMessage.cpp \
	firmware/dcos/src/network/PublicationMessage.cpp \
	firmware/dcos/src/network/TimeSyncMessage.cpp \
	firmware/dcos/src/network/ClockServo.cpp \
	firmware/dcos/src/network/RemoteForward.cpp \
	firmware/dcos/src/network/RemoteMemoryHolds.cpp

# Kernel sources that run only on the target: task switching, the tick, traps.
DCOS_TARGET_SRCS := \
	firmware/dcos/src/kernel/Kernel.cpp \
	firmware/dcos/src/kernel/ConsoleRoot.cpp \
	firmware/dcos/src/kernel/KernelCommands.cpp \
	firmware/dcos/src/kernel/BootCommands.cpp \
	$(wildcard firmware/dcos/src/task/*.cpp firmware/dcos/src/task/*.S) \
	$(wildcard firmware/dcos/src/scheduler/*.cpp firmware/dcos/src/scheduler/*.S) \
	$(wildcard firmware/dcos/src/timer/*.cpp) \
	$(wildcard firmware/dcos/src/memory/*Manager.cpp firmware/dcos/src/memory/*Agent.cpp) \
	$(wildcard firmware/dcos/src/memory/MemoryCommands.cpp) \
	firmware/dcos/src/system/InterruptManager.cpp \
	$(wildcard firmware/dcos/src/port/*.cpp) \
	$(wildcard firmware/dcos/src/dsm/*.cpp) \
	$(wildcard firmware/dcos/src/semaphore/*.cpp) \
	firmware/dcos/src/application/ApplicationLoader.cpp \
	firmware/dcos/src/application/ApplicationCommands.cpp \
	firmware/dcos/src/network/NetworkInterfacesManager.cpp \
	firmware/dcos/src/network/RemoteAgent.cpp \
	firmware/dcos/src/network/NameService.cpp \
	firmware/dcos/src/network/GlobalTime.cpp \
	firmware/dcos/src/network/NetworkCommands.cpp \
	firmware/dcos/src/ObjectDirectory.cpp

# The full configuration's kernel, in link order (which is the order of the
# console commands' and the agents' recovery tables).
DCOS_FULL_SRCS := $(DCOS_PORTABLE_SRCS) $(DCOS_TARGET_SRCS)

# The core: the system agent (devices and interrupts), the scheduler, task
# and timer agents, the kernel entry and what they share.
DCOS_CORE_SRCS := \
	firmware/dcos/src/kernel/Kernel.cpp \
	firmware/dcos/src/GregorianCalendar.cpp \
	firmware/dcos/src/ObjectTableCore.cpp \
	firmware/dcos/src/ResourceRecovery.cpp \
	firmware/dcos/src/StackArena.cpp \
	firmware/dcos/src/system/DeviceManager.cpp \
	firmware/dcos/src/system/InterruptManager.cpp \
	$(wildcard firmware/dcos/src/task/*.cpp firmware/dcos/src/task/*.S) \
	$(wildcard firmware/dcos/src/scheduler/*.cpp firmware/dcos/src/scheduler/*.S) \
	$(wildcard firmware/dcos/src/timer/*.cpp) \
	firmware/dcos/src/network/RemoteForward.cpp

# The minimal configuration's kernel: the core, in the full one's order, and its root task.
DCOS_MINIMAL_SRCS := $(filter $(DCOS_CORE_SRCS),$(DCOS_FULL_SRCS)) firmware/dcos/src/kernel/MinimalRoot.cpp
