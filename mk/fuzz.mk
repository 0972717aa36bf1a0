# Fuzzing the CAN link layer (fieldbus/can), the Modbus stack
# (fieldbus/modbus), the host Modbus tools, the host CAN library's gs_usb
# decoder and the kernel's network tables (firmware/dcos/fuzz) with libFuzzer.
#
#   make fuzz        builds the fuzz targets, replays each seed corpus once,
#                    then fuzzes each target for FUZZ_SECONDS; fails on any crash
#   make test-fuzz   the same without installing packages first (run by 'make test');
#                    both write $(FUZZ_REPORT) for the closing summary
#
# The targets are compiled by Debian's clang with libFuzzer and the address and
# undefined-behaviour sanitizers (packages clang and libclang-rt-14-dev). Any
# sanitizer report aborts the target, so it counts as a crash; the input that
# caused it is kept in $(FUZZ_BUILD)/artifacts/<target>/.

FUZZ_BUILD := $(BUILD)/fuzz
# Fuzzing time per target; some two dozen targets, run $(JOBS) at a time by 'make test'.
FUZZ_SECONDS ?= 15
FUZZ_TARGETS := frame isotp slcan frametext
FUZZ_CORPUS := fieldbus/can/fuzz/corpus
FUZZ_REPORT := $(BUILD)/reports/fuzz-tests.xml
# The Modbus targets: sources, seeds and report of their own, run by the same script.
MODBUS_FUZZ_TARGETS := rtu_receiver slave master
MODBUS_FUZZ_CORPUS := fieldbus/modbus/fuzz/corpus
MODBUS_FUZZ_REPORT := $(BUILD)/reports/fuzz-modbus-tests.xml
# The host Modbus tools' own parsers of outside input (host_tools/modbus):
# command-line values, the simulator's configuration (toml++ compiled in,
# header-only, so it is instrumented with our checks), the frames read from
# the line. They link Debian's fmt and libmodbus, which are not instrumented.
HOST_MODBUS_FUZZ_TARGETS := modbus_arguments modbus_sim_config modbus_frames
HOST_MODBUS_FUZZ_CORPUS := host_tools/modbus/fuzz/corpus
HOST_MODBUS_FUZZ_REPORT := $(BUILD)/reports/fuzz-host-modbus-tests.xml
# The host CAN library's reading of what a gs_usb adapter sends over USB
# (host_tools/can/fuzz): its bulk IN transfers and its answers to
# DEVICE_CONFIG and BT_CONST, with the bit timing computed from the latter.
HOSTCAN_FUZZ_TARGETS := gsusb_frames
HOSTCAN_FUZZ_CORPUS := host_tools/can/fuzz/corpus
HOSTCAN_FUZZ_REPORT := $(BUILD)/reports/fuzz-hostcan-tests.xml
# The kernel's parsers of outside input (firmware/dcos/fuzz): the network
# interfaces manager's address text and tables, which the console sets, and
# the remote transaction and publication messages every node decodes from the bus.
DCOS_FUZZ_TARGETS := network_tables remote_message publication_message time_sync
DCOS_FUZZ_CORPUS := firmware/dcos/fuzz/corpus
DCOS_FUZZ_REPORT := $(BUILD)/reports/fuzz-dcos-tests.xml
# Controller images: the verifier every image a controller is sent passes
# through (firmware/image/fuzz) and dcos-image's ELF reader
# (host_tools/image/fuzz), on Debian's mbedTLS (not instrumented).
IMAGE_FUZZ_TARGETS := image
IMAGE_FUZZ_CORPUS := firmware/image/fuzz/corpus
IMAGE_FUZZ_REPORT := $(BUILD)/reports/fuzz-image-tests.xml
HOST_IMAGE_FUZZ_TARGETS := elf_payload
HOST_IMAGE_FUZZ_CORPUS := host_tools/image/fuzz/corpus
HOST_IMAGE_FUZZ_REPORT := $(BUILD)/reports/fuzz-host-image-tests.xml
# The flash protocol's node side (firmware/flash/fuzz): framing and session.
FLASH_FUZZ_TARGETS := flash_session flash_can
FLASH_FUZZ_CORPUS := firmware/flash/fuzz/corpus
FLASH_FUZZ_REPORT := $(BUILD)/reports/fuzz-flash-tests.xml
# The configuration protocol's node side (firmware/sei/fuzz): requests and
# CAN frames, scans included.
SEI_FUZZ_TARGETS := sei_server
SEI_FUZZ_CORPUS := firmware/sei/fuzz/corpus
SEI_FUZZ_REPORT := $(BUILD)/reports/fuzz-sei-tests.xml
# dcos-mon's reading of the monitoring stream (host_tools/mon/fuzz): every
# frame of type 0x41 the bus brings, decoded by the node's own frame code.
MON_FUZZ_TARGETS := monitor_frames
MON_FUZZ_CORPUS := host_tools/mon/fuzz/corpus
MON_FUZZ_REPORT := $(BUILD)/reports/fuzz-mon-tests.xml
# dcos-config's reading of a saved node configuration (host_tools/config/fuzz),
# the TOML file a user hands to `dcos-config restore`.
CONFIG_FUZZ_TARGETS := saved_node
CONFIG_FUZZ_CORPUS := host_tools/config/fuzz/corpus
CONFIG_FUZZ_REPORT := $(BUILD)/reports/fuzz-config-tests.xml
# The dual-Pentium board's reader of the BIOS's MultiProcessor Specification
# tables (firmware/bsp_p5smp/fuzz), which it believes about its processors
# and interrupt wiring.
P5SMP_FUZZ_TARGETS := mp_table shared_memory_ring
P5SMP_FUZZ_CORPUS := firmware/bsp_p5smp/fuzz/corpus
P5SMP_FUZZ_REPORT := $(BUILD)/reports/fuzz-p5smp-tests.xml
# dcos-flash --recover's reading of what an MCP2221A answers over USB HID
# (host_tools/flash/fuzz): every reply, and whole conversations of the
# reset and strap sequence with a scripted device.
HOSTFLASH_FUZZ_TARGETS := mcp2221_reports
HOSTFLASH_FUZZ_CORPUS := host_tools/flash/fuzz/corpus
HOSTFLASH_FUZZ_REPORT := $(BUILD)/reports/fuzz-hostflash-tests.xml

