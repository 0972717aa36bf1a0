# fieldbus/modbus: the portable Modbus RTU stack (docs/protocols/modbus.md).

# Sources with no hardware access at all: built for the host tests, the
# fuzzers (mk/fuzz.mk) and the firmware, where the i486 check covers them.
MODBUS_PORTABLE_SRCS := \
	fieldbus/modbus/src/Crc16.cpp \
	fieldbus/modbus/src/Master.cpp \
	fieldbus/modbus/src/ModbusError.cpp \
	fieldbus/modbus/src/Request.cpp \
	fieldbus/modbus/src/Response.cpp \
	fieldbus/modbus/src/RtuReceiver.cpp \
	fieldbus/modbus/src/RtuTiming.cpp \
	fieldbus/modbus/src/RtuTransport.cpp \
	fieldbus/modbus/src/Server.cpp \
	fieldbus/modbus/src/Slave.cpp
