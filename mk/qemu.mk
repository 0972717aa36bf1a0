# The emulator: Debian's QEMU 7.2 source with our device models
# (tests_renode/models/*.c) compiled in, i386 system emulation only.
#
# tests_renode/qemu/build_qemu.sh does everything: it enables deb-src in the
# machine's apt sources if needed, fetches the source with apt-get source,
# configures, builds and caches qemu-system-i386 in build/qemu-<key>/, where
# <key> hashes the script and the models. With the key unchanged it returns
# in well under a second; a model change recompiles that model only (about
# 10 s); a fresh clone builds QEMU once (about 5 minutes on 2 cores).
# Boards name it as "built:qemu-system-i386" (tests_renode/dcoslab/built_emulator.py).

QEMU_BUILD_SCRIPT := tests_renode/qemu/build_qemu.sh

.PHONY: emulator

# Always asks the script: it decides from the hash whether anything is to do.
# After deps, so that two apt-get runs never race under make -j.
emulator: deps
	@$(QEMU_BUILD_SCRIPT)

run test test-emulator bench: emulator
