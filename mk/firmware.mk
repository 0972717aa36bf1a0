# Freestanding firmware for the ISA i486 board.
#
# The firmware is C++20 without exceptions, RTTI or the C++ runtime, built
# for -march=i486 and linked with ld directly so that no part of the
# distribution's 32-bit libgcc (built for i686, with CMOV) gets in.

FW_BUILD := $(BUILD)/fw486

FW_INCLUDES := \
	-Ifirmware/runtime/include \
	-Ifirmware/arch_x86/include \
	-Ifirmware/boot/include \
	-Ifirmware/shell/include \
	-Ifirmware/dcos/include \
	-Ifirmware/bsp_486/include \
	-Idrivers/iobus/include \
	-Ifieldbus/can/include \
	-Ifieldbus/modbus/include \
	-Idrivers/can/include \
	-Idrivers/pci/include \
	-Idrivers/modbus/include \
	-Idrivers/ata/include

FW_ARCH_FLAGS := -m32 -march=i486 -mtune=i486
# How every firmware object is compiled, the kernel's and an application's
# alike (mk/sdk.mk hands these to applications through the installed DCOS).
# -mregparm=3 passes a call's first three arguments in registers: every
# kernel service an application calls saves its pushes and loads. Kernel
# and applications must agree on it, hence here; the assembly stubs keep the
# stack convention (arch_x86/AssemblyLinkage.hpp). -freg-struct-return
# returns a structure of up to eight bytes in EAX:EDX, as the other i386
# ABIs do, instead of through a hidden pointer to the caller's memory: a
# Result<ObjectId>, Result<void*> or Result<uint32_t> (a value and a Status)
# is most primitives' answer. No alignment padding of
# functions, loops or jump targets: -mtune=i486 pads each to 16 bytes, a
# tenth of the kernel's code, for a prefetch gain the 486's 8 KiB cache
# gives back as misses; padding in a hot path is also executed as no-ops.
# No frame pointer (-fomit-frame-pointer): EBP is a seventh register, and
# every call saves its push, move and pop; the panic report's back trace
# scans the stack for return addresses instead of following EBP
# (boot/src/Panic.cpp), and debuggers unwind from the DWARF frame tables -g
# writes. A 4-byte stack (-mpreferred-stack-boundary=2): nothing here uses
# SSE (-mgeneral-regs-only), so no frame needs 16-byte alignment, and the
# SUB and ADD that kept it are gone from every call that makes one.
# Applications get the same flags (mk/sdk.mk), so both sides agree.
FW_CODE_FLAGS := -std=c++20 $(FW_ARCH_FLAGS) -mregparm=3 -freg-struct-return -mpreferred-stack-boundary=2 -O2 \
	-falign-functions=1 -falign-jumps=1 -falign-loops=1 -falign-labels=1 -g \
	-ffreestanding -fno-pic -fno-pie -fno-exceptions -fno-rtti -fno-threadsafe-statics \
	-fno-stack-protector -fstack-clash-protection -fno-asynchronous-unwind-tables -fno-unwind-tables \
	-fomit-frame-pointer -fno-tree-loop-distribute-patterns -mgeneral-regs-only \
	-fno-isolate-erroneous-paths-dereference -fno-isolate-erroneous-paths-attribute \
	-ffunction-sections -fdata-sections
# An ignored Status or Result is an error in applications too, whose build
# does not otherwise stop at warnings (dcos/Status.hpp says why).
FW_WARNING_FLAGS := -Wall -Wextra -Wno-missing-field-initializers -Werror=unused-result
FW_CXXFLAGS := $(FW_CODE_FLAGS) $(FW_WARNING_FLAGS) -Werror -MMD -MP $(FW_INCLUDES)
FW_ASFLAGS := $(FW_ARCH_FLAGS) -MMD -MP $(FW_INCLUDES)
# --gc-sections drops what nothing reaches, each function and object on its
# own (-ffunction-sections -fdata-sections); the linker script keeps the
# kernel's application interface and the tables the linker gathers.
FW_LDFLAGS := -m elf_i386 -nostdlib -static --gc-sections -T firmware/boot/link.ld

