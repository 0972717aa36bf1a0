# drivers/pci: PCI configuration space (mechanism #1) and enumeration.

# Sources with no hardware access of their own (the configuration ports go
# through the mocked port I/O on the host): built for the host tests and
# the firmware.
PCI_DRIVER_PORTABLE_SRCS := \
	drivers/pci/src/Bar.cpp \
	drivers/pci/src/ConfigSpace.cpp \
	drivers/pci/src/Enumerator.cpp
