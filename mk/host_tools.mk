# Host tools engineers install (host_tools/): C++ on Debian's libraries,
# CLI11 for arguments, fmt for output, nlohmann-json for --json. Their
# libraries' unit tests are part of the host test binary (mk/host.mk).

HOST_TOOLS_BUILD := $(BUILD)/host_tools
HOST_TOOLS_BIN := $(HOST_TOOLS_BUILD)/bin

# The host CAN library: transports behind one interface (host_tools/can).
HOSTCAN_SRCS := $(wildcard host_tools/can/src/*.cpp)
HOSTCAN_TEST_SRCS := $(wildcard host_tools/can/unit_tests/*.cpp)
# gs_usb adapters are reached through Debian's libusb-1.0 (libusb-1.0-0-dev),
# so every program that links the library links it too; the source names
# the header's folder itself, so no include path is needed.
HOSTCAN_LIBS := $(shell pkg-config --libs libusb-1.0 2>/dev/null || echo -lusb-1.0)
# The host Modbus library (host_tools/modbus): argument and configuration
# checks, device identification framing, the simulator's behaviours, on
# Debian's libmodbus and toml++ (the shared library, hence the defines).
HOSTMODBUS_SRCS := $(wildcard host_tools/modbus/src/*.cpp)
HOSTMODBUS_CXXFLAGS := -Ihost_tools/modbus/include -Ihost_tools/toml/include -I/usr/include/modbus -DTOML_HEADER_ONLY=0 -DTOML_SHARED_LIB=1
# Controller images (docs/boot.md): the format and the verifier the stage
# loader uses (firmware/image), and the host's ELF reader and signer
# (host_tools/image), on Debian's mbedTLS.
IMAGE_SRCS := $(wildcard firmware/image/src/*.cpp)
HOSTIMAGE_SRCS := $(wildcard host_tools/image/src/*.cpp)
# dcos-flash's link to a node (host_tools/flash), on the protocol's own code (firmware/flash).
HOSTFLASH_SRCS := $(wildcard host_tools/flash/src/*.cpp)
# dcos-flash --recover drives a node's reset and strap lines on an MCP2221A
# through Debian's hidapi (libhidapi-dev), hidraw back end; only the tool
# links it: the unit tests drive the same sequence through a fake device.
HOSTFLASH_HIDAPI_SRCS := host_tools/flash/hidapi/HidapiDevice.cpp
HOSTFLASH_HIDAPI_LIBS := $(shell pkg-config --libs hidapi-hidraw 2>/dev/null || echo -lhidapi-hidraw)
# dcos-config's scan, requests and link to the nodes (host_tools/config), on
# the configuration protocol's own code (firmware/sei).
HOSTCONFIG_SRCS := $(wildcard host_tools/config/src/*.cpp)
# dcos-mon's stream reader, link and trend plot (host_tools/mon), on the
# monitoring stream's own frame code (firmware/sei) and Debian's cairo,
# which draws the PNG (pkg-config knows its include path; the fallback is
# where Debian puts it).
HOSTMON_SRCS := $(wildcard host_tools/mon/src/*.cpp)
HOSTMON_CXXFLAGS := -Ihost_tools/mon/include $(shell pkg-config --cflags cairo 2>/dev/null || echo -I/usr/include/cairo)
HOSTMON_LIBS := -lcairo
# The card's records, the firmware's own code (firmware/boot), which the
# host's card tool writes and reads.
BOOT_RECORD_SRCS := firmware/boot/src/BootState.cpp firmware/boot/src/BootStateStore.cpp firmware/boot/src/ConfigurationStore.cpp \
	firmware/boot/src/ConfigurationBlock.cpp firmware/boot/src/Crc32.cpp
HOST_TOOLS_LIBS := -lfmt -lmodbus -ltomlplusplus -lmbedcrypto

DCOS_CAN := $(HOST_TOOLS_BIN)/dcos-can
DCOS_MODBUS := $(HOST_TOOLS_BIN)/dcos-modbus
DCOS_MODBUS_SIM := $(HOST_TOOLS_BIN)/dcos-modbus-sim
DCOS_IMAGE := $(HOST_TOOLS_BIN)/dcos-image
DCOS_CARD := $(HOST_TOOLS_BIN)/dcos-card
DCOS_FLASH := $(HOST_TOOLS_BIN)/dcos-flash
DCOS_CONFIG := $(HOST_TOOLS_BIN)/dcos-config
DCOS_MON := $(HOST_TOOLS_BIN)/dcos-mon
HOST_TOOLS := $(DCOS_CAN) $(DCOS_MODBUS) $(DCOS_MODBUS_SIM) $(DCOS_IMAGE) $(DCOS_CARD) $(DCOS_FLASH) $(DCOS_CONFIG) \
	$(DCOS_MON)

host-tools: $(HOST_TOOLS)

# dcos-can decodes remote transactions, publications and the global time base's
# frames with the kernel's own codecs.
$(DCOS_CAN): $(BUILD)/host/host_tools/can/tools/dcos-can.cpp.o $(patsubst %,$(BUILD)/host/%.o,$(HOSTCAN_SRCS) $(CAN_PORTABLE_SRCS) \
	firmware/dcos/src/network/RemoteMessage.cpp firmware/dcos/src/network/PublicationMessage.cpp \
	firmware/dcos/src/network/TimeSyncMessage.cpp)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)g++ -o $@ $^ $(HOST_TOOLS_LIBS) $(HOSTCAN_LIBS)

# The Modbus tools need only the stack's CRC from fieldbus/modbus.
HOSTMODBUS_OBJS := $(patsubst %,$(BUILD)/host/%.o,$(HOSTMODBUS_SRCS) fieldbus/modbus/src/Crc16.cpp)

$(DCOS_MODBUS): $(BUILD)/host/host_tools/modbus/tools/dcos-modbus.cpp.o $(HOSTMODBUS_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)g++ -o $@ $^ $(HOST_TOOLS_LIBS)

$(DCOS_MODBUS_SIM): $(BUILD)/host/host_tools/modbus/tools/dcos-modbus-sim.cpp.o $(HOSTMODBUS_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)g++ -o $@ $^ $(HOST_TOOLS_LIBS)

$(DCOS_IMAGE) $(DCOS_CARD): $(HOST_TOOLS_BIN)/%: $(BUILD)/host/host_tools/image/tools/%.cpp.o \
	$(patsubst %,$(BUILD)/host/%.o,$(IMAGE_SRCS) $(HOSTIMAGE_SRCS) $(BOOT_RECORD_SRCS))
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)g++ -o $@ $^ -lfmt -lmbedcrypto

$(DCOS_FLASH): $(BUILD)/host/host_tools/flash/tools/dcos-flash.cpp.o \
	$(patsubst %,$(BUILD)/host/%.o,$(HOSTFLASH_SRCS) $(HOSTFLASH_HIDAPI_SRCS) $(FLASH_PORTABLE_SRCS) $(IMAGE_SRCS) \
		$(HOSTIMAGE_SRCS) $(BOOT_RECORD_SRCS) $(HOSTCAN_SRCS) $(CAN_PORTABLE_SRCS))
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)g++ -o $@ $^ -lfmt -lmbedcrypto $(HOSTCAN_LIBS) $(HOSTFLASH_HIDAPI_LIBS)

$(DCOS_CONFIG): $(BUILD)/host/host_tools/config/tools/dcos-config.cpp.o \
	$(patsubst %,$(BUILD)/host/%.o,$(HOSTCONFIG_SRCS) $(SEI_PORTABLE_SRCS) $(IMAGE_SRCS) $(HOSTIMAGE_SRCS) $(BOOT_RECORD_SRCS) \
		$(HOSTCAN_SRCS) $(CAN_PORTABLE_SRCS))
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)g++ -o $@ $^ -lfmt -lmbedcrypto -ltomlplusplus $(HOSTCAN_LIBS)

# dcos-mon: the configuration protocol's client and requests (host_tools/config)
# to start and renew the stream, its own link and reader (host_tools/mon).
$(DCOS_MON): $(BUILD)/host/host_tools/mon/tools/dcos-mon.cpp.o \
	$(patsubst %,$(BUILD)/host/%.o,$(HOSTMON_SRCS) $(HOSTCONFIG_SRCS) $(SEI_PORTABLE_SRCS) $(IMAGE_SRCS) $(HOSTIMAGE_SRCS) \
		$(BOOT_RECORD_SRCS) $(HOSTCAN_SRCS) $(CAN_PORTABLE_SRCS))
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)g++ -o $@ $^ -lfmt -lmbedcrypto -ltomlplusplus $(HOSTMON_LIBS) $(HOSTCAN_LIBS)
