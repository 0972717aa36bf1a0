# Builds, runs and tests a DCOS application kept in a directory of its own.
#
# This file is installed as <prefix>/share/dcos/application.mk. An
# application's directory holds only its sources (*.cpp, *.S, in any
# subfolder except build/ and tests/) and, optionally, its emulator tests
# (tests/test_*.py). Its Makefile needs two lines:
#
#     DCOS ?= /opt/dcos
#     include $(DCOS)/share/dcos/application.mk
#
# and then, in that directory:
#
#     make          builds build/<name>-<board>.elf (the default target, "app")
#     make run      boots it on the emulated board, console on this terminal
#                   (ARGS="..." passes launcher options: --append node=3, --set isa-mfio.noise-lsb=0.5;
#                   on the dual-Pentium board node 3's console is on a pseudo-terminal the emulator names)
#     make test     runs tests/test_*.py against it in the emulator
#     make clean    removes build/
#
# Without a Makefile: make -f <prefix>/share/dcos/application.mk APP=<dir> [target].
# In the DCOS source tree, `make app|run|test-app APP=<dir>` does the same
# through a staged installation in build/sdk.
#
# Variables: APP (the application's directory, default: the current one),
# BOARD (the board to build for, default 486; the installed ones are the
# share/dcos/board-<board>.mk files: 486, the ISA 486 board, and p5smp, the
# dual-Pentium board), KERNEL_CONFIG (the kernel configuration
# to link with: full, the default, or minimal, the system, scheduler, task and
# timer agents only, with no console shell; the image is then
# build/<name>-<board>-minimal.elf; docs/guide/kernel-configurations.md),
# APP_BUILD (where objects and the image go, default $(APP)/build),
# APP_CXXFLAGS (extra compiler flags), APP_JUNIT (a JUnit XML report for
# `test`), V=1 (show commands). Sources are compiled with the board's flags,
# which define DCOS_BOARD_486 or DCOS_BOARD_P5SMP.
#
# A board with two nodes (p5smp: node 2 on the first processor, node 3 on
# the second; its board-p5smp.mk sets DCOS_BOARD_SECOND_NODE_ADDRESS) runs
# the application on both. The same objects are linked twice: first as
# node 3's image at that address (build/<name>-p5smp-node3.elf), which is
# stripped and made into an object whose data it is (objcopy names the
# symbols after the input file, DCOS_BOARD_SECOND_NODE_BLOB, so it is made
# under that name in a folder of its own); then as node 2's image
# (build/<name>-p5smp.elf), which carries that object and starts node 3
# from it. The application tells the nodes apart by bsp::nodeId().

DCOS_SHARE := $(abspath $(dir $(lastword $(MAKEFILE_LIST))))
DCOS_PREFIX := $(abspath $(DCOS_SHARE)/../..)

# Each board the installation builds for brings its compiler and linker
# flags and the name of its emulated board (board-<board>.mk).
BOARD ?= 486
DCOS_BOARDS := $(patsubst board-%.mk,%,$(notdir $(wildcard $(DCOS_SHARE)/board-*.mk)))
ifeq ($(filter $(BOARD),$(DCOS_BOARDS)),)
$(error BOARD=$(BOARD) is not a board this DCOS builds for; its boards are: $(DCOS_BOARDS))
endif
include $(DCOS_SHARE)/board-$(BOARD).mk

KERNEL_CONFIG ?= full
ifeq ($(filter $(KERNEL_CONFIG),full minimal),)
$(error KERNEL_CONFIG=$(KERNEL_CONFIG) is not a kernel configuration; they are: full minimal)
endif
APP_CONFIG_SUFFIX := $(if $(filter minimal,$(KERNEL_CONFIG)),-minimal)

APP ?= $(CURDIR)
APP_DIR := $(abspath $(APP))
APP_NAME := $(notdir $(APP_DIR))
APP_BUILD ?= $(APP_DIR)/build
APP_BUILD_DIR := $(abspath $(APP_BUILD))
APP_IMAGE := $(APP_BUILD_DIR)/$(APP_NAME)-$(BOARD)$(APP_CONFIG_SUFFIX).elf
# Objects are kept per board: the boards' code flags differ.
APP_OBJ_DIR := $(APP_BUILD_DIR)/obj-$(BOARD)
# A two-node board's second node image, and the object that carries it.
ifneq ($(DCOS_BOARD_SECOND_NODE_ADDRESS),)
APP_SECOND_IMAGE := $(APP_BUILD_DIR)/$(APP_NAME)-$(BOARD)$(APP_CONFIG_SUFFIX)-node3.elf
APP_SECOND_BLOB := $(APP_BUILD_DIR)/node3-$(BOARD)$(APP_CONFIG_SUFFIX)/node3-image.o
endif
APP_Q := $(if $(filter 1,$(V)),,@)
APP_PYTHON := /usr/bin/python3