FUZZ_CXX := clang++
# toml++ is compiled into the fuzz targets as Debian's shared library, which
# the tools use, is built: with its internal assertions off. One of them
# (parse_key, on a control character in a table header) aborts where the
# library as shipped reports a parse error with the line, which is what
# dcos-modbus-sim shows; the seed toml_control_character_in_header keeps
# that answer checked. The sanitizers still see every memory error.
TOML_RELEASE_ASSERT := -D"TOML_ASSERT(expr)=static_assert(true)"
FUZZ_SANITIZERS := address,undefined
FUZZ_CXXFLAGS := -std=c++20 -O1 -g -fno-omit-frame-pointer -fno-sanitize-recover=all \
	-Wall -Wextra -Wno-missing-field-initializers -Werror -MMD -MP \
	-Ifieldbus/can/include -Ifieldbus/modbus/include -Ifirmware/dcos/include \
	-Ihost_tools/modbus/include -Ihost_tools/toml/include -I/usr/include/modbus -Ifirmware/image/include -Ihost_tools/image/include \
	-Ifirmware/flash/include -Ifirmware/boot/include -Ifirmware/runtime/include -Ifirmware/sei/include \
	-Ihost_tools/config/include -Ihost_tools/can/include \
	-Ihost_tools/mon/include \
	$(TOML_RELEASE_ASSERT)
# Objects are instrumented for coverage without libFuzzer's main; the
# targets are linked with it.
FUZZ_COMPILE_FLAGS := $(FUZZ_CXXFLAGS) -fsanitize=fuzzer-no-link,$(FUZZ_SANITIZERS)
FUZZ_LINK_FLAGS := -fsanitize=fuzzer,$(FUZZ_SANITIZERS)

FUZZ_LIBRARY_OBJS := $(patsubst %,$(FUZZ_BUILD)/%.o,$(CAN_PORTABLE_SRCS))
FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/fieldbus/can/fuzz/fuzz_%.cpp.o,$(FUZZ_TARGETS))
FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(FUZZ_TARGETS))
MODBUS_FUZZ_LIBRARY_OBJS := $(patsubst %,$(FUZZ_BUILD)/%.o,$(MODBUS_PORTABLE_SRCS))
MODBUS_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/fieldbus/modbus/fuzz/fuzz_%.cpp.o,$(MODBUS_FUZZ_TARGETS))
MODBUS_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(MODBUS_FUZZ_TARGETS))
HOST_MODBUS_FUZZ_LIBRARY_OBJS := $(patsubst %,$(FUZZ_BUILD)/%.o,$(HOSTMODBUS_SRCS) fieldbus/modbus/src/Crc16.cpp)
HOST_MODBUS_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/host_tools/modbus/fuzz/fuzz_%.cpp.o,$(HOST_MODBUS_FUZZ_TARGETS))
HOST_MODBUS_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(HOST_MODBUS_FUZZ_TARGETS))
# The error frames' reading is SocketCAN's own (SocketCanTransport.cpp's
# decodeErrorFrame), which the gs_usb decoder shares.
HOSTCAN_FUZZ_LIBRARY_OBJS := $(patsubst %,$(FUZZ_BUILD)/%.o,host_tools/can/src/GsUsbProtocol.cpp \
	host_tools/can/src/SocketCanTransport.cpp $(CAN_PORTABLE_SRCS))
