/*
 * The lab's Kvaser PCIcan ("lab-kvaser-pci"): one to four SJA1000 CAN
 * controllers behind an AMCC S5920 PCI bridge, on the lab bus.
 *
 * The card has the identity and register layout of QEMU's own model of it
 * (kvaser_pci, hw/net/can/can_kvaser_pci.c), which Linux's kvaser_pci
 * driver (drivers/net/can/sja1000/kvaser_pci.c) and the DCOS firmware's
 * KvaserPciCard (drivers/can/include/sja1000/KvaserPciCard.hpp) drive:
 *
 *  - vendor 0x10E8 (AMCC, the S5920's maker), device 0x8406, class 0xFF00,
 *    interrupt pin INTA#;
 *  - BAR0, 0x80 I/O ports: the S5920's operation registers, of which the
 *    card uses INTCSR (its add-on interrupt enable lets the chips'
 *    interrupt through to INTA#) and PTCR;
 *  - BAR1, 0x80 I/O ports: the chips, 32 ports each, one after another;
 *    a position past the chips the card carries reads 0, which is how the
 *    drivers count them (Linux's number_of_sja1000_chip stops at the first
 *    chip whose MOD does not read back reset mode);
 *  - BAR2, 8 I/O ports: the card's Xilinx logic, whose register 7 holds
 *    its version in the high nibble.
 *
 * QEMU's model puts its one chip, QEMU's idealised SJA1000 core, on a QEMU
 * CAN bus. This one puts up to four of the lab's chips
 * (sja1000_lab_chip.c: that core with bus timing, transmission on the lab
 * bus and fault confinement) on lab buses, exactly as the ISA card
 * (isa_sja1000.c) does: properties bus0..bus3, hub, hub-name, hub-timeout
 * and hub-realtime mean what they mean there, and the board has one link
 * to the hub (labbus_board_link_join), which this card shares with the
 * board's other lab devices. The chips run from the card's 16 MHz
 * oscillator (Linux's KVASER_PCI_CAN_CLOCK is 16000000 / 2, the CAN clock).
 *
 * Every chip drives the card's one interrupt: INTA# is asserted while any
 * chip's interrupt output is and INTCSR's add-on interrupt enable is set.
 * PCI interrupts are level triggered and may be shared, so the line simply
 * follows that condition.
 *
 * docs/protocols/labbus.md, "The PCI card", describes the card for its
 * users; docs/can/pci-sja1000.md the firmware's driver.
 *
 * This file lives in the DCOS repository under tests_renode/models/ and is
 * copied into Debian's QEMU 7.2 source tree by
 * tests_renode/qemu/build_qemu.sh.
 *
 * This program is free software; you can redistribute it and/or
 * modify it under the terms of the GNU General Public License as
 * published by the Free Software Foundation; either version 2 or
 * (at your option) any later version.
 */

#include "qemu/osdep.h"
#include "qemu/bitops.h"
#include "qemu/module.h"
#include "qapi/error.h"
#include "qom/object.h"
#include "hw/irq.h"
#include "hw/pci/pci.h"
#include "hw/qdev-properties.h"

#include "labbus_link.h"
#include "sja1000_lab_chip.h"

/* ======================================================================== */
/* The card's layout                                                         */
/* ======================================================================== */

/*
 * Identity: QEMU's KVASER_PCI_VENDOR_ID1 and KVASER_PCI_DEVICE_ID1, which
 * are Linux's names and values too. QEMU's kvaser_pci_class_init gives the
 * class as 0x00ff00 in a 16-bit field: base class 0xFF (a device that fits
 * no defined class), subclass 0, which is what its configuration header
 * reads and what this card gives.
 */
#define KVASER_VENDOR_ID          0x10e8
#define KVASER_DEVICE_ID          0x8406
#define KVASER_CLASS              0xff00
#define KVASER_REVISION           0x00

/*
 * The BARs, all I/O (QEMU's kvaser_pci_realize, Linux's
 * kvaser_pci_init_one): sizes QEMU's KVASER_PCI_S5920_RANGE,
 * KVASER_PCI_SJA_RANGE and KVASER_PCI_XILINX_RANGE, Linux's
 * PCI_CONFIG_PORT_SIZE, PCI_PORT_SIZE and PCI_PORT_XILINX_SIZE.
 */
