# drivers/can: the SJA1000 CAN controller, one chip core with bus front ends.

# Sources with no hardware access of their own (the chip goes through the
# mocked port I/O on the host): built for the host tests and the firmware.
CAN_DRIVER_PORTABLE_SRCS := \
	drivers/can/src/BitTiming.cpp \
	drivers/can/src/BoardCanChannel.cpp \
	drivers/can/src/IsaSja1000Channel.cpp \
	drivers/can/src/KvaserPciCard.cpp \
	drivers/can/src/PciSja1000Channel.cpp \
	drivers/can/src/Sja1000Chip.cpp \
	drivers/can/src/Sja1000Controller.cpp

# Sources that run only on the target: the console command.
CAN_DRIVER_TARGET_SRCS := \
	drivers/can/src/CanNetworkLink.cpp \
	drivers/can/src/CanCommands.cpp