HOSTCAN_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/host_tools/can/fuzz/fuzz_%.cpp.o,$(HOSTCAN_FUZZ_TARGETS))
HOSTCAN_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(HOSTCAN_FUZZ_TARGETS))
DCOS_FUZZ_LIBRARY_OBJS := $(FUZZ_BUILD)/firmware/dcos/src/network/NetworkAddress.cpp.o \
	$(FUZZ_BUILD)/firmware/dcos/src/network/RemoteMessage.cpp.o \
	$(FUZZ_BUILD)/firmware/dcos/src/network/PublicationMessage.cpp.o \
	$(FUZZ_BUILD)/firmware/dcos/src/network/TimeSyncMessage.cpp.o \
	$(FUZZ_BUILD)/firmware/dcos/src/network/ClockServo.cpp.o
DCOS_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/firmware/dcos/fuzz/fuzz_%.cpp.o,$(DCOS_FUZZ_TARGETS))
DCOS_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(DCOS_FUZZ_TARGETS))
IMAGE_FUZZ_LIBRARY_OBJS := $(patsubst %,$(FUZZ_BUILD)/%.o,$(IMAGE_SRCS) $(BOOT_RECORD_SRCS))
IMAGE_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/firmware/image/fuzz/fuzz_%.cpp.o,$(IMAGE_FUZZ_TARGETS))
IMAGE_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(IMAGE_FUZZ_TARGETS))
HOST_IMAGE_FUZZ_LIBRARY_OBJS := $(patsubst %,$(FUZZ_BUILD)/%.o,host_tools/image/src/ElfPayload.cpp $(IMAGE_SRCS))
HOST_IMAGE_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/host_tools/image/fuzz/fuzz_%.cpp.o,$(HOST_IMAGE_FUZZ_TARGETS))
HOST_IMAGE_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(HOST_IMAGE_FUZZ_TARGETS))
FLASH_FUZZ_LIBRARY_OBJS := $(patsubst %,$(FUZZ_BUILD)/%.o,$(FLASH_PORTABLE_SRCS) $(IMAGE_SRCS) $(CAN_PORTABLE_SRCS) \
	firmware/boot/src/BootState.cpp firmware/boot/src/BootStateStore.cpp firmware/boot/src/Crc32.cpp)
FLASH_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/firmware/flash/fuzz/fuzz_%.cpp.o,$(FLASH_FUZZ_TARGETS))
FLASH_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(FLASH_FUZZ_TARGETS))
SEI_FUZZ_LIBRARY_OBJS := $(patsubst %,$(FUZZ_BUILD)/%.o,$(SEI_PORTABLE_SRCS) firmware/image/src/Sha256.cpp $(CAN_PORTABLE_SRCS))
SEI_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/firmware/sei/fuzz/fuzz_%.cpp.o,$(SEI_FUZZ_TARGETS))
SEI_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(SEI_FUZZ_TARGETS))
MON_FUZZ_LIBRARY_OBJS := $(patsubst %,$(FUZZ_BUILD)/%.o,host_tools/mon/src/StreamDecoder.cpp \
	firmware/sei/src/MonitorFrame.cpp $(CAN_PORTABLE_SRCS))
MON_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/host_tools/mon/fuzz/fuzz_%.cpp.o,$(MON_FUZZ_TARGETS))
MON_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(MON_FUZZ_TARGETS))
CONFIG_FUZZ_LIBRARY_OBJS := $(patsubst %,$(FUZZ_BUILD)/%.o,$(filter-out %/CanConfigLink.cpp %/NodeSession.cpp,\
	$(HOSTCONFIG_SRCS)) $(SEI_PORTABLE_SRCS) firmware/image/src/Sha256.cpp $(IMAGE_SRCS) $(CAN_PORTABLE_SRCS))
