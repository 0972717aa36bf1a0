# The dual-Pentium board's images (firmware/bsp_p5smp; docs/boards/p5smp.md).
#
# The same kernel runs on both boards: the p5smp images link the ISA board's
# objects (FW_OBJS, compiled once for the i486, which the Pentium runs as
# they are) except the board file and the one kernel source that inlines
# the board's tick timer (bsp/BoardTick.hpp: TimerManager.cpp reads the time
# since the last tick on every clock read). Those, the board's own sources
# and PCI are compiled here for the Pentium, with this board's include
# folder first so that its bsp/BoardTick.hpp is the one found. The two
# BoardTick.hpp headers name their variables differently (tickTimerDivisor
# on the 486, apicTickCounts here), so an object compiled against the other
# board's header cannot link into an image unnoticed.

FWP5_BUILD := $(BUILD)/fwp5
FWP5_IMAGES_STAMP := $(FWP5_BUILD)/images.stamp
FWP5_ARCH_FLAGS := -m32 -march=pentium -mtune=pentium
FWP5_INCLUDES := -Ifirmware/bsp_p5smp/include $(FW_INCLUDES)
FWP5_CXXFLAGS := $(subst $(FW_ARCH_FLAGS),$(FWP5_ARCH_FLAGS),$(FW_CODE_FLAGS)) $(FW_WARNING_FLAGS) -Werror -MMD -MP \
	$(FWP5_INCLUDES)
FWP5_ASFLAGS := $(FWP5_ARCH_FLAGS) -MMD -MP $(FWP5_INCLUDES)

# Sources compiled for this board: its own, and the kernel's that inline the tick.
P5SMP_BOARD_SRCS := $(sort $(wildcard firmware/bsp_p5smp/src/*.cpp firmware/bsp_p5smp/src/*.S))
FWP5_KERNEL_SRCS := firmware/dcos/src/timer/TimerManager.cpp
fwp5_objects = $(patsubst %,$(FWP5_BUILD)/%.o,$(1))
FWP5_OWN_OBJS := $(call fwp5_objects,$(P5SMP_BOARD_SRCS) $(FWP5_KERNEL_SRCS))
# The ISA board's objects this board does not link.
FWP5_REPLACED_OBJS := $(call fw_objects,$(wildcard firmware/bsp_486/src/Board486.cpp) $(FWP5_KERNEL_SRCS))
FWP5_OBJS := $(filter-out $(FWP5_REPLACED_OBJS),$(FW_OBJS)) $(FWP5_OWN_OBJS)

# Node 3's images: the production and test images' objects linked at
# 16 MiB, the upper half of the board's memory (bsp/SecondProcessor.hpp).
# Node 2's production image carries node 3's production image, and its test
# image node 3's test image, stripped, as data (node3-image.o, whose symbols
# _binary_node3_stripped_elf_start and _end BoardP5smp.cpp names: objcopy
# names them after the input file, hence one folder per kind), and loads it
# when it starts the second processor. The --defsym comes before the linker
# script, whose DEFINED() sees only what is defined by then.
IMAGE_P5SMP_NODE3 := $(BUILD)/p5smp/dcos-p5smp-node3.elf
IMAGE_P5SMP_NODE3_TEST := $(BUILD)/p5smp/dcos-p5smp-node3-test.elf
FWP5_NODE3_LOAD_ADDRESS := 0x1000000
FWP5_NODE3_BLOB := $(FWP5_BUILD)/node3/node3-image.o
FWP5_NODE3_TEST_BLOB := $(FWP5_BUILD)/node3-test/node3-image.o

$(IMAGE_P5SMP_NODE3): $(FWP5_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY) firmware/boot/link.ld \
		$(FWP5_IMAGES_STAMP)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld --defsym=__image_load_address=$(FWP5_NODE3_LOAD_ADDRESS) $(FW_LDFLAGS) -o $@ $(FWP5_OBJS) \
		$(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY)

$(IMAGE_P5SMP_NODE3_TEST): $(FWP5_OBJS) $(FW_TARGET_TEST_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY) \
		firmware/boot/link.ld $(FWP5_IMAGES_STAMP)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld --defsym=__image_load_address=$(FWP5_NODE3_LOAD_ADDRESS) $(FW_LDFLAGS) -o $@ $(FWP5_OBJS) \
		$(FW_TARGET_TEST_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY)

$(FWP5_NODE3_BLOB): $(IMAGE_P5SMP_NODE3)
$(FWP5_NODE3_TEST_BLOB): $(IMAGE_P5SMP_NODE3_TEST)
$(FWP5_NODE3_BLOB) $(FWP5_NODE3_TEST_BLOB):
	@mkdir -p $(dir $@)
	@echo "  BLOB    $@"
	$(Q)objcopy --strip-all $< $(dir $@)node3-stripped.elf
	$(Q)cd $(dir $@) && objcopy -I binary -O elf32-i386 -B i386 \
		--rename-section .data=.rodata.node3_image,alloc,load,readonly,data,contents \
		--add-section .note.GNU-stack=/dev/null node3-stripped.elf node3-image.o

$(IMAGE_P5SMP): $(FWP5_OBJS) $(FWP5_NODE3_BLOB) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY) firmware/boot/link.ld \
		$(FWP5_IMAGES_STAMP)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld $(FW_LDFLAGS) -o $@ $(FWP5_OBJS) $(FWP5_NODE3_BLOB) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY)

# The same on-target test suite as the ISA board's test image, on both nodes.
$(IMAGE_P5SMP_TEST): $(FWP5_OBJS) $(FWP5_NODE3_TEST_BLOB) $(FW_TARGET_TEST_OBJS) $(FW_FLASH_SERVICE_OBJS) \
		$(MBEDTLS_FW_LIBRARY) firmware/boot/link.ld $(FWP5_IMAGES_STAMP)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld $(FW_LDFLAGS) -o $@ $(FWP5_OBJS) $(FWP5_NODE3_TEST_BLOB) $(FW_TARGET_TEST_OBJS) $(FW_FLASH_SERVICE_OBJS) \
		$(MBEDTLS_FW_LIBRARY)

$(FWP5_IMAGES_STAMP): FORCE
	@mkdir -p $(dir $@)
	@echo '$(FWP5_OBJS) $(FW_TARGET_TEST_OBJS) $(FW_FLASH_SERVICE_OBJS)' | $(update_if_changed)

FWP5_FLAGS_STAMP := $(FWP5_BUILD)/flags.stamp
$(FWP5_FLAGS_STAMP): FORCE
	@mkdir -p $(dir $@)
	@echo '$(FWP5_CXXFLAGS) $(FWP5_ASFLAGS)' | $(update_if_changed)

$(FWP5_BUILD)/%.cpp.o: %.cpp $(FWP5_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)g++ $(FWP5_CXXFLAGS) -c $< -o $@

$(FWP5_BUILD)/%.S.o: %.S $(FWP5_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)g++ $(FWP5_ASFLAGS) -c $< -o $@

-include $(shell find $(FWP5_BUILD) -name '*.d' 2>/dev/null)
