# The emulator: Debian's QEMU 7.2 source with our device models
# (tests_renode/models/*.c) compiled in: qemu-system-i386 for the boards and
# qemu-system-x86_64 for the lab VM with our cards (docs/guide/lab-vm.md).
#
# tests_renode/qemu/build_qemu.sh does everything: it enables deb-src in the
# machine's apt sources if needed, fetches the source with apt-get source,
# configures, builds and caches both programs in build/qemu-<key>/, where
# <key> hashes the script and the models. With the key unchanged it returns
# in well under a second; a model change recompiles that model only (about
# 10 s); a fresh clone builds QEMU once (about 12 CPU-minutes: 6-7 minutes
# on 2 idle cores). Boards name it as "built:qemu-system-i386"
# (tests_renode/dcoslab/built_emulator.py).

QEMU_BUILD_SCRIPT := tests_renode/qemu/build_qemu.sh

.PHONY: emulator

# Always asks the script: it decides from the hash whether anything is to do.
# After deps, so that two apt-get runs never race under make -j.
emulator: deps
	@$(QEMU_BUILD_SCRIPT)

run test test-emulator bench: emulator
