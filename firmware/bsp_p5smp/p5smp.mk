# firmware/bsp_p5smp: the dual-Pentium board (seed 9.2, controller nodes 2
# and 3): MP configuration tables, local and I/O APIC, the board itself.

# Sources with no hardware access of their own (registers go through
# checked windows, memory through readers the host tests supply): built
# for the host tests and the firmware.
P5SMP_PORTABLE_SRCS := firmware/bsp_p5smp/src/MpTable.cpp firmware/bsp_p5smp/src/LocalApic.cpp firmware/bsp_p5smp/src/IoApic.cpp \
	firmware/bsp_p5smp/src/SharedMemoryRing.cpp firmware/bsp_p5smp/src/ElfImage.cpp
