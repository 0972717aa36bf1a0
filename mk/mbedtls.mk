# mbedTLS for the firmware: Debian's own source (apt-get source mbedtls,
# 2.28, by mk/fetch-debian-source.sh into build/mbedtls-src/tree), compiled
# for the i486 with the firmware's code flags and DCOS's configuration
# (firmware/image/mbedtls/dcos_mbedtls_config.h): SHA-256 and ECDSA P-256
# verification, which check controller images (docs/boot.md). The host
# tools link Debian's packaged library instead (libmbedtls-dev).

MBEDTLS_SOURCE_ROOT := $(BUILD)/mbedtls-src
MBEDTLS_TREE := $(MBEDTLS_SOURCE_ROOT)/tree
MBEDTLS_FETCHED := $(MBEDTLS_SOURCE_ROOT)/fetched.stamp
MBEDTLS_FW_BUILD := $(FW_BUILD)/mbedtls
# The library's files the configuration needs; nothing else is compiled.
MBEDTLS_FW_MODULES := asn1parse asn1write bignum constant_time ecdsa ecp ecp_curves memory_buffer_alloc platform \
	platform_util sha256
MBEDTLS_FW_OBJS := $(patsubst %,$(MBEDTLS_FW_BUILD)/%.c.o,$(MBEDTLS_FW_MODULES))
MBEDTLS_FW_LIBRARY := $(MBEDTLS_FW_BUILD)/libmbedcrypto.a
# The firmware's code flags for C (FW_CODE_FLAGS less the C++ ones), with
# the optimisation that makes a boot's image check fastest (make bench,
# Image.*): -O2 for the big-number and curve arithmetic (a signature
# verified in 9 % fewer instructions than at -Os), -Os for SHA-256 (whose
# rounds GCC's -O2 makes 9 % slower on the i486). mbedTLS is not ours, so
# its warnings are not errors.
MBEDTLS_OPTIMISATION := -O2
$(MBEDTLS_FW_BUILD)/sha256.c.o: MBEDTLS_OPTIMISATION := -Os
MBEDTLS_FW_CFLAGS := -std=c99 $(FW_ARCH_FLAGS) -mregparm=3 -freg-struct-return -mpreferred-stack-boundary=2 \
	-falign-functions=1 -falign-jumps=1 -falign-loops=1 -falign-labels=1 -g -ffreestanding -fno-pic -fno-pie \
	-fno-stack-protector -fno-asynchronous-unwind-tables -fno-unwind-tables -fomit-frame-pointer \
	-fno-tree-loop-distribute-patterns -mgeneral-regs-only -ffunction-sections -fdata-sections \
	-DMBEDTLS_CONFIG_FILE='"dcos_mbedtls_config.h"' -Ifirmware/image/mbedtls -I$(MBEDTLS_TREE)/include -MMD -MP
# What firmware code that uses firmware/image (and so mbedTLS's headers)
# compiles with.
FW_IMAGE_INCLUDES := -Ifirmware/image/include -DMBEDTLS_CONFIG_FILE='"dcos_mbedtls_config.h"' \
	-Ifirmware/image/mbedtls -I$(MBEDTLS_TREE)/include

$(MBEDTLS_FETCHED):
	@mk/fetch-debian-source.sh mbedtls $(MBEDTLS_SOURCE_ROOT)
	@touch $@

# Named .c.o, as the firmware's objects are named .cpp.o: a plain %.o rule
# would also match make's attempt to remake the dependency files (x.d from
# x.d.o, by its built-in rule %: %.o).
$(MBEDTLS_FW_BUILD)/%.c.o: $(MBEDTLS_FETCHED) firmware/image/mbedtls/dcos_mbedtls_config.h mk/mbedtls.mk
	@mkdir -p $(dir $@)
	@echo "  CC      $@"
	$(Q)gcc $(MBEDTLS_FW_CFLAGS) $(MBEDTLS_OPTIMISATION) -c $(MBEDTLS_TREE)/library/$*.c -o $@

$(MBEDTLS_FW_LIBRARY): $(MBEDTLS_FW_OBJS)
	@echo "  AR      $@"
	$(Q)rm -f $@ && ar rcs $@ $^


# Controller images' format and verifier (firmware/image), compiled for the
# firmware against this library's headers: cold code, like mbedTLS itself.
FW_IMAGE_SRCS := $(wildcard firmware/image/src/*.cpp)
FW_IMAGE_OBJS := $(call fw_objects,$(FW_IMAGE_SRCS))
# The on-target tests of the verifier, in the test image; one of them runs
# Wycheproof's vectors, turned into C++ at build time.
WYCHEPROOF_VECTORS := firmware/image/unit_tests/wycheproof/ecdsa_secp256r1_sha256_p1363_test.json
WYCHEPROOF_INCLUDE := $(FW_BUILD)/generated/WycheproofVectors.inc
FW_IMAGE_USER_OBJS := $(FW_IMAGE_OBJS) $(FW_BUILD)/tests_renode/target/ImageVerifierTest.cpp.o \
	$(FW_BUILD)/tests_renode/target/WycheproofTest.cpp.o
$(FW_IMAGE_USER_OBJS): FW_OBJECT_FLAGS := $(FW_COLD_FLAGS) $(FW_IMAGE_INCLUDES) -I$(FW_BUILD)/generated
$(FW_IMAGE_USER_OBJS): | $(MBEDTLS_FETCHED)
$(FW_BUILD)/tests_renode/target/WycheproofTest.cpp.o: $(WYCHEPROOF_INCLUDE)

$(WYCHEPROOF_INCLUDE): $(WYCHEPROOF_VECTORS) tests_renode/target/wycheproof_table.py
	@mkdir -p $(dir $@)
	@echo "  GEN     $@"
	$(Q)$(PYTHON) tests_renode/target/wycheproof_table.py $(WYCHEPROOF_VECTORS) $@