CONFIG_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/host_tools/config/fuzz/fuzz_%.cpp.o,$(CONFIG_FUZZ_TARGETS))
CONFIG_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(CONFIG_FUZZ_TARGETS))
P5SMP_FUZZ_LIBRARY_OBJS := $(FUZZ_BUILD)/firmware/bsp_p5smp/src/MpTable.cpp.o \
	$(FUZZ_BUILD)/firmware/bsp_p5smp/src/SharedMemoryRing.cpp.o
P5SMP_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/firmware/bsp_p5smp/fuzz/fuzz_%.cpp.o,$(P5SMP_FUZZ_TARGETS))
P5SMP_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(P5SMP_FUZZ_TARGETS))
HOSTFLASH_FUZZ_LIBRARY_OBJS := $(patsubst %,$(FUZZ_BUILD)/%.o,host_tools/flash/src/Mcp2221.cpp \
	host_tools/flash/src/Mcp2221Lines.cpp)
HOSTFLASH_FUZZ_TARGET_OBJS := $(patsubst %,$(FUZZ_BUILD)/host_tools/flash/fuzz/fuzz_%.cpp.o,$(HOSTFLASH_FUZZ_TARGETS))
HOSTFLASH_FUZZ_BINARIES := $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(HOSTFLASH_FUZZ_TARGETS))
# Reached only through the pattern rule below, the objects would count as
# intermediate files and be deleted after every build.
.SECONDARY: $(FUZZ_LIBRARY_OBJS) $(FUZZ_TARGET_OBJS) $(MODBUS_FUZZ_LIBRARY_OBJS) $(MODBUS_FUZZ_TARGET_OBJS) \
	$(HOST_MODBUS_FUZZ_LIBRARY_OBJS) $(HOST_MODBUS_FUZZ_TARGET_OBJS) $(DCOS_FUZZ_LIBRARY_OBJS) $(DCOS_FUZZ_TARGET_OBJS) \
	$(IMAGE_FUZZ_LIBRARY_OBJS) $(IMAGE_FUZZ_TARGET_OBJS) $(HOST_IMAGE_FUZZ_LIBRARY_OBJS) $(HOST_IMAGE_FUZZ_TARGET_OBJS) \
	$(FLASH_FUZZ_LIBRARY_OBJS) $(FLASH_FUZZ_TARGET_OBJS) $(SEI_FUZZ_LIBRARY_OBJS) $(SEI_FUZZ_TARGET_OBJS) \
	$(MON_FUZZ_LIBRARY_OBJS) $(MON_FUZZ_TARGET_OBJS) $(CONFIG_FUZZ_LIBRARY_OBJS) $(CONFIG_FUZZ_TARGET_OBJS)
.SECONDARY: $(P5SMP_FUZZ_LIBRARY_OBJS) $(P5SMP_FUZZ_TARGET_OBJS)
.SECONDARY: $(HOSTCAN_FUZZ_LIBRARY_OBJS) $(HOSTCAN_FUZZ_TARGET_OBJS)
.SECONDARY: $(HOSTFLASH_FUZZ_LIBRARY_OBJS) $(HOSTFLASH_FUZZ_TARGET_OBJS)

.PHONY: fuzz test-fuzz fuzz-targets

fuzz: deps
	@$(MAKE) --no-print-directory test-fuzz

fuzz-targets: $(FUZZ_BINARIES) $(MODBUS_FUZZ_BINARIES) $(HOST_MODBUS_FUZZ_BINARIES) $(DCOS_FUZZ_BINARIES) \
	$(IMAGE_FUZZ_BINARIES) $(HOST_IMAGE_FUZZ_BINARIES) $(FLASH_FUZZ_BINARIES) $(SEI_FUZZ_BINARIES) \
	$(MON_FUZZ_BINARIES) $(CONFIG_FUZZ_BINARIES)
fuzz-targets: $(P5SMP_FUZZ_BINARIES)
fuzz-targets: $(HOSTCAN_FUZZ_BINARIES)
fuzz-targets: $(HOSTFLASH_FUZZ_BINARIES)

# A target that does not build is reported as a failed test case, so the
# summary shows it instead of a missing suite. The groups run side by side,
# $(JOBS) at a time (each libFuzzer run takes one core), and every group
# runs even when another fails (-k): the exit status says whether any did.
FUZZ_RUN_GROUPS := CAN MODBUS HOST_MODBUS HOSTCAN DCOS IMAGE HOST_IMAGE FLASH SEI MON CONFIG P5SMP HOSTFLASH
CAN_FUZZ_CORPUS = $(FUZZ_CORPUS)
CAN_FUZZ_REPORT = $(FUZZ_REPORT)
CAN_FUZZ_TARGETS = $(FUZZ_TARGETS)

