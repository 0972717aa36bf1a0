# The bench image and 'make bench'.
#
# dcos486-bench.elf is the production firmware plus the benchmark framework
# and cases in tests_renode/bench/. It reads the time-stamp counter with
# RDTSC, which no i486 has, so it is exempt from the i486 check and runs on
# the board's "benchmark_cpu" (a Pentium model; see
# tests_renode/boards/isa486.json and docs/performance.md).
#
# Every benchmark runs once with 8 and once with 4096 objects of its type,
# so the bench image is compiled with kernel tables of 4096 slots (the 12-bit
# index limit) and a stack arena for 4096 tasks of kMinimumStackSize (2 KiB,
# which takes a 4 KiB page and a 4 KiB guard page)
# besides the shell's 16 KiB. The kernel's table sizes are compile-time
# constants (dcos/internal/KernelConfig.hpp), so every firmware source is
# compiled a second time with them into $(FW_BENCH_BUILD); the production
# and test images are unchanged. The tables still start with the production
# image's active slots (64 tasks, 32 timers, 8 devices): the benchmarks grow
# them with AddObjects, as an application would.

FW_BENCH_BUILD := $(BUILD)/fw486-bench
FW_BENCH_DEFINES := \
	-DDCOS_CONFIG_TASK_CAPACITY=4096 \
	-DDCOS_CONFIG_TIMER_CAPACITY=4096 \
	-DDCOS_CONFIG_DEVICE_CAPACITY=4096 \
	-DDCOS_CONFIG_STACK_ARENA_KIB=33024 \
	-DDCOS_CONFIG_POOL_CAPACITY=4096 \
	-DDCOS_CONFIG_HEAP_CAPACITY=4096 \
	-DDCOS_CONFIG_PORT_CAPACITY=4096 \
	-DDCOS_CONFIG_MESSAGE_BUFFERS=8192 \
	-DDCOS_CONFIG_PUBLISHER_CAPACITY=4096 \
	-DDCOS_CONFIG_SUBSCRIPTION_CAPACITY=4096 \
	-DDCOS_CONFIG_SEMAPHORE_CAPACITY=4096
FW_BENCH_CXXFLAGS := $(FW_CXXFLAGS) $(FW_BENCH_DEFINES)
FW_BENCH_ASFLAGS := $(FW_ASFLAGS) $(FW_BENCH_DEFINES)

# Benchmarks run in link order (files in this order, any file not listed
# after them). ConfigurationBench measures AddObjects, which needs tables
# that no other benchmark has fully activated yet, so it comes before every
# file that fills a table.
FW_BENCH_ORDER := \
	tests_renode/bench/BenchmarkRunner.cpp \
	tests_renode/bench/BenchSupport.cpp \
	tests_renode/bench/KernelStructuresBench.cpp \
	tests_renode/bench/ConfigurationBench.cpp \
	tests_renode/bench/TaskBench.cpp \
	tests_renode/bench/SchedulerBench.cpp \
	tests_renode/bench/KernelSwitchBench.cpp \
	tests_renode/bench/TimerBench.cpp \
	tests_renode/bench/SystemBench.cpp \
	tests_renode/bench/BufferPoolBench.cpp \
	tests_renode/bench/HeapBench.cpp \
	tests_renode/bench/DsmBench.cpp \
	tests_renode/bench/PortBench.cpp \
	tests_renode/bench/SemaphoreBench.cpp