ifeq ($(wildcard $(APP_DIR)/.),)
$(error application directory '$(APP)' does not exist)
endif

# Sources: every .cpp and .S under the directory except in build/, tests/
# and the build folder when it lies inside the directory.
APP_BUILD_INSIDE := $(patsubst $(APP_DIR)/%,./%,$(filter $(APP_DIR)/%,$(APP_BUILD_DIR)))
APP_SRCS := $(shell cd '$(APP_DIR)' && find . \( -path ./build -o -path ./tests $(if $(APP_BUILD_INSIDE),-o -path '$(APP_BUILD_INSIDE)') \) \
	-prune -o \( -name '*.cpp' -o -name '*.S' \) -type f -print | sed 's|^\./||' | LC_ALL=C sort)
APP_OBJS := $(patsubst %,$(APP_OBJ_DIR)/%.o,$(APP_SRCS))
APP_TESTS := $(wildcard $(APP_DIR)/tests/test_*.py)

# The kernel configuration's library: an agent the minimal one leaves out is
# not in it, so a call to one of its primitives is an undefined reference.
DCOS_LIBRARY := $(DCOS_PREFIX)/lib/dcos/$(BOARD)/libdcos$(BOARD)$(APP_CONFIG_SUFFIX).a
DCOS_LINK_SCRIPT := $(DCOS_PREFIX)/lib/dcos/$(BOARD)/link.ld
# A board's own headers (lib/dcos/<board>/include: the dual-Pentium board's
# bsp/BoardTick.hpp replaces the 486's) come before the common ones.
APP_CPPFLAGS := $(addprefix -I,$(wildcard $(DCOS_PREFIX)/lib/dcos/$(BOARD)/include)) -I$(DCOS_PREFIX)/include \
	-I$(APP_DIR) -MMD -MP
APP_ALL_CXXFLAGS := $(DCOS_BOARD_CXXFLAGS) $(APP_CPPFLAGS) $(APP_CXXFLAGS)

.PHONY: app run test clean
.DEFAULT_GOAL := app
.DELETE_ON_ERROR:

app: $(APP_IMAGE)

# Checks an image just linked ($(1)): it must declare its application and,
# like the kernel, hold no instruction the board's processor lacks.
define check_image
$(APP_Q)if ! nm $(1) | grep -q ' [DdRr] dcosApplication$$'; then \
	echo "error: no source of $(APP_DIR) declares its application with DCOS_APPLICATION (dcos/Application.hpp)" >&2; \
	rm -f $(1); exit 1; fi
$(APP_Q)$(if $(DCOS_BOARD_INSTRUCTION_CHECK),$(APP_PYTHON) $(DCOS_SHARE)/tools/$(DCOS_BOARD_INSTRUCTION_CHECK) $(1) || { rm -f $(1); exit 1; })
endef

# The image: the application's objects, then the whole DCOS library (whole,
# because shell commands and recovery functions register through linker
# sections that nothing else references), and on a two-node board the
# second node's image as data ($(APP_SECOND_BLOB), below).
$(APP_IMAGE): $(APP_OBJS) $(APP_SECOND_BLOB) $(DCOS_LIBRARY) $(DCOS_LINK_SCRIPT)
	@if [ -z '$(APP_SRCS)' ]; then echo "error: $(APP_DIR) holds no .cpp or .S source" >&2; exit 1; fi
	@echo "  LD      $@"
	$(APP_Q)ld $(DCOS_BOARD_LDFLAGS) -T $(DCOS_LINK_SCRIPT) -o $@ $(APP_OBJS) $(APP_SECOND_BLOB) \
		--whole-archive $(DCOS_LIBRARY) --no-whole-archive
	$(call check_image,$@)
	@echo "application $(APP_NAME): $@$(if $(APP_SECOND_IMAGE), (carries $(notdir $(APP_SECOND_IMAGE))))"

ifneq ($(DCOS_BOARD_SECOND_NODE_ADDRESS),)
# The second node's image, linked at its own address: the --defsym comes
# before the linker script, whose DEFINED() sees only what is defined by then.
$(APP_SECOND_IMAGE): $(APP_OBJS) $(DCOS_LIBRARY) $(DCOS_LINK_SCRIPT)
	@if [ -z '$(APP_SRCS)' ]; then echo "error: $(APP_DIR) holds no .cpp or .S source" >&2; exit 1; fi
	@echo "  LD      $@"
	$(APP_Q)ld --defsym=__image_load_address=$(DCOS_BOARD_SECOND_NODE_ADDRESS) $(DCOS_BOARD_LDFLAGS) \
		-T $(DCOS_LINK_SCRIPT) -o $@ $(APP_OBJS) --whole-archive $(DCOS_LIBRARY) --no-whole-archive
	$(call check_image,$@)

