# Applications outside the tree: the installed DCOS and the targets that use it.
#
#   make install PREFIX=<path>   installs DCOS for building applications (mk/install-sdk.sh)
#   make app APP=<dir> [BOARD=486|p5smp]  builds the application in <dir> (image in build/apps/<name>/)
#   make run APP=<dir>           builds it and boots it on the emulated board
#   make test-app APP=<dir>      builds it and runs its own emulator tests (<dir>/tests/test_*.py)
#
# The tree's own app, run and test-app go through a staged installation in
# build/sdk, made by the same script as 'make install', so an application is
# built the same way against the tree as against an installed DCOS.

SDK_STAGE := $(BUILD)/sdk
SDK_STAMP := $(SDK_STAGE)/.installed
LIBRARY_486 := $(BUILD)/486/libdcos486.a
# The minimal kernel configuration's library (docs/guide/kernel-configurations.md):
# an application built with KERNEL_CONFIG=minimal links this one instead.
LIBRARY_486_MINIMAL := $(BUILD)/486/libdcos486-minimal.a
BOARD_FLAGS_486 := $(BUILD)/486/board-486.mk
# The dual-Pentium board's libraries (mk/board_p5smp.mk): the ISA board's
# objects less its board file and TimerManager.cpp, with the Pentium's own
# (FWP5_OWN_OBJS), in each kernel configuration. An application for this
# board is linked twice from one library, as node 3's image at 16 MiB and
# as node 2's image carrying it (mk/application.mk).
LIBRARY_P5SMP := $(BUILD)/p5smp/libdcosp5smp.a
LIBRARY_P5SMP_MINIMAL := $(BUILD)/p5smp/libdcosp5smp-minimal.a
BOARD_FLAGS_P5SMP := $(BUILD)/p5smp/board-p5smp.mk
# The minimal configuration has no shell: the board's console commands stay out, as the kernel's do.
FWP5_MINIMAL_OBJS := $(filter-out $(FWP5_REPLACED_OBJS),$(FW_MINIMAL_OBJS)) $(filter-out %Commands.cpp.o,$(FWP5_OWN_OBJS))
APPLICATION_MAKEFILE := $(SDK_STAGE)/share/dcos/application.mk
# The emulator's path changes with its sources (tests_renode/qemu/build_qemu.sh).
QEMU_BINARY := $(shell $(QEMU_BUILD_SCRIPT) --print-path)

