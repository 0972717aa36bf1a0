# Applications outside the tree: the installed DCOS and the targets that use it.
#
#   make install PREFIX=<path>   installs DCOS for building applications (mk/install-sdk.sh)
#   make app APP=<dir> [BOARD=486]  builds the application in <dir> (image in build/apps/<name>/)
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
APPLICATION_MAKEFILE := $(SDK_STAGE)/share/dcos/application.mk
# The emulator's path changes with its sources (tests_renode/qemu/build_qemu.sh).
QEMU_BINARY := $(shell $(QEMU_BUILD_SCRIPT) --print-path)

# Examples under docs/examples/, built and tested by 'make test'.
EXAMPLE_APPS := $(patsubst %/,%,$(sort $(dir $(wildcard docs/examples/*/*.cpp))))

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
		'DCOS_BOARD_CXXFLAGS := $(FW_CODE_FLAGS) $(FW_WARNING_FLAGS)' \
		'DCOS_BOARD_ASFLAGS := $(FW_ARCH_FLAGS)' \
		'DCOS_BOARD_LDFLAGS := $(patsubst -T%,,$(filter-out firmware/boot/link.ld,$(FW_LDFLAGS)))' \
		'DCOS_BOARD_INSTRUCTION_CHECK := check_i486.py' \
		'DCOS_BOARD_EMULATED := isa486' > $@

$(QEMU_BINARY):
	@$(QEMU_BUILD_SCRIPT)

SDK_INPUTS := $(LIBRARY_486) $(LIBRARY_486_MINIMAL) $(IMAGE_486) $(BOARD_FLAGS_486) $(QEMU_BINARY) mk/install-sdk.sh mk/application.mk \
	firmware/boot/link.ld host_tools/isa_check/check_i486.py host_tools/app_build/explain_configuration_error.py tests_renode/launch.py tests_renode/plant.py tests_renode/pytest.ini \
	$(wildcard tests_renode/dcoslab/*.py tests_renode/boards/*.json) \
	host_tools/bringup/mfio_bringup.py host_tools/bringup/bringup_report.py host_tools/plant_simulator/plant_simulator.py \
	$(wildcard host_tools/modbus/examples/*.toml) \
	$(HOST_TOOLS) \
	$(shell find firmware/*/include drivers/*/include fieldbus/*/include -name '*.hpp')

install_sdk = mk/install-sdk.sh '$(1)' $(LIBRARY_486) $(LIBRARY_486_MINIMAL) $(IMAGE_486) $(BOARD_FLAGS_486) $(QEMU_BINARY) $(HOST_TOOLS_BIN)

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
	$(foreach example,$(EXAMPLE_APPS),$(call app_make,$(example),test \
		APP_JUNIT=$(abspath $(BUILD))/reports/example-$(notdir $(example)).xml APP_PYTEST_ARGS='-n $(JOBS)') \
		|| status=1;) \
	exit $$status