#define KVASER_BRIDGE_BAR         0
#define KVASER_CHIPS_BAR          1
#define KVASER_XILINX_BAR         2
#define KVASER_BRIDGE_PORTS       0x80
#define KVASER_CHIPS_PORTS        0x80
#define KVASER_XILINX_PORTS       0x08

/*
 * Chips: one every 0x20 ports of BAR1 (QEMU's KVASER_PCI_BYTES_PER_SJA,
 * Linux's KVASER_PCI_PORT_BYTES), at most four (Linux's
 * MAX_NO_OF_CHANNELS; the PCIcan-Q). A real card carries 1, 2 or 4.
 */
#define KVASER_CHIP_STRIDE        0x20
#define KVASER_MAX_CHIPS          4

/*
 * The S5920's operation registers in BAR0, doublewords. The card uses two
 * (Linux's S5920_INTCSR and S5920_PTCR, QEMU's the same): the others, the
 * mailboxes among them (QEMU's S5920_OMB 0x0c, S5920_IMB 0x1c, S5920_MBEF
 * 0x34, S5920_RCR 0x3c), are not wired to anything on the card and read 0,
 * as in QEMU's model.
 */
#define S5920_INTCSR              0x38   /* interrupt control/status */
#define S5920_PTCR                0x60   /* pass-thru configuration */
#define S5920_REGISTER_BYTES      4

/*
 * INTCSR bit 13, the add-on interrupt enable (Linux's
 * INTCSR_ADDON_INTENABLE_M, QEMU's S5920_INTCSR_ADDON_INTENABLE_M): the
 * add-on interrupt pin, which the chips drive, asserts INTA#. Bit 23
 * (QEMU's S5920_INTCSR_INTERRUPT_ASSERTED_M) is read only and reads as set
 * while the chips drive that pin, whether or not the enable lets it
 * through, as QEMU's kvaser_pci_s5920_io_read reads it: the question a
 * routine on a shared line asks (KvaserPciCard::interruptAsserted()).
 */
#define INTCSR_ADDON_INTENABLE    (1u << 13)
#define INTCSR_INTERRUPT_ASSERTED (1u << 23)

/*
 * Xilinx register 7: the logic's version in the high nibble, simulated
 * interrupts in the low one (Linux's XILINX_VERINT). QEMU's model reads
 * version 13 (KVASER_PCI_XILINX_VERSION_NUMBER) and no interrupts; Linux's
 * driver notes its values are for version 14 (XILINX_PRESUMED_VERSION) and
 * only reports the version.
 */
#define XILINX_VERINT             7
#define XILINX_VERSION_SHIFT      4
#define XILINX_VERSION            13

/* ======================================================================== */
/* The card                                                                  */
/* ======================================================================== */

#define TYPE_LAB_KVASER_PCI "lab-kvaser-pci"
OBJECT_DECLARE_SIMPLE_TYPE(LabKvaserPciState, LAB_KVASER_PCI)

struct LabKvaserPciState {
    PCIDevice parent_obj;

    MemoryRegion bridge_io;
    MemoryRegion chips_io;
    MemoryRegion xilinx_io;
    LabBusLink *link;

    /* The chips' interrupt outputs, and which of them are high. */
    qemu_irq *chip_irqs;
    uint32_t chip_irq_levels;

    /* The S5920 registers the card keeps. */
    uint32_t intcsr;
    uint32_t ptcr;

    /* Properties: the chips carried, and the lab buses they are wired to. */
    uint32_t channels;
    char *hub_path;
    char *hub_name;
    uint32_t hub_timeout_s;
    bool hub_realtime;
    char *bus_name[KVASER_MAX_CHIPS];

    Sja1000Channel chan[KVASER_MAX_CHIPS];
};

/* -- the interrupt ---------------------------------------------------------- */

/* INTA#: a chip's interrupt, let through by the add-on interrupt enable. */
static void kvaser_update_inta(LabKvaserPciState *card)
{
    pci_set_irq(&card->parent_obj, card->chip_irq_levels &&
                (card->intcsr & INTCSR_ADDON_INTENABLE));
}

