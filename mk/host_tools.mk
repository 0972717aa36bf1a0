# Host tools engineers install (host_tools/): C++ on Debian's libraries,
# CLI11 for arguments, fmt for output, nlohmann-json for --json. Their
# libraries' unit tests are part of the host test binary (mk/host.mk).

HOST_TOOLS_BUILD := $(BUILD)/host_tools
HOST_TOOLS_BIN := $(HOST_TOOLS_BUILD)/bin

# The host CAN library: transports behind one interface (host_tools/can).
HOSTCAN_SRCS := $(wildcard host_tools/can/src/*.cpp)
HOSTCAN_TEST_SRCS := $(wildcard host_tools/can/unit_tests/*.cpp)
HOST_TOOLS_LIBS := -lfmt

DCOS_CAN := $(HOST_TOOLS_BIN)/dcos-can
HOST_TOOLS := $(DCOS_CAN)

host-tools: $(HOST_TOOLS)

$(DCOS_CAN): $(BUILD)/host/host_tools/can/tools/dcos-can.cpp.o $(patsubst %,$(BUILD)/host/%.o,$(HOSTCAN_SRCS) $(CAN_PORTABLE_SRCS))
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)g++ -o $@ $^ $(HOST_TOOLS_LIBS)
