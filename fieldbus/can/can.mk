# fieldbus/can: the portable CAN link layer (docs/protocols/can.md).

# Sources with no hardware access at all: built for the host tests, the
# fuzzers (mk/fuzz.mk) and the firmware, where the i486 check covers them.
CAN_PORTABLE_SRCS := \
	fieldbus/can/src/CanFrame.cpp \
	fieldbus/can/src/FrameText.cpp \
	fieldbus/can/src/IsoTpConfig.cpp \
	fieldbus/can/src/IsoTpPci.cpp \
	fieldbus/can/src/IsoTpReceiver.cpp \
	fieldbus/can/src/IsoTpRequestServer.cpp \
	fieldbus/can/src/IsoTpSender.cpp \
	fieldbus/can/src/LinkError.cpp \
	fieldbus/can/src/MessageIdentifier.cpp \
	fieldbus/can/src/SlcanCodec.cpp