FW_BENCH_SRCS := $(filter $(wildcard tests_renode/bench/*.cpp),$(FW_BENCH_ORDER)) \
	$(filter-out $(FW_BENCH_ORDER),$(sort $(wildcard tests_renode/bench/*.cpp))) \
	$(wildcard tests_renode/thread_metric/*.cpp)

fw_bench_objects = $(patsubst %,$(FW_BENCH_BUILD)/%.o,$(1))
# The revision stamp does not depend on the configuration: the production object serves.
FW_BENCH_KERNEL_OBJS := $(call fw_bench_objects,$(FW_SRCS)) $(FW_BUILD)/generated/BuildRevision.cpp.o
FW_BENCH_OBJS := $(call fw_bench_objects,$(FW_BENCH_SRCS))
# Cold code is compiled for size here as in the production image (mk/firmware.mk).
$(call fw_bench_objects,$(FW_COLD_SRCS)): FW_OBJECT_FLAGS := $(FW_COLD_FLAGS)
# The image benchmarks use the firmware's image verifier and mbedTLS (the
# production objects: they do not depend on the kernel's table sizes).
$(call fw_bench_objects,tests_renode/bench/ImageBench.cpp): FW_OBJECT_FLAGS := $(FW_IMAGE_INCLUDES)
$(call fw_bench_objects,tests_renode/bench/ImageBench.cpp): | $(MBEDTLS_FETCHED)

IMAGE_486_BENCH := $(BUILD)/486/dcos486-bench.elf
BENCH_REPORT := $(BUILD)/bench/kernel.json
PRIMITIVES_REPORT := $(BUILD)/bench/primitives.json
THREAD_METRIC_REPORT := $(BUILD)/bench/thread_metric.json
FOOTPRINT_REPORT := $(BUILD)/bench/footprint.json
BUDGET_REPORT := $(BUILD)/bench/budgets.json
REMOTE_REPORT := $(BUILD)/bench/remote.json
# The dual-Pentium board's figures: primitives on the other node of the board, interrupt latency.
P5SMP_REPORT := $(BUILD)/bench/p5smp.json
# The same single-node tables as the 486 board's, on node 2 of the dual board (the p5smp bench image).
P5SMP_KERNEL_REPORT := $(BUILD)/bench/kernel-p5smp.json
P5SMP_PRIMITIVES_REPORT := $(BUILD)/bench/primitives-p5smp.json
FLASH_REPORT := $(BUILD)/bench/flash.json
BENCH_BUDGETS := tests_renode/bench/budgets.toml
# STRICT=1 makes 'make bench' fail on every figure that offends its budget
# (tests_renode/bench/budgets.py); without it the verdict is only printed.
BENCH_STRICT := $(if $(filter 1,$(STRICT)),--strict)

# The linker maps of the full production image and of the minimal one, for
# the footprint report (tests_renode/bench/footprint.py). They are linked
# here, from the same objects, flags and linker script, rather than by the
# images' own rules, so that the images' builds stay as they are;
# footprint.py checks that a map's sections add up to its image's.
FOOTPRINT_MAPS := $(BUILD)/bench
FOOTPRINT_MAP := $(FOOTPRINT_MAPS)/dcos486.map
FOOTPRINT_MAP_MINIMAL := $(FOOTPRINT_MAPS)/dcos486-minimal.map
link_map = @mkdir -p $(dir $@) && echo "  MAP     $@" && \
	ld $(FW_LDFLAGS) -Map=$@ -o $(@:.map=-map.elf) $(1) && rm -f $(@:.map=-map.elf)

$(FOOTPRINT_MAP): $(FW_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY) firmware/boot/link.ld $(FW_IMAGES_STAMP)
	$(call link_map,$(FW_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY))

$(FOOTPRINT_MAP_MINIMAL): $(FW_MINIMAL_OBJS) $(FW_SELFCHECK_OBJS) firmware/boot/link.ld $(FW_IMAGES_STAMP)
	$(call link_map,$(FW_MINIMAL_OBJS) $(FW_SELFCHECK_OBJS))

# The counting image: the test image's objects, compiled once, plus the
# instruction counter (tests_renode/bench/counter/InstructionCounter.cpp),
# which defines the weak dcosInstructionCount the remote agent and the CAN
# driver read (arch_x86/InstructionCounter.hpp). The remote bench boots it
# on the board's benchmark CPU with -icount to count the instructions of a
# remote transaction on each node (docs/performance.md, "Remote
# transactions"). Like the bench image it holds CPUID and RDTSC, so it is
# exempt from the i486 check; it tests for the counter at boot and runs on
# a 486 too, counting nothing.
IMAGE_486_TEST_COUNTING := $(BUILD)/486/dcos486-test-counting.elf
FW_COUNTER_OBJS := $(call fw_objects,tests_renode/bench/counter/InstructionCounter.cpp)

$(IMAGE_486_TEST_COUNTING): $(FW_OBJS) $(FW_TARGET_TEST_OBJS) $(FW_FLASH_SERVICE_OBJS) $(MBEDTLS_FW_LIBRARY) $(FW_COUNTER_OBJS) \
		firmware/boot/link.ld $(FW_IMAGES_STAMP)
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld $(FW_LDFLAGS) -o $@ $(FW_OBJS) $(FW_TARGET_TEST_OBJS) $(FW_COUNTER_OBJS) $(FW_FLASH_SERVICE_OBJS) \
		$(MBEDTLS_FW_LIBRARY)

# Built with the other images, so the emulator suite can check the framework
# and run the remote bench.
firmware: $(IMAGE_486_BENCH) $(IMAGE_486_TEST_COUNTING)

$(IMAGE_486_BENCH): $(FW_BENCH_KERNEL_OBJS) $(FW_BENCH_OBJS) $(FW_IMAGE_OBJS) $(MBEDTLS_FW_LIBRARY) firmware/boot/link.ld
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld $(FW_LDFLAGS) -o $@ $(FW_BENCH_KERNEL_OBJS) $(FW_BENCH_OBJS) $(FW_IMAGE_OBJS) $(MBEDTLS_FW_LIBRARY)

FW_BENCH_FLAGS_STAMP := $(FW_BENCH_BUILD)/flags.stamp
$(FW_BENCH_FLAGS_STAMP): FORCE
	@mkdir -p $(dir $@)
	@echo '$(FW_BENCH_CXXFLAGS) $(FW_BENCH_ASFLAGS) $(FW_COLD_FLAGS) $(FW_COLD_SRCS)' | $(update_if_changed)

$(FW_BENCH_BUILD)/%.cpp.o: %.cpp $(FW_BENCH_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)g++ $(FW_BENCH_CXXFLAGS) $(FW_OBJECT_FLAGS) -c $< -o $@

$(FW_BENCH_BUILD)/%.S.o: %.S $(FW_BENCH_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)g++ $(FW_BENCH_ASFLAGS) -c $< -o $@

-include $(shell find $(FW_BENCH_BUILD) -name '*.d' 2>/dev/null)

# The dual-Pentium board's bench image (mk/board_p5smp.mk): the bench image's objects,
# with this board's own sources compiled here with the same kernel table
# sizes. Node 2 alone: with 4096-object tables the image runs past node 3's
# half of memory, so node 2 says so at boot and does not start node 3 (the
# single-node tables, "the existing tables on one node").
FWP5_BENCH_BUILD := $(BUILD)/fwp5-bench
FWP5_BENCH_CXXFLAGS := $(FWP5_CXXFLAGS) $(FW_BENCH_DEFINES)
FWP5_BENCH_ASFLAGS := $(FWP5_ASFLAGS) $(FW_BENCH_DEFINES)
# The bench's own sources that inline the board's tick (bsp/BoardTick.hpp), as TimerManager.cpp does.
FWP5_BENCH_TICK_SRCS := tests_renode/bench/BenchmarkRunner.cpp tests_renode/bench/ModbusBench.cpp
FWP5_BENCH_OWN_OBJS := $(patsubst %,$(FWP5_BENCH_BUILD)/%.o,$(P5SMP_BOARD_SRCS) $(FWP5_KERNEL_SRCS) $(FWP5_BENCH_TICK_SRCS))
FWP5_BENCH_REPLACED_OBJS := $(call fw_bench_objects,$(wildcard firmware/bsp_486/src/Board486.cpp) $(FWP5_KERNEL_SRCS) \
	$(FWP5_BENCH_TICK_SRCS))
IMAGE_P5SMP_BENCH := $(BUILD)/p5smp/dcos-p5smp-bench.elf
firmware: $(IMAGE_P5SMP_BENCH)

$(IMAGE_P5SMP_BENCH): $(filter-out $(FWP5_BENCH_REPLACED_OBJS),$(FW_BENCH_KERNEL_OBJS) $(FW_BENCH_OBJS)) \
		$(FWP5_BENCH_OWN_OBJS) $(FW_IMAGE_OBJS) $(MBEDTLS_FW_LIBRARY) firmware/boot/link.ld
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld $(FW_LDFLAGS) -o $@ $(filter-out $(FWP5_BENCH_REPLACED_OBJS),$(FW_BENCH_KERNEL_OBJS) $(FW_BENCH_OBJS)) \
		$(FWP5_BENCH_OWN_OBJS) $(FW_IMAGE_OBJS) $(MBEDTLS_FW_LIBRARY)

FWP5_BENCH_FLAGS_STAMP := $(FWP5_BENCH_BUILD)/flags.stamp
$(FWP5_BENCH_FLAGS_STAMP): FORCE
	@mkdir -p $(dir $@)
	@echo '$(FWP5_BENCH_CXXFLAGS) $(FWP5_BENCH_ASFLAGS)' | $(update_if_changed)

$(FWP5_BENCH_BUILD)/%.cpp.o: %.cpp $(FWP5_BENCH_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)g++ $(FWP5_BENCH_CXXFLAGS) -c $< -o $@

$(FWP5_BENCH_BUILD)/%.S.o: %.S $(FWP5_BENCH_FLAGS_STAMP)
	@mkdir -p $(dir $@)
	@echo "  CXX     $@"
	$(Q)g++ $(FWP5_BENCH_ASFLAGS) -c $< -o $@

-include $(shell find $(FWP5_BENCH_BUILD) -name '*.d' 2>/dev/null)
