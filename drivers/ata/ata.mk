# drivers/ata: the controller's CompactFlash card (True IDE mode) by ATA PIO.
# No hardware access of its own (port I/O is mocked on the host): built for
# the host tests and the firmware's stage loader.
ATA_DRIVER_PORTABLE_SRCS := drivers/ata/src/AtaPioDisk.cpp