/* A chip's interrupt output (n: the chip) changed. */
static void kvaser_chip_irq(void *opaque, int n, int level)
{
    LabKvaserPciState *card = opaque;

    if (level) {
        card->chip_irq_levels |= BIT(n);
    } else {
        card->chip_irq_levels &= ~BIT(n);
    }
    kvaser_update_inta(card);
}

/* -- BAR0: the S5920 -------------------------------------------------------- */

static uint32_t kvaser_bridge_register(LabKvaserPciState *card, hwaddr reg)
{
    switch (reg) {
    case S5920_INTCSR:
        return (card->intcsr & ~INTCSR_INTERRUPT_ASSERTED) |
               (card->chip_irq_levels ? INTCSR_INTERRUPT_ASSERTED : 0);
    case S5920_PTCR:
        return card->ptcr;
    default:
        return 0;
    }
}

/*
 * The registers are doublewords; Linux and the firmware access them so.
 * A byte or word access reads or writes its part of the doubleword, as on
 * the S5920's 32-bit PCI target, where QEMU's model answers at the
 * register's own address only.
 */
static uint64_t kvaser_bridge_read(void *opaque, hwaddr addr, unsigned size)
{
    LabKvaserPciState *card = opaque;
    hwaddr reg = QEMU_ALIGN_DOWN(addr, S5920_REGISTER_BYTES);
    unsigned shift = (addr % S5920_REGISTER_BYTES) * BITS_PER_BYTE;

    return extract32(kvaser_bridge_register(card, reg), shift,
                     size * BITS_PER_BYTE);
}

static void kvaser_bridge_write(void *opaque, hwaddr addr, uint64_t data,
                                unsigned size)
{
    LabKvaserPciState *card = opaque;
    hwaddr reg = QEMU_ALIGN_DOWN(addr, S5920_REGISTER_BYTES);
    unsigned shift = (addr % S5920_REGISTER_BYTES) * BITS_PER_BYTE;

    switch (reg) {
    case S5920_INTCSR:
        /* Bit 23 is read only: it always shows the chips' interrupt. */
        card->intcsr = deposit32(card->intcsr, shift, size * BITS_PER_BYTE,
                                 data) & ~INTCSR_INTERRUPT_ASSERTED;
        /* Setting the enable while a chip interrupts asserts INTA# now. */
        kvaser_update_inta(card);
        break;
    case S5920_PTCR:
        card->ptcr = deposit32(card->ptcr, shift, size * BITS_PER_BYTE, data);
        break;
    default:
        break;
    }
}

static const MemoryRegionOps kvaser_bridge_ops = {
    .read = kvaser_bridge_read,
    .write = kvaser_bridge_write,
    .valid.min_access_size = 1,
    .valid.max_access_size = 4,
    .impl.min_access_size = 1,
    .impl.max_access_size = 4,
    .endianness = DEVICE_LITTLE_ENDIAN,
};

/* -- BAR1: the chips -------------------------------------------------------- */

static uint64_t kvaser_chips_read(void *opaque, hwaddr addr, unsigned size)
{
    LabKvaserPciState *card = opaque;
    unsigned chip = addr / KVASER_CHIP_STRIDE;

    if (chip >= card->channels) {
        /* No chip here: nothing drives the data bus (QEMU's reads 0). */
        return 0;
    }
    return sja1000_chip_read(&card->chan[chip], addr % KVASER_CHIP_STRIDE);
}

static void kvaser_chips_write(void *opaque, hwaddr addr, uint64_t value,
                               unsigned size)
{
    LabKvaserPciState *card = opaque;
    unsigned chip = addr / KVASER_CHIP_STRIDE;

    if (chip < card->channels) {
        sja1000_chip_write(&card->chan[chip], addr % KVASER_CHIP_STRIDE,
                           value);
    }
}

static const MemoryRegionOps kvaser_chips_ops = {
    .read = kvaser_chips_read,
    .write = kvaser_chips_write,
    /*
     * The chips sit on the card's 8-bit local bus: a wider access is split
     * into byte accesses at consecutive ports, lowest first, as in QEMU's
     * model (impl.max_access_size 1).
     */
    .valid.min_access_size = 1,
    .valid.max_access_size = 4,
    .impl.min_access_size = 1,
    .impl.max_access_size = 1,
    .endianness = DEVICE_LITTLE_ENDIAN,
};

