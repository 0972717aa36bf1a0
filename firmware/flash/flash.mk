# firmware/flash: the flash protocol (docs/protocols/flash.md), its
# messages, serial framing and the node's session. Pure code: built for the
# host tests, the fuzz targets, dcos-flash and the stage loader.
FLASH_PORTABLE_SRCS := $(wildcard firmware/flash/src/*.cpp)
