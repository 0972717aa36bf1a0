# drivers/modbus: the controller's Modbus RTU line on the board's RS-485
# port (COM2), over fieldbus/modbus's portable stack.

# Sources with no hardware access of their own: built for the host tests and the firmware.
MODBUS_DRIVER_PORTABLE_SRCS := \
	drivers/modbus/src/ApplicationMapModel.cpp \
	drivers/modbus/src/LineRunner.cpp

# Sources that run only on the target: the line's task and the console command.
MODBUS_DRIVER_TARGET_SRCS := \
	drivers/modbus/src/BoardLine.cpp \
	drivers/modbus/src/ModbusCommands.cpp \
	drivers/modbus/src/NodeMapBackend.cpp \
	drivers/modbus/src/PollLine.cpp