test-fuzz:
	@mkdir -p $(dir $(FUZZ_REPORT))
	@if $(MAKE) --no-print-directory fuzz-targets; then built=; else built=--build-failed; fi; \
	$(MAKE) --no-print-directory -k -j$(JOBS) FUZZ_BUILT=$$built $(addprefix fuzz-run-,$(FUZZ_RUN_GROUPS))

.PHONY: $(addprefix fuzz-run-,$(FUZZ_RUN_GROUPS))
$(addprefix fuzz-run-,$(FUZZ_RUN_GROUPS)): fuzz-run-%:
	@$(PYTHON) fieldbus/can/fuzz/run_fuzzers.py $(FUZZ_BUILT) --build $(FUZZ_BUILD) --corpus $($*_FUZZ_CORPUS) \
		--seconds $(FUZZ_SECONDS) --report $($*_FUZZ_REPORT) $($*_FUZZ_TARGETS)

$(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/fieldbus/can/fuzz/fuzz_%.cpp.o $(FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^

# A static pattern rule, so the Modbus targets never fall to the CAN one.
$(MODBUS_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/fieldbus/modbus/fuzz/fuzz_%.cpp.o $(MODBUS_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^

$(HOST_MODBUS_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/host_tools/modbus/fuzz/fuzz_%.cpp.o \
		$(HOST_MODBUS_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^ -lfmt -lmodbus

$(HOSTCAN_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/host_tools/can/fuzz/fuzz_%.cpp.o \
		$(HOSTCAN_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^

$(DCOS_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/firmware/dcos/fuzz/fuzz_%.cpp.o $(DCOS_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^

$(IMAGE_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/firmware/image/fuzz/fuzz_%.cpp.o $(IMAGE_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^ -lmbedcrypto

$(HOST_IMAGE_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/host_tools/image/fuzz/fuzz_%.cpp.o \
		$(HOST_IMAGE_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^ -lmbedcrypto

$(FLASH_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/firmware/flash/fuzz/fuzz_%.cpp.o $(FLASH_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^ -lmbedcrypto

$(SEI_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/firmware/sei/fuzz/fuzz_%.cpp.o $(SEI_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^ -lmbedcrypto

$(MON_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/host_tools/mon/fuzz/fuzz_%.cpp.o $(MON_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^

$(CONFIG_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/host_tools/config/fuzz/fuzz_%.cpp.o \
		$(CONFIG_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^ -lfmt -lmbedcrypto

$(P5SMP_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/firmware/bsp_p5smp/fuzz/fuzz_%.cpp.o $(P5SMP_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^

# The board's headers are found only by its own objects, so the flags every
# other object is built with stay as they were.
$(P5SMP_FUZZ_LIBRARY_OBJS) $(P5SMP_FUZZ_TARGET_OBJS): $(FUZZ_BUILD)/%.cpp.o: %.cpp $(FUZZ_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_COMPILE_FLAGS) -Ifirmware/bsp_p5smp/include -c $< -o $@

FUZZ_FLAGS_STAMP := $(FUZZ_BUILD)/flags.stamp
$(FUZZ_FLAGS_STAMP): FORCE
	@mkdir -p $(dir $@)
	@echo '$(FUZZ_COMPILE_FLAGS) $(FUZZ_LINK_FLAGS)' > $@.new
	@cmp -s $@.new $@ && rm -f $@.new || mv $@.new $@

# dcos-flash's headers (host_tools/flash/include) likewise, for its objects only.
$(HOSTFLASH_FUZZ_BINARIES): $(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/host_tools/flash/fuzz/fuzz_%.cpp.o \
		$(HOSTFLASH_FUZZ_LIBRARY_OBJS)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_LINK_FLAGS) -o $@ $^ -lfmt

$(HOSTFLASH_FUZZ_LIBRARY_OBJS) $(HOSTFLASH_FUZZ_TARGET_OBJS): $(FUZZ_BUILD)/%.cpp.o: %.cpp $(FUZZ_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_COMPILE_FLAGS) -Ihost_tools/flash/include -c $< -o $@

$(FUZZ_BUILD)/%.cpp.o: %.cpp $(FUZZ_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)$(FUZZ_CXX) $(FUZZ_COMPILE_FLAGS) -c $< -o $@

-include $(shell find $(FUZZ_BUILD) -name '*.d' 2>/dev/null)
