# The controller's CompactFlash card (docs/boot.md): the boot sector, the
# stage loader, and `make card`, a card image the emulated board boots from
# through its BIOS as a real board does.
#
#   make card     build/486/card-486.img: the production firmware signed with
#                 the development key, in slot A, which the first boot confirms
#
# The development key (build/keys/development.pem) is generated on this
# machine the first time it is needed and never leaves build/: no key ships
# with DCOS (docs/guide/signing-images.md). A plant's cards trust the
# plant's own key instead (dcos-card create -p).

BOOT_SECTOR_SRC := firmware/boot/loader/boot_sector.S
BOOT_SECTOR_OBJ := $(call fw_objects,$(BOOT_SECTOR_SRC))
BOOT_SECTOR_ELF := $(BUILD)/486/boot-sector.elf
BOOT_SECTOR_BIN := $(BUILD)/486/boot-sector.bin

# The stage loader: its own entry and main, the card's records, the ATA
# driver, the image verifier with mbedTLS, the flash protocol with the CAN
# card's chip core and ISO-TP for recovery, and the runtime's memory,
# formatting and division. Objects are the firmware's (same flags), linked
# at 0x10000 by its own script.
STAGE_SRCS := \
	firmware/boot/loader/stage_entry.S \
	firmware/boot/loader/StageLoader.cpp \
	firmware/boot/src/BootStateStore.cpp \
	firmware/boot/src/BootState.cpp \
	firmware/boot/src/CommandLine.cpp \
	firmware/boot/src/ConfigurationBlock.cpp \
	firmware/boot/src/Crc32.cpp \
	firmware/bsp_486/src/BoardReset.cpp \
	$(ATA_DRIVER_PORTABLE_SRCS) \
	$(FLASH_PORTABLE_SRCS) \
	drivers/can/src/BitTiming.cpp \
	drivers/can/src/Sja1000Chip.cpp \
	$(filter-out %/SlcanCodec.cpp %/FrameText.cpp,$(CAN_PORTABLE_SRCS)) \
	firmware/runtime/src/CxxRuntime.cpp \
	firmware/runtime/src/Format.cpp \
	firmware/runtime/src/Int64Division.cpp \
	firmware/runtime/src/LibgccReplacements.cpp \
	firmware/runtime/src/MemoryFunctions.cpp
STAGE_OBJS := $(call fw_objects,$(STAGE_SRCS)) $(FW_IMAGE_OBJS)
STAGE_ELF := $(BUILD)/486/stage-loader.elf
STAGE_BIN := $(BUILD)/486/stage-loader.bin
# They include the image verifier's headers, and so mbedTLS's.
STAGE_IMAGE_USER_OBJS := $(call fw_objects,firmware/boot/loader/StageLoader.cpp $(FLASH_PORTABLE_SRCS))
$(STAGE_IMAGE_USER_OBJS): FW_OBJECT_FLAGS := $(FW_COLD_FLAGS) $(FW_IMAGE_INCLUDES) -Ifirmware/flash/include
$(STAGE_IMAGE_USER_OBJS): | $(MBEDTLS_FETCHED)

DEVELOPMENT_KEY := $(BUILD)/keys/development.pem
CARD_486 := $(BUILD)/486/card-486.img
CARD_IMAGE_486 := $(BUILD)/486/dcos486.dcos
# The development images' version: DCOS's, with the commit count as build number.
CARD_VERSION := $(shell sed -n 's/.*versionString = "\(.*\)";/\1/p' firmware/dcos/include/dcos/Version.hpp)+$(shell git rev-list --count HEAD 2>/dev/null || echo 0)

.PHONY: card loader

loader: $(BOOT_SECTOR_BIN) $(STAGE_BIN)
card: $(CARD_486)

$(BOOT_SECTOR_ELF): $(BOOT_SECTOR_OBJ) firmware/boot/loader/boot_sector.ld
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld -m elf_i386 -nostdlib -static --no-warn-rwx-segments -T firmware/boot/loader/boot_sector.ld -o $@ $(BOOT_SECTOR_OBJ)

$(STAGE_ELF): $(STAGE_OBJS) $(MBEDTLS_FW_LIBRARY) firmware/boot/loader/stage.ld
	@mkdir -p $(dir $@)
	@echo "  LD      $@"
	$(Q)ld -m elf_i386 -nostdlib -static --gc-sections --no-warn-rwx-segments -T firmware/boot/loader/stage.ld -o $@ $(STAGE_OBJS) \
		$(MBEDTLS_FW_LIBRARY)

$(BOOT_SECTOR_BIN) $(STAGE_BIN): %.bin: %.elf
	@echo "  BIN     $@"
	$(Q)objcopy -O binary $< $@

$(DEVELOPMENT_KEY): | $(DCOS_IMAGE)
	@mkdir -p $(dir $@)
	@echo "  KEYGEN  $@ (the development key: it never leaves build/)"
	$(Q)$(DCOS_IMAGE) keygen -o $@ >/dev/null

$(CARD_IMAGE_486): $(IMAGE_486) $(DEVELOPMENT_KEY) $(DCOS_IMAGE)
	@echo "  SIGN    $@ ($(CARD_VERSION))"
	$(Q)$(DCOS_IMAGE) sign -k $(DEVELOPMENT_KEY) --board isa486 --version $(CARD_VERSION) -o $@ $(IMAGE_486) >/dev/null

$(CARD_486): $(BOOT_SECTOR_BIN) $(STAGE_BIN) $(CARD_IMAGE_486) $(DEVELOPMENT_KEY) $(DCOS_CARD)
	@echo "  CARD    $@"
	$(Q)$(DCOS_CARD) create -o $@.new --boot-sector $(BOOT_SECTOR_BIN) --stage $(STAGE_BIN) \
		-p $(DEVELOPMENT_KEY).pub --force >/dev/null
	$(Q)$(DCOS_CARD) write $@.new --slot A $(CARD_IMAGE_486) >/dev/null
	$(Q)mv -f $@.new $@
