# Kernel sources with no hardware access: built for the host tests and the firmware.
DCOS_PORTABLE_SRCS := \
	firmware/dcos/src/GregorianCalendar.cpp \
	firmware/dcos/src/ResourceRecovery.cpp \
	firmware/dcos/src/StackArena.cpp \
	firmware/dcos/src/memory/BufferPool.cpp \
	firmware/dcos/src/memory/SegmentedHeap.cpp \
	firmware/dcos/src/MessageBufferPool.cpp \
	firmware/dcos/src/MessageQueue.cpp \
	firmware/dcos/src/application/ConfigurationReport.cpp \
	$(wildcard firmware/dcos/src/system/DeviceManager.cpp) \
	$(wildcard firmware/dcos/src/system/DeviceCommands.cpp)

# Kernel sources that run only on the target: task switching, the tick, traps.
DCOS_TARGET_SRCS := \
	$(wildcard firmware/dcos/src/kernel/*.cpp) \
	$(wildcard firmware/dcos/src/task/*.cpp firmware/dcos/src/task/*.S) \
	$(wildcard firmware/dcos/src/scheduler/*.cpp) \
	$(wildcard firmware/dcos/src/timer/*.cpp) \
	$(wildcard firmware/dcos/src/memory/*Manager.cpp firmware/dcos/src/memory/*Agent.cpp) \
	$(wildcard firmware/dcos/src/memory/MemoryCommands.cpp) \
	firmware/dcos/src/system/InterruptManager.cpp \
	$(wildcard firmware/dcos/src/port/*.cpp) \
	$(wildcard firmware/dcos/src/dsm/*.cpp) \
	$(wildcard firmware/dcos/src/semaphore/*.cpp) \
	firmware/dcos/src/application/ApplicationLoader.cpp \
	firmware/dcos/src/application/ApplicationCommands.cpp