# Stripped, then wrapped as read-only data; objcopy runs in the blob's
# folder on the bare file name, which names the symbols.
$(APP_SECOND_BLOB): $(APP_SECOND_IMAGE)
	@mkdir -p $(dir $@)
	@echo "  BLOB    $@"
	$(APP_Q)objcopy --strip-all $< $(dir $@)$(DCOS_BOARD_SECOND_NODE_BLOB)
	$(APP_Q)cd $(dir $@) && objcopy -I binary -O elf32-i386 -B i386 \
		--rename-section .data=.rodata.node3_image,alloc,load,readonly,data,contents \
		--add-section .note.GNU-stack=/dev/null $(DCOS_BOARD_SECOND_NODE_BLOB) $(notdir $@)
endif

# Objects depend on the flags and on the DCOS they were compiled against.
# The stamp is rewritten only when the text changes, through a temporary file
# named after the shell's process id, so that two builds at once never race
# on one temporary name.
APP_FLAGS_STAMP := $(APP_OBJ_DIR)/flags.stamp
$(APP_FLAGS_STAMP): FORCE
	@mkdir -p $(dir $@)
	@new='$@.new.'$$$$; echo '$(APP_ALL_CXXFLAGS) $(DCOS_PREFIX)' > "$$new" && \
		{ cmp -s "$$new" '$@' && rm -f "$$new" || mv -f "$$new" '$@'; }

# A failed compilation's messages end with a one-line summary when they hold
# a configuration error (the compiler names the object in a template).
$(APP_OBJ_DIR)/%.cpp.o: $(APP_DIR)/%.cpp $(APP_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $<"
	$(APP_Q)g++ $(APP_ALL_CXXFLAGS) -c $< -o $@ 2> $@.messages || { \
		$(APP_PYTHON) $(DCOS_SHARE)/tools/explain_configuration_error.py $@.messages; rm -f $@.messages; exit 1; }
	@cat $@.messages >&2; rm -f $@.messages

$(APP_OBJ_DIR)/%.S.o: $(APP_DIR)/%.S $(APP_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  AS      $<"
	$(APP_Q)g++ $(DCOS_BOARD_ASFLAGS) $(APP_CPPFLAGS) -c $< -o $@

run: app
	@$(APP_PYTHON) $(DCOS_SHARE)/python/launch.py --board $(DCOS_BOARD_EMULATED) --image $(APP_IMAGE) $(DCOS_BOARD_RUN_ARGS) $(ARGS)

# The application's own emulator tests, with the lab's fixtures (the
# `application` fixture boots this image). No tests is not a failure, but it is said.
test: app
ifeq ($(APP_TESTS),)
	@echo "application $(APP_NAME): no tests (add tests/test_*.py to $(APP_DIR))"
else
	$(APP_Q)cd '$(APP_DIR)' && PYTHONPATH='$(DCOS_SHARE)/python' PYTHONDONTWRITEBYTECODE=1 \
		$(APP_PYTHON) -m pytest -c '$(DCOS_SHARE)/pytest.ini' --rootdir '$(APP_DIR)' -p dcoslab.pytest_plugin \
		--dcos-board $(DCOS_BOARD_EMULATED) --dcos-image '$(APP_IMAGE)' --dcos-kernel-config $(KERNEL_CONFIG) \
		$(if $(APP_JUNIT),--junitxml='$(APP_JUNIT)') \
		$(APP_PYTEST_ARGS) tests
endif

clean:
	rm -rf '$(APP_BUILD_DIR)'

.PHONY: FORCE
FORCE:

# A build folder that last built another directory's application (the tree
# keys build/apps/ by name only) starts afresh: its dependency files name
# the other directory's sources.
ifneq ($(shell cat '$(APP_BUILD_DIR)/application-directory' 2>/dev/null),$(APP_DIR))
$(shell rm -rf '$(APP_BUILD_DIR)'/obj '$(APP_BUILD_DIR)'/obj-* '$(APP_BUILD_DIR)/flags.stamp'; mkdir -p '$(APP_BUILD_DIR)' && \
	printf '%s\n' '$(APP_DIR)' > '$(APP_BUILD_DIR)/application-directory')
endif

-include $(shell find '$(APP_OBJ_DIR)' -name '*.d' 2>/dev/null)
