# DCOS: the single entry point for building, running and testing.
#
#   make          firmware images and host tools
#   make run      boot the ISA 486 controller in the emulator, console on this terminal
#                 (BOARD=p5smp: the dual-Pentium controller, node 2's console here, node 3's on a pty)
#                 (KERNEL_CONFIG=minimal: the minimal kernel's image, its self-check;
#                 with APP=<dir>, the application built with that configuration)
#                 (APP=<dir>: with the application in <dir>; ARGS="...": launcher options,
#                 e.g. ARGS="--set isa-mfio.noise-lsb=0.5 --append node=3 --append tick_hz=100")
#   make test     host unit tests, the emulator regression suite, then the examples
#   make app APP=<dir>       build an application kept outside the tree
#   make test-app APP=<dir>  run an application's own emulator tests
#   make install PREFIX=<path>  install DCOS to build applications against
#   make bench    benchmarks, footprint and their budgets (STRICT=1: fail on any offender)
#   make emulator build the emulator with our board models (done by run, test and bench)
#   make clean    remove build/
#
# 'make run' and 'make test' install the Debian packages they lack first.

BUILD      := build
# V=1 shows the full compiler command lines.
Q          := $(if $(filter 1,$(V)),,@)
PYTHON     := /usr/bin/python3
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)

.DEFAULT_GOAL := all
.PHONY: all deps run plant test test-host test-emulator test-fuzz fuzz bench clean firmware host-tests host-tools emulator FORCE
.DELETE_ON_ERROR:

include mk/firmware.mk
include mk/host_tools.mk
include mk/card.mk
include mk/host.mk
include mk/bench.mk
include mk/qemu.mk
include mk/sdk.mk
include mk/fuzz.mk

all: firmware host-tests host-tools loader card

deps:
	@mk/install-deps.sh

run: deps
ifneq ($(CARD),)
	@$(MAKE) --no-print-directory card
	@$(PYTHON) tests_renode/launch.py --board isa486 --card $(CARD_486) $(ARGS)
else ifeq ($(APP),)
	@$(MAKE) --no-print-directory firmware
ifeq ($(BOARD),p5smp)
	@$(PYTHON) tests_renode/launch.py --board p5smp --image $(IMAGE_P5SMP) --serial node3=pty $(ARGS)
else
	@$(PYTHON) tests_renode/launch.py --board isa486 --image $(if $(filter minimal,$(KERNEL_CONFIG)),$(IMAGE_486_MINIMAL),$(IMAGE_486)) $(ARGS)
endif
else
	@$(MAKE) --no-print-directory sdk
	@$(call app_make,$(APP),run)
endif

# The distributed plant of docs/guide/distributed-plant.md: two controllers on
# two CAN buses hold a simulated process; ARGS="--seconds 20" and the like go
# to tests_renode/plant.py (--help lists them).
plant: deps
	@$(MAKE) --no-print-directory firmware host-tools sdk
	@$(call app_make,docs/examples/plant,app)
	@$(PYTHON) tests_renode/plant.py $(ARGS)

# Every suite runs even when an earlier one fails; the summary line counts
# them all and the exit status says whether anything failed.
test: deps
	@$(MAKE) --no-print-directory -j$(JOBS) all
	@mkdir -p $(BUILD)/reports
	@rm -f $(BUILD)/reports/*.xml
	@status=0; \
	$(MAKE) --no-print-directory test-host || status=1; \
	$(MAKE) --no-print-directory test-fuzz || status=1; \
	$(MAKE) --no-print-directory test-emulator || status=1; \
	$(MAKE) --no-print-directory test-examples || status=1; \
	$(PYTHON) mk/summarize_reports.py $(BUILD)/reports || status=1; \
	exit $$status

test-host: host-tests
	@mkdir -p $(BUILD)/reports
	$(HOST_TEST_BINARY) --gtest_output=xml:$(BUILD)/reports/host-unit-tests.xml

test-emulator: firmware sdk
	@mkdir -p $(BUILD)/reports
	$(PYTHON) -m pytest -c tests_renode/pytest.ini tests_renode -n $(JOBS) \
		--junitxml=$(BUILD)/reports/emulator-tests.xml

# Builds the bench image and runs every benchmark on the board's benchmark CPU
# with exact instruction counting, and under KVM where it works; prints the
# seed's Tables 9.2-9.11 for DCOS and writes $(PRIMITIVES_REPORT) and $(BENCH_REPORT);
# runs Thread-Metric; measures a flash over CAN (tests_renode/bench/flash_bench.py); reports the footprint of the full production image and
# of the minimal one by component;
# and prints every figure against its budget in $(BENCH_BUDGETS). STRICT=1
# fails when any figure offends its budget (docs/performance.md, "Budgets").
# The reports of the last run are removed first, so that the verdict never
# reads a figure a failed step left behind.
bench: deps
	@$(MAKE) --no-print-directory $(IMAGE_486_BENCH) $(IMAGE_486) $(IMAGE_486_MINIMAL) $(IMAGE_486_TEST_COUNTING) $(FOOTPRINT_MAP) $(FOOTPRINT_MAP_MINIMAL) $(IMAGE_P5SMP_TEST) $(IMAGE_P5SMP_BENCH)
	@rm -f $(PRIMITIVES_REPORT) $(THREAD_METRIC_REPORT) $(REMOTE_REPORT) $(P5SMP_REPORT) $(P5SMP_KERNEL_REPORT) $(P5SMP_PRIMITIVES_REPORT) $(FLASH_REPORT) $(FOOTPRINT_REPORT) $(BUDGET_REPORT)
	@$(PYTHON) tests_renode/bench/run_benchmarks.py --board isa486 --output $(BENCH_REPORT) --primitives $(PRIMITIVES_REPORT) --budgets $(BENCH_BUDGETS)
	@$(PYTHON) tests_renode/thread_metric/run_thread_metric.py --board isa486 --output $(THREAD_METRIC_REPORT) --budgets $(BENCH_BUDGETS)
	@$(PYTHON) tests_renode/bench/remote_bench.py --output $(REMOTE_REPORT) --budgets $(BENCH_BUDGETS)
	@$(PYTHON) tests_renode/bench/p5smp_bench.py --output $(P5SMP_REPORT)
	@$(PYTHON) tests_renode/bench/run_benchmarks.py --board p5smp --kvm off --output $(P5SMP_KERNEL_REPORT) --primitives $(P5SMP_PRIMITIVES_REPORT) --can $(BUILD)/bench/can-p5smp.json --modbus $(BUILD)/bench/modbus-p5smp.json --budgets $(BENCH_BUDGETS)
	@$(MAKE) --no-print-directory card loader host-tools
	@$(PYTHON) tests_renode/bench/flash_bench.py --output $(FLASH_REPORT)
	@$(PYTHON) tests_renode/bench/footprint.py --maps $(FOOTPRINT_MAPS) --build-directory $(FW_BUILD) --output $(FOOTPRINT_REPORT) --budgets $(BENCH_BUDGETS)
	@$(PYTHON) tests_renode/bench/budgets.py --budgets $(BENCH_BUDGETS) --primitives $(PRIMITIVES_REPORT) --thread-metric $(THREAD_METRIC_REPORT) --footprint $(FOOTPRINT_REPORT) --remote $(REMOTE_REPORT) --output $(BUDGET_REPORT) $(BENCH_STRICT)

clean:
	rm -rf $(BUILD)
