# firmware/flash: the flash protocol (docs/protocols/flash.md), its
# messages, serial framing, the node's session and its ISO-TP server for
# CAN. Pure code: built for the host tests, the fuzz targets, dcos-flash
# and the stage loader.
FLASH_PORTABLE_SRCS := \
	firmware/flash/src/CanFlashServer.cpp \
	firmware/flash/src/FlashMessage.cpp \
	firmware/flash/src/FlashSession.cpp \
	firmware/flash/src/SerialFramer.cpp

# The kernel's flash service and its console command: the running node
# takes images over CAN (FlashService.hpp). Linked into the images that
# carry the service (FW_FLASH_SERVICE_OBJS, mk/firmware.mk).
FLASH_TARGET_SRCS := \
	firmware/flash/src/FlashService.cpp \
	firmware/flash/src/FlashCommands.cpp