include firmware/dcos/dcos.mk
include drivers/iobus/iobus.mk
include fieldbus/can/can.mk
include fieldbus/modbus/modbus.mk
include drivers/can/can.mk
include drivers/pci/pci.mk
include firmware/bsp_p5smp/p5smp.mk
include drivers/modbus/modbus.mk
include drivers/ata/ata.mk
include firmware/flash/flash.mk
include firmware/sei/sei.mk

# Sources every image contains, whatever its kernel configuration: the
# runtime, the CPU, the loader's entry and the board.
FW_BASE_SRCS := \
	$(wildcard firmware/runtime/src/*.cpp) \
	$(wildcard firmware/arch_x86/src/*.cpp firmware/arch_x86/src/*.S) \
	$(wildcard firmware/boot/src/*.cpp firmware/boot/src/*.S) \
	$(wildcard firmware/bsp_486/src/*.cpp)

# The full kernel configuration (docs/guide/kernel-configurations.md): every
# agent, the application loader, the console shell and the drivers. The
# production, test and bench images and the SDK's library are built from it.
# In link order, which is the order of the tables the linker gathers (console
# commands, recovery functions): hence the base sources spelt out around the
# shell and the kernel rather than as FW_BASE_SRCS.
FW_SRCS := \
	$(wildcard firmware/runtime/src/*.cpp) \
	$(wildcard firmware/arch_x86/src/*.cpp firmware/arch_x86/src/*.S) \
	$(wildcard firmware/boot/src/*.cpp firmware/boot/src/*.S) \
	$(wildcard firmware/shell/src/*.cpp) \
	$(DCOS_FULL_SRCS) \
	$(wildcard firmware/bsp_486/src/*.cpp) \
	$(IOBUS_PORTABLE_SRCS) \
	$(IOBUS_TARGET_SRCS) \
	$(CAN_PORTABLE_SRCS) \
	$(MODBUS_PORTABLE_SRCS) \
	$(CAN_DRIVER_PORTABLE_SRCS) \
	$(CAN_DRIVER_TARGET_SRCS) \
	$(PCI_DRIVER_PORTABLE_SRCS) \
	$(MODBUS_DRIVER_PORTABLE_SRCS) \
	$(MODBUS_DRIVER_TARGET_SRCS) \
	$(ATA_DRIVER_PORTABLE_SRCS)

# The minimal kernel configuration: the system, scheduler, task and timer
# agents and what boot needs; no shell, no console commands, no other agent,
# no application loader, no drivers. Its objects are the full
# configuration's, compiled once, but for its own root task.
FW_MINIMAL_SRCS := $(FW_BASE_SRCS) $(DCOS_MINIMAL_SRCS)
# The minimal image's application: the built-in self-check, its proof of life.
FW_SELFCHECK_SRCS := $(wildcard firmware/selfcheck/src/*.cpp)

# The on-target test suite, linked only into the test image.
FW_TARGET_TEST_SRCS := $(wildcard tests_renode/target/*.cpp)
# The kernel-core on-target tests the minimal kernel runs (those that need
# no agent, driver or shell command it leaves out; tests_renode/test_minimal_kernel.py),
# with the runner that takes the test's name from the kernel command line.
# The shell's sources are only the tests' output there (they print through
# a shell object); no shell runs.
FW_MINIMAL_TARGET_TEST_SRCS := \
	$(addprefix tests_renode/target/, \
		EmulatorExit.cpp KernelTestSupport.cpp SchedulingTest.cpp TaskServicesTest.cpp TimerAlarmTest.cpp \
		ObjectLifecycleTest.cpp InterruptServiceTest.cpp ProfilingFpuTest.cpp MemoryProtectionTest.cpp) \
	$(wildcard tests_renode/target/minimal/*.cpp) \
	firmware/shell/src/Shell.cpp firmware/shell/src/LineEditor.cpp

# Cold code, compiled for size (-Os) rather than speed: what runs at boot or
# at an engineer's request, never on a path `make bench` measures. The
# console shell and every console command, the application loader and its
# configuration report, the root tasks, boot, the GDT, and the self-check. Everything else stays -O2: the agents' services, and
# what they call, Kernel.cpp's tick handler and the page tables' guard
# pages (task creation and deletion) among them.
FW_COLD_SRCS := \
	$(wildcard firmware/shell/src/*.cpp) \
	$(filter %Commands.cpp,$(FW_SRCS)) \
	$(wildcard firmware/dcos/src/application/*.cpp) \
	firmware/dcos/src/kernel/ConsoleRoot.cpp firmware/dcos/src/kernel/MinimalRoot.cpp \
	$(wildcard firmware/boot/src/*.cpp) \
	firmware/arch_x86/src/Gdt.cpp \
	$(FW_SELFCHECK_SRCS)
FW_COLD_FLAGS := -Os

fw_objects = $(patsubst %,$(FW_BUILD)/%.o,$(1))
# mbedTLS and the controller image verifier (FW_IMAGE_OBJS), before the
# images that link them.
include mk/mbedtls.mk
FW_OBJS := $(call fw_objects,$(FW_SRCS)) $(FW_BUILD)/generated/BuildRevision.cpp.o
# The flash service (firmware/flash, FlashService.hpp), with the flash
# protocol, the image verifier and mbedTLS it runs on: the production and
# test images and the SDK's library carry it; the bench and minimal images
# do not, and the kernel reaches it only through weak hooks
# (dcos/internal/FlashServiceHooks.hpp). Its objects are the stage
# loader's (mk/card.mk), compiled for size: none is on a real-time path.
# The same task is the system engineering interface agent's: it serves the
# configuration protocol (firmware/sei, docs/protocols/config.md) too.
FW_FLASH_TARGET_OBJS := $(call fw_objects,$(FLASH_TARGET_SRCS))
FW_SEI_OBJS := $(call fw_objects,$(SEI_PORTABLE_SRCS) $(SEI_TARGET_SRCS))
FW_FLASH_SERVICE_OBJS := $(call fw_objects,$(FLASH_PORTABLE_SRCS)) $(FW_FLASH_TARGET_OBJS) $(FW_SEI_OBJS) \
	$(FW_IMAGE_OBJS)
$(FW_FLASH_TARGET_OBJS) $(FW_SEI_OBJS): FW_OBJECT_FLAGS := $(FW_COLD_FLAGS) $(FW_IMAGE_INCLUDES) \
	-Ifirmware/flash/include -Ifirmware/sei/include
$(FW_SEI_OBJS): | $(MBEDTLS_FETCHED)
$(FW_FLASH_TARGET_OBJS): | $(MBEDTLS_FETCHED)
FW_TARGET_TEST_OBJS := $(call fw_objects,$(FW_TARGET_TEST_SRCS))
FW_MINIMAL_OBJS := $(call fw_objects,$(FW_MINIMAL_SRCS)) $(FW_BUILD)/generated/BuildRevision.cpp.o
FW_SELFCHECK_OBJS := $(call fw_objects,$(FW_SELFCHECK_SRCS))
FW_MINIMAL_TARGET_TEST_OBJS := $(call fw_objects,$(FW_MINIMAL_TARGET_TEST_SRCS))

# The cold objects' optimisation, after FW_CXXFLAGS' -O2 (the last -O counts).
$(call fw_objects,$(FW_COLD_SRCS)): FW_OBJECT_FLAGS := $(FW_COLD_FLAGS)

IMAGE_486 := $(BUILD)/486/dcos486.elf
IMAGE_486_TEST := $(BUILD)/486/dcos486-test.elf
IMAGE_486_MINIMAL := $(BUILD)/486/dcos486-minimal.elf
IMAGE_486_MINIMAL_TEST := $(BUILD)/486/dcos486-minimal-test.elf
# The dual-Pentium board's images (mk/board_p5smp.mk).
IMAGE_P5SMP := $(BUILD)/p5smp/dcos-p5smp.elf
IMAGE_P5SMP_TEST := $(BUILD)/p5smp/dcos-p5smp-test.elf

FW_IMAGES_STAMP := $(FW_BUILD)/images.stamp

firmware: $(IMAGE_486) $(IMAGE_486_TEST) $(IMAGE_486_MINIMAL) $(IMAGE_486_MINIMAL_TEST) $(IMAGE_P5SMP) $(IMAGE_P5SMP_TEST)

$(IMAGE_486): $(FW_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY) firmware/boot/link.ld $(FW_IMAGES_STAMP)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld $(FW_LDFLAGS) -o $@ $(FW_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY)

# The test image carries the flash service too, and its on-target tests
# "image" and "wycheproof" check controller images with the same mbedTLS.
$(IMAGE_486_TEST): $(FW_OBJS) $(FW_TARGET_TEST_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY) firmware/boot/link.ld \
		$(FW_IMAGES_STAMP)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld $(FW_LDFLAGS) -o $@ $(FW_OBJS) $(FW_TARGET_TEST_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY)

$(IMAGE_486_MINIMAL): $(FW_MINIMAL_OBJS) $(FW_SELFCHECK_OBJS) firmware/boot/link.ld $(FW_IMAGES_STAMP)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld $(FW_LDFLAGS) -o $@ $(FW_MINIMAL_OBJS) $(FW_SELFCHECK_OBJS)

$(IMAGE_486_MINIMAL_TEST): $(FW_MINIMAL_OBJS) $(FW_MINIMAL_TARGET_TEST_OBJS) firmware/boot/link.ld $(FW_IMAGES_STAMP)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld $(FW_LDFLAGS) -o $@ $(FW_MINIMAL_OBJS) $(FW_MINIMAL_TARGET_TEST_OBJS)

# Replaces the target by the text piped into it, only when the text changed,
# so that what depends on the target is rebuilt only then. The temporary file
# is named after the shell's process id: two builds at once each rename their
# own file, and a rename is atomic, so neither can find the other's file gone.
update_if_changed = { new='$@.new.'$$$$; cat > "$$new" && { cmp -s "$$new" '$@' && rm -f "$$new" || mv -f "$$new" '$@'; }; }

# Images depend on the lists of objects they link, as objects on their flags:
# an object taken out of an image relinks it.
$(FW_IMAGES_STAMP): FORCE
	@mkdir -p $(dir $@)
	@echo '$(FW_LDFLAGS) $(FW_OBJS) $(FW_TARGET_TEST_OBJS) $(FW_MINIMAL_OBJS) $(FW_SELFCHECK_OBJS) $(FW_MINIMAL_TARGET_TEST_OBJS) $(FW_FLASH_SERVICE_OBJS)' | $(update_if_changed)

# Objects depend on the flags they were compiled with: a change of flags
# rebuilds everything instead of linking stale objects.
FW_FLAGS_STAMP := $(FW_BUILD)/flags.stamp
$(FW_FLAGS_STAMP): FORCE
	@mkdir -p $(dir $@)
	@echo '$(FW_CXXFLAGS) $(FW_ASFLAGS) $(FW_COLD_FLAGS) $(FW_COLD_SRCS)' | $(update_if_changed)

$(FW_BUILD)/%.cpp.o: %.cpp $(FW_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)g++ $(FW_CXXFLAGS) $(FW_OBJECT_FLAGS) -c $< -o $@

$(FW_BUILD)/%.S.o: %.S $(FW_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)g++ $(FW_ASFLAGS) -c $< -o $@

# The revision is regenerated on every build but rewritten only when it
# changes, so an unchanged tree does not relink.
FW_REVISION := $(shell git describe --always --dirty 2>/dev/null || echo unknown)
$(FW_BUILD)/generated/BuildRevision.cpp: FORCE
	@mkdir -p $(dir $@)
	@printf 'namespace dcos { const char* buildRevisionText = "%s"; }\n' "$(FW_REVISION)" | $(update_if_changed)

$(FW_BUILD)/generated/BuildRevision.cpp.o: $(FW_BUILD)/generated/BuildRevision.cpp
	@echo "  CXX     $@"
	$(Q)g++ $(FW_CXXFLAGS) -c $< -o $@

-include $(shell find $(FW_BUILD) -name '*.d' 2>/dev/null)

include mk/board_p5smp.mk