# Examples under docs/examples/, built and tested by 'make test', each for
# the board its Makefile names (a line 'BOARD ?= p5smp'), else the 486.
EXAMPLE_APPS := $(patsubst %/,%,$(sort $(dir $(wildcard docs/examples/*/*.cpp))))
example_board = $(or $(shell sed -n 's/^BOARD *?= *\([a-z0-9]*\) *$$/\1/p' '$(1)/Makefile' 2>/dev/null),486)

.PHONY: sdk install app test-app test-examples

# The full configuration's library carries the flash service, as the
# production image does (mk/firmware.mk), with mbedTLS's objects.
$(LIBRARY_486): $(FW_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_OBJS)
	@mkdir -p $(dir $@)
	@echo "  AR      $@"
	$(Q)rm -f $@ && ar rcs $@ $(FW_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_OBJS)

$(LIBRARY_486_MINIMAL): $(FW_MINIMAL_OBJS)
	@mkdir -p $(dir $@)
	@echo "  AR      $@"
	$(Q)rm -f $@ && ar rcs $@ $(FW_MINIMAL_OBJS)

$(BOARD_FLAGS_486): $(FW_FLAGS_STAMP) mk/sdk.mk
	@mkdir -p $(dir $@)
	@printf '%s\n' '# How code for the ISA 486 board is compiled, linked, checked and emulated (written by make install).' \
		'DCOS_BOARD_CXXFLAGS := $(FW_CODE_FLAGS) $(FW_WARNING_FLAGS) -DDCOS_BOARD_486=1' \
		'DCOS_BOARD_ASFLAGS := $(FW_ARCH_FLAGS) -DDCOS_BOARD_486=1' \
		'DCOS_BOARD_LDFLAGS := $(patsubst -T%,,$(filter-out firmware/boot/link.ld,$(FW_LDFLAGS)))' \
		'DCOS_BOARD_INSTRUCTION_CHECK := check_i486.py' \
		'DCOS_BOARD_EMULATED := isa486' > $@

$(LIBRARY_P5SMP): $(FWP5_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_OBJS)
	@mkdir -p $(dir $@)
	@echo "  AR      $@"
	$(Q)rm -f $@ && ar rcs $@ $(FWP5_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_OBJS)

$(LIBRARY_P5SMP_MINIMAL): $(FWP5_MINIMAL_OBJS)
	@mkdir -p $(dir $@)
	@echo "  AR      $@"
	$(Q)rm -f $@ && ar rcs $@ $(FWP5_MINIMAL_OBJS)

# Node 3's image is linked at DCOS_BOARD_SECOND_NODE_ADDRESS, stripped and
# carried in node 2's image as the data of an object made from a file named
# DCOS_BOARD_SECOND_NODE_BLOB (objcopy names the symbols BoardP5smp.cpp
# looks for, _binary_node3_stripped_elf_start and _end, after that file).
# The run arguments give node 3's console a pseudo-terminal.
$(BOARD_FLAGS_P5SMP): $(FW_FLAGS_STAMP) $(FWP5_FLAGS_STAMP) mk/sdk.mk mk/board_p5smp.mk
	@mkdir -p $(dir $@)
	@printf '%s\n' '# How code for the dual-Pentium board is compiled, linked, checked and emulated (written by make install).' \
		'DCOS_BOARD_CXXFLAGS := $(subst $(FW_ARCH_FLAGS),$(FWP5_ARCH_FLAGS),$(FW_CODE_FLAGS)) $(FW_WARNING_FLAGS) -DDCOS_BOARD_P5SMP=1' \
		'DCOS_BOARD_ASFLAGS := $(FWP5_ARCH_FLAGS) -DDCOS_BOARD_P5SMP=1' \
		'DCOS_BOARD_LDFLAGS := $(patsubst -T%,,$(filter-out firmware/boot/link.ld,$(FW_LDFLAGS)))' \
		'DCOS_BOARD_INSTRUCTION_CHECK := check_i486.py --cpu pentium' \
		'DCOS_BOARD_EMULATED := p5smp' \
		'DCOS_BOARD_SECOND_NODE_ADDRESS := $(FWP5_NODE3_LOAD_ADDRESS)' \
		'DCOS_BOARD_SECOND_NODE_BLOB := node3-stripped.elf' \
		'DCOS_BOARD_RUN_ARGS := --serial node3=pty' > $@

$(QEMU_BINARY):
	@$(QEMU_BUILD_SCRIPT)

SDK_INPUTS := $(LIBRARY_486) $(LIBRARY_486_MINIMAL) $(IMAGE_486) $(BOARD_FLAGS_486) \
	$(LIBRARY_P5SMP) $(LIBRARY_P5SMP_MINIMAL) $(IMAGE_P5SMP) $(BOARD_FLAGS_P5SMP) \
	$(QEMU_BINARY) mk/install-sdk.sh mk/application.mk \
	firmware/boot/link.ld host_tools/isa_check/check_i486.py host_tools/app_build/explain_configuration_error.py tests_renode/launch.py tests_renode/plant.py tests_renode/pytest.ini \
	$(wildcard tests_renode/dcoslab/*.py tests_renode/boards/*.json) \
	host_tools/bringup/mfio_bringup.py host_tools/bringup/bringup_report.py host_tools/plant_simulator/plant_simulator.py \
	$(wildcard host_tools/modbus/examples/*.toml) \
	$(HOST_TOOLS) \
	$(shell find firmware/*/include drivers/*/include fieldbus/*/include -name '*.hpp')

# Each board: its name, its two libraries, its plain image and its flags.
install_sdk = mk/install-sdk.sh '$(1)' $(QEMU_BINARY) $(HOST_TOOLS_BIN) \
	486 $(LIBRARY_486) $(LIBRARY_486_MINIMAL) $(IMAGE_486) $(BOARD_FLAGS_486) \
	p5smp $(LIBRARY_P5SMP) $(LIBRARY_P5SMP_MINIMAL) $(IMAGE_P5SMP) $(BOARD_FLAGS_P5SMP)

$(SDK_STAMP): $(SDK_INPUTS)
	@echo "  STAGE   $(SDK_STAGE)"
	$(Q)$(call install_sdk,$(SDK_STAGE))
	@touch $@

sdk: $(SDK_STAMP)

install: deps $(SDK_INPUTS)
	@if [ -z '$(PREFIX)' ]; then echo "error: say where: make install PREFIX=<path>" >&2; exit 1; fi
	$(Q)$(call install_sdk,$(PREFIX))
	@echo "DCOS installed in $(PREFIX); build an application with: make -f $(PREFIX)/share/dcos/application.mk APP=<dir>"

# make app|run|test-app APP=<dir>: the application build in build/apps/<name>/.
# BOARD (default 486) goes through to the application build, which names the boards it has.
app_make = $(MAKE) --no-print-directory -f $(APPLICATION_MAKEFILE) APP='$(1)' $(if $(BOARD),BOARD='$(BOARD)') \
	APP_BUILD='$(abspath $(BUILD))/apps/$(notdir $(abspath $(1)))' $(2)

check_app = @if [ -z '$(APP)' ]; then echo "error: say which application: make $@ APP=<dir>" >&2; exit 1; fi

app: deps
	$(check_app)
	@$(MAKE) --no-print-directory sdk
	@$(call app_make,$(APP),app)

test-app: deps emulator
	$(check_app)
	@$(MAKE) --no-print-directory sdk
	@$(call app_make,$(APP),test)

# Every example builds and passes its tests; each writes a JUnit report for the summary.
test-examples: sdk
	@status=0; \
	$(foreach example,$(EXAMPLE_APPS),$(call app_make,$(example),test BOARD=$(call example_board,$(example)) \
		APP_JUNIT=$(abspath $(BUILD))/reports/example-$(notdir $(example)).xml APP_PYTEST_ARGS='-n $(JOBS)') \
		|| status=1;) \
	exit $$status
