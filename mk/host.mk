# Host unit tests: the firmware's portable parts, built natively and tested
# with GoogleTest. DCOS_HOST_BUILD swaps port I/O for a recording mock.

HOST_BUILD := $(BUILD)/host
HOST_CXXFLAGS := -std=c++20 -O1 -g -Wall -Wextra -Wno-missing-field-initializers -Werror -DDCOS_HOST_BUILD -MMD -MP $(FW_INCLUDES) \
	-Ifirmware/bsp_p5smp/include \
	-Ihost_tools/can/include $(HOSTMODBUS_CXXFLAGS) -Ifirmware/image/include -Ihost_tools/image/include \
	-Ifirmware/flash/include -Ihost_tools/flash/include -Ifirmware/sei/include -Ihost_tools/config/include \
	$(HOSTMON_CXXFLAGS)

# Firmware sources with no hardware access of their own (chip drivers go
# through the mocked port I/O).
HOST_PORTABLE_SRCS := \
	firmware/arch_x86/src/CpuException.cpp \
	firmware/runtime/src/Int64Division.cpp \
	firmware/runtime/src/Format.cpp \
	firmware/boot/src/CommandLine.cpp \
	firmware/boot/src/BootState.cpp \
	firmware/boot/src/BootControl.cpp \
	firmware/boot/src/BootStateStore.cpp \
	firmware/boot/src/ConfigurationStore.cpp \
	firmware/boot/src/ConfigurationBlock.cpp \
	firmware/boot/src/Crc32.cpp \
	$(wildcard firmware/shell/src/*.cpp) \
	$(DCOS_PORTABLE_SRCS) \
	firmware/bsp_486/src/Pic8259.cpp \
	firmware/bsp_486/src/Pit8254.cpp \
	firmware/bsp_486/src/Rtc146818.cpp \
	firmware/bsp_486/src/Uart16550.cpp \
	$(P5SMP_PORTABLE_SRCS) \
	$(PCI_DRIVER_PORTABLE_SRCS) \
	$(IOBUS_PORTABLE_SRCS) \
	$(CAN_PORTABLE_SRCS) \
	$(MODBUS_PORTABLE_SRCS) \
	$(CAN_DRIVER_PORTABLE_SRCS) \
	$(ATA_DRIVER_PORTABLE_SRCS) \
	$(MODBUS_DRIVER_PORTABLE_SRCS) \
	$(HOSTCAN_SRCS) \
	$(HOSTMODBUS_SRCS) \
	$(IMAGE_SRCS) \
	$(HOSTIMAGE_SRCS) \
	$(FLASH_PORTABLE_SRCS) \
	$(HOSTFLASH_SRCS) \
	$(SEI_PORTABLE_SRCS) \
	$(HOSTCONFIG_SRCS) \
	$(HOSTMON_SRCS)

HOST_TEST_SRCS := $(wildcard firmware/*/unit_tests/*.cpp drivers/*/unit_tests/*.cpp fieldbus/*/unit_tests/*.cpp \
	host_tools/*/unit_tests/*.cpp)
HOST_OBJS := $(patsubst %,$(HOST_BUILD)/%.o,$(HOST_PORTABLE_SRCS) $(HOST_TEST_SRCS))
HOST_TEST_BINARY := $(HOST_BUILD)/unit_tests

host-tests: $(HOST_TEST_BINARY)

$(HOST_TEST_BINARY): $(HOST_OBJS)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)g++ -o $@ $^ -lgtest -lgtest_main -pthread $(HOST_TOOLS_LIBS) $(HOSTMON_LIBS) $(HOSTCAN_LIBS)

HOST_FLAGS_STAMP := $(HOST_BUILD)/flags.stamp
$(HOST_FLAGS_STAMP): FORCE
	@mkdir -p $(dir $@)
	@echo '$(HOST_CXXFLAGS)' | $(update_if_changed)

$(HOST_BUILD)/%.cpp.o: %.cpp $(HOST_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)g++ $(HOST_CXXFLAGS) $(HOST_FILE_FLAGS) -c $< -o $@

-include $(shell find $(HOST_BUILD) -name '*.d' 2>/dev/null)

# Flags of one file (outside the flags stamp, which would otherwise take
# them from whichever file's build first reached it). The image verifier's
# tests read Wycheproof's vectors from the tree.
$(HOST_BUILD)/firmware/image/unit_tests/EcdsaP256WycheproofTest.cpp.o: \
	HOST_FILE_FLAGS := -DDCOS_IMAGE_TEST_DATA='"$(CURDIR)/firmware/image/unit_tests"'