/* -- BAR2: the Xilinx logic ------------------------------------------------- */

static uint64_t kvaser_xilinx_read(void *opaque, hwaddr addr, unsigned size)
{
    return addr == XILINX_VERINT ? XILINX_VERSION << XILINX_VERSION_SHIFT : 0;
}

static void kvaser_xilinx_write(void *opaque, hwaddr addr, uint64_t value,
                                unsigned size)
{
    /* Nothing the drivers use is written here (QEMU's ignores writes). */
}

static const MemoryRegionOps kvaser_xilinx_ops = {
    .read = kvaser_xilinx_read,
    .write = kvaser_xilinx_write,
    .valid.min_access_size = 1,
    .valid.max_access_size = 4,
    .impl.min_access_size = 1,
    .impl.max_access_size = 1,
    .endianness = DEVICE_LITTLE_ENDIAN,
};

/* -- life cycle ------------------------------------------------------------- */

static void kvaser_realize(PCIDevice *pci, Error **errp)
{
    ERRP_GUARD();
    LabKvaserPciState *card = LAB_KVASER_PCI(pci);
    LabBusLinkConfig config = {
        .path = card->hub_path,
        .name = card->hub_name,
        .timeout_s = card->hub_timeout_s,
        .realtime = card->hub_realtime,
    };
    unsigned i;

    if (card->channels < 1 || card->channels > KVASER_MAX_CHIPS) {
        error_setg(errp, "lab-kvaser-pci: channels=%" PRIu32 " is not 1 to "
                   "%u (a real PCIcan carries 1, 2 or 4)", card->channels,
                   KVASER_MAX_CHIPS);
        return;
    }
    for (i = 0; i < KVASER_MAX_CHIPS; i++) {
        bool named = card->bus_name[i] && *card->bus_name[i];

        if (named && i >= card->channels) {
            error_setg(errp, "lab-kvaser-pci: bus%u=%s names a chip the card "
                       "does not carry (channels=%" PRIu32 ")", i,
                       card->bus_name[i], card->channels);
            return;
        }
    }
    if (!sja1000_card_join_hub(OBJECT(card), TYPE_LAB_KVASER_PCI,
                               card->bus_name, card->channels, &config,
                               &card->link, errp)) {
        return;
    }

    pci->config[PCI_INTERRUPT_PIN] = 1; /* INTA# */
    memory_region_init_io(&card->bridge_io, OBJECT(card), &kvaser_bridge_ops,
                          card, TYPE_LAB_KVASER_PCI "-s5920",
                          KVASER_BRIDGE_PORTS);
    memory_region_init_io(&card->chips_io, OBJECT(card), &kvaser_chips_ops,
                          card, TYPE_LAB_KVASER_PCI "-sja1000",
                          KVASER_CHIPS_PORTS);
    memory_region_init_io(&card->xilinx_io, OBJECT(card), &kvaser_xilinx_ops,
                          card, TYPE_LAB_KVASER_PCI "-xilinx",
                          KVASER_XILINX_PORTS);
    pci_register_bar(pci, KVASER_BRIDGE_BAR, PCI_BASE_ADDRESS_SPACE_IO,
                     &card->bridge_io);
    pci_register_bar(pci, KVASER_CHIPS_BAR, PCI_BASE_ADDRESS_SPACE_IO,
                     &card->chips_io);
    pci_register_bar(pci, KVASER_XILINX_BAR, PCI_BASE_ADDRESS_SPACE_IO,
                     &card->xilinx_io);

    card->chip_irqs = qemu_allocate_irqs(kvaser_chip_irq, card,
                                         card->channels);
    for (i = 0; i < card->channels; i++) {
        if (!sja1000_card_chip_start(&card->chan[i], i, card->chip_irqs[i],
                                     card->link, card->bus_name[i], errp)) {
            return;
        }
    }
}

static void kvaser_exit(PCIDevice *pci)
{
    LabKvaserPciState *card = LAB_KVASER_PCI(pci);
    unsigned i;

    for (i = 0; i < card->channels; i++) {
        sja1000_chip_teardown(&card->chan[i]);
    }
    qemu_free_irqs(card->chip_irqs, card->channels);
    card->chip_irqs = NULL;
    labbus_board_link_forget(card->link);
}

