# drivers/iobus: the ISA resource manager and the multi-function I/O board.

# Sources with no hardware access of their own (the chip goes through the
# mocked port I/O on the host): built for the host tests and the firmware.
IOBUS_PORTABLE_SRCS := \
	drivers/iobus/src/AnalogScaling.cpp \
	drivers/iobus/src/IsaResourceManager.cpp \
	drivers/iobus/src/LinearityFit.cpp \
	drivers/iobus/src/MfioBoard.cpp \
	drivers/iobus/src/MfioChip.cpp \
	drivers/iobus/src/MfioClient.cpp

# Sources that run only on the target: the console command and the bring-up sequence.
IOBUS_TARGET_SRCS := \
	drivers/iobus/src/Bringup.cpp \
	drivers/iobus/src/IobusCommands.cpp
