# The bench image and 'make bench'.
#
# dcos486-bench.elf is the production firmware (FW_OBJS, mk/firmware.mk)
# plus the benchmark framework and cases in tests_renode/bench/. It reads the
# time-stamp counter with RDTSC, which no i486 has, so it is exempt from the
# i486 check and runs on the board's "benchmark_cpu" (a Pentium model; see
# tests_renode/boards/isa486.json and docs/performance.md).

FW_BENCH_SRCS := $(wildcard tests_renode/bench/*.cpp)
FW_BENCH_OBJS := $(call fw_objects,$(FW_BENCH_SRCS))

IMAGE_486_BENCH := $(BUILD)/486/dcos486-bench.elf
BENCH_REPORT := $(BUILD)/bench/kernel.json

# Built with the other images, so the emulator suite can check the framework.
firmware: $(IMAGE_486_BENCH)

$(IMAGE_486_BENCH): $(FW_OBJS) $(FW_BENCH_OBJS) firmware/boot/link.ld
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld $(FW_LDFLAGS) -o $@ $(FW_OBJS) $(FW_BENCH_OBJS)