/*
 * The card's reset (PCI RST#): every chip's hardware reset, which leaves it
 * in reset mode with its interrupt low, and the S5920's interrupt control
 * cleared, so INTA# stays off until a driver sets the add-on interrupt
 * enable again. PTCR reads 0 again, as QEMU's model always reads it.
 */
static void kvaser_reset(DeviceState *dev)
{
    LabKvaserPciState *card = LAB_KVASER_PCI(dev);
    unsigned i;

    card->intcsr = 0;
    card->ptcr = 0;
    for (i = 0; i < card->channels; i++) {
        sja1000_chip_hardware_reset(&card->chan[i]);
    }
    kvaser_update_inta(card);
}

static Property kvaser_properties[] = {
    DEFINE_PROP_UINT32("channels", LabKvaserPciState, channels, 1),
    DEFINE_PROP_STRING("hub", LabKvaserPciState, hub_path),
    DEFINE_PROP_STRING("hub-name", LabKvaserPciState, hub_name),
    DEFINE_PROP_UINT32("hub-timeout", LabKvaserPciState, hub_timeout_s, 60),
    DEFINE_PROP_BOOL("hub-realtime", LabKvaserPciState, hub_realtime, false),
    DEFINE_PROP_STRING("bus0", LabKvaserPciState, bus_name[0]),
    DEFINE_PROP_STRING("bus1", LabKvaserPciState, bus_name[1]),
    DEFINE_PROP_STRING("bus2", LabKvaserPciState, bus_name[2]),
    DEFINE_PROP_STRING("bus3", LabKvaserPciState, bus_name[3]),
    DEFINE_PROP_END_OF_LIST(),
};

static void kvaser_class_init(ObjectClass *klass, void *data)
{
    DeviceClass *dc = DEVICE_CLASS(klass);
    PCIDeviceClass *k = PCI_DEVICE_CLASS(klass);
    unsigned i;

    k->realize = kvaser_realize;
    k->exit = kvaser_exit;
    k->vendor_id = KVASER_VENDOR_ID;
    k->device_id = KVASER_DEVICE_ID;
    k->revision = KVASER_REVISION;
    k->class_id = KVASER_CLASS;
    dc->desc = "the lab's Kvaser PCIcan: 1-4 SJA1000s on lab CAN buses";
    dc->reset = kvaser_reset;
    device_class_set_props(dc, kvaser_properties);
    object_class_property_set_description(klass, "channels",
        "SJA1000s on the card, 1 to 4 (a real PCIcan has 1, 2 or 4); the "
        "positions past them read 0");
    object_class_property_set_description(klass, "hub",
        "unix socket of the lab bus hub (dcoslab/canbus.py); none: no hub");
    object_class_property_set_description(klass, "hub-name",
        "this board's participant name at the hub, e.g. board2");
    object_class_property_set_description(klass, "hub-timeout",
        "seconds to wait for a silent hub before stopping the board");
    object_class_property_set_description(klass, "hub-realtime",
        "join the hub as a real-time participant, for a machine run without "
        "-icount: never held at boundaries, events applied on arrival");
    for (i = 0; i < KVASER_MAX_CHIPS; i++) {
        g_autofree char *name = g_strdup_printf("bus%u", i);
        g_autofree char *text = g_strdup_printf(
            "lab bus chip %u is wired to (none: a bus without other nodes)", i);

        object_class_property_set_description(klass, name, text);
    }
    set_bit(DEVICE_CATEGORY_NETWORK, dc->categories);
}

static const TypeInfo kvaser_info = {
    .name          = TYPE_LAB_KVASER_PCI,
    .parent        = TYPE_PCI_DEVICE,
    .instance_size = sizeof(LabKvaserPciState),
    .class_init    = kvaser_class_init,
    .interfaces = (InterfaceInfo[]) {
        { INTERFACE_CONVENTIONAL_PCI_DEVICE },
        { },
    },
};

static void kvaser_register_types(void)
{
    type_register_static(&kvaser_info);
}

type_init(kvaser_register_types)
