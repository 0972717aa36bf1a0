/*
 * DCOS two-channel ISA SJA1000 CAN card ("isa-sja1000").
 *
 * The card is a PC/104-style board with two Philips/NXP SJA1000 stand-alone
 * CAN controllers, port mapped: channel 0 answers the 32 ports from iobase,
 * channel 1 the 32 ports from iobase + 0x20 (register n of a chip at port
 * base + n, as Linux's sja1000_isa driver addresses a port-mapped chip with
 * reg_shift 0). Each channel has its own ISA interrupt line. The chips run
 * from the usual 16 MHz crystal (CAN clock 8 MHz), so BRP 0 is a time
 * quantum of 125 ns.
 *
 * This file is the card's ISA front end: the ports, the interrupt lines,
 * the properties and the board's link. The chips are the lab's SJA1000
 * core, sja1000_lab_chip.c: QEMU's reviewed SJA1000 core
 * (hw/net/can/can_sja1000.c) with the bus timing, transmission on the lab
 * bus and fault confinement it lacks. The Kvaser PCIcan, pci_kvaser_lab.c,
 * is the other front end over the same chips.
 *
 * A channel named to a lab bus (bus0, bus1) joins the hub through the
 * board's link (properties hub and hub-name; labbus_link.c, shared with
 * the RS-485 UART of isa_rs485.c), a child object that holds the
 * board's emulated time at quantum boundaries so that every board on the
 * hub stays in step. A machine that runs in real time (no -icount, such as
 * the lab VM's Linux) cannot be held that way, as its clock follows the
 * host's; with hub-realtime=on its link joins the hub as a real-time
 * participant instead, which never holds the boards, takes the hub's events
 * as they arrive and lets its own requests count from the hub's next
 * boundary. (QEMU 7.2 creates with -object only the types its
 * QAPI schema lists, so the link is made by the first device that names a
 * hub rather than by the user; one board has one link, which every device
 * of the board that names the hub shares.) The hub
 * is tests_renode/dcoslab/canbus.py; docs/protocols/labbus.md specifies the
 * protocol, the lock-step and the timing model the chips follow. A channel
 * without a bus is a chip on a bus with no other node: the chip simulates
 * that lone bus itself, with the same timing model, so its frames are never
 * acknowledged.
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
#include "qemu/module.h"
#include "qapi/error.h"
#include "qom/object.h"
#include "hw/irq.h"
#include "hw/isa/isa.h"
#include "hw/qdev-properties.h"

#include "labbus_link.h"
#include "sja1000_lab_chip.h"

/* The card: two chips, 32 ports each. */
#define SJA_CARD_CHANNELS     2
#define SJA_CHANNEL_PORTS     SJA1000_CHIP_REGISTERS
#define SJA_CARD_PORTS        (SJA_CARD_CHANNELS * SJA_CHANNEL_PORTS)

#define TYPE_ISA_SJA1000 "isa-sja1000"
OBJECT_DECLARE_SIMPLE_TYPE(IsaSja1000State, ISA_SJA1000)

struct IsaSja1000State {
    ISADevice parent_obj;

    MemoryRegion io;
    LabBusLink *link;

    /* Properties: jumpers, and the lab buses the channels are wired to. */
    uint32_t iobase;
    uint32_t irq_line[SJA_CARD_CHANNELS];
    char *hub_path;
    char *hub_name;
    uint32_t hub_timeout_s;
    bool hub_realtime;
    char *bus_name[SJA_CARD_CHANNELS];

    Sja1000Channel chan[SJA_CARD_CHANNELS];
};

/* -- the ports ------------------------------------------------------------ */

static uint64_t sja_card_read(void *opaque, hwaddr addr, unsigned size)
{
    IsaSja1000State *card = opaque;

    return sja1000_chip_read(&card->chan[addr / SJA_CHANNEL_PORTS],
                             addr % SJA_CHANNEL_PORTS);
}

static void sja_card_write(void *opaque, hwaddr addr, uint64_t value,
                           unsigned size)
{
    IsaSja1000State *card = opaque;

    sja1000_chip_write(&card->chan[addr / SJA_CHANNEL_PORTS],
                       addr % SJA_CHANNEL_PORTS, value);
}

static const MemoryRegionOps sja_card_ops = {
    .read = sja_card_read,
    .write = sja_card_write,
    /*
     * The chips sit on the card's 8-bit data path: a 16- or 32-bit access
     * is split into byte accesses at consecutive ports, lowest first.
     */
    .valid.min_access_size = 1,
    .valid.max_access_size = 4,
    .impl.min_access_size = 1,
    .impl.max_access_size = 1,
    .endianness = DEVICE_LITTLE_ENDIAN,
};

static void sja_card_realize(DeviceState *dev, Error **errp)
{
    ERRP_GUARD();
    ISADevice *isa = ISA_DEVICE(dev);
    IsaSja1000State *card = ISA_SJA1000(dev);
    LabBusLinkConfig config = {
        .path = card->hub_path,
        .name = card->hub_name,
        .timeout_s = card->hub_timeout_s,
        .realtime = card->hub_realtime,
    };
    unsigned i;

    if (card->iobase > 0x10000 - SJA_CARD_PORTS ||
        (card->iobase & (SJA_CHANNEL_PORTS - 1))) {
        error_setg(errp, "isa-sja1000: iobase 0x%" PRIx32 " must be a "
                   "multiple of 0x%x with 0x%x ports below 0x10000",
                   card->iobase, SJA_CHANNEL_PORTS, SJA_CARD_PORTS);
        return;
    }
    for (i = 0; i < SJA_CARD_CHANNELS; i++) {
        if (card->irq_line[i] >= ISA_NUM_IRQS) {
            error_setg(errp, "isa-sja1000: irq%u %" PRIu32 " is not an ISA "
                       "line (0..15)", i, card->irq_line[i]);
            return;
        }
    }
    if (card->irq_line[0] == card->irq_line[1]) {
        /*
         * ISA interrupts are edge triggered and not shared: one line per
         * chip, as the card's jumpers allow.
         */
        error_setg(errp, "isa-sja1000: irq0 and irq1 are both %" PRIu32
                   "; each channel needs its own line", card->irq_line[0]);
        return;
    }
    if (!sja1000_card_join_hub(OBJECT(card), TYPE_ISA_SJA1000, card->bus_name,
                               SJA_CARD_CHANNELS, &config, &card->link,
                               errp)) {
        return;
    }

    memory_region_init_io(&card->io, OBJECT(dev), &sja_card_ops, card,
                          TYPE_ISA_SJA1000, SJA_CARD_PORTS);
    isa_register_ioport(isa, &card->io, card->iobase);
    for (i = 0; i < SJA_CARD_CHANNELS; i++) {
        if (!sja1000_card_chip_start(&card->chan[i], i,
                                     isa_get_irq(isa, card->irq_line[i]),
                                     card->link, card->bus_name[i], errp)) {
            return;
        }
    }
}

static void sja_card_unrealize(DeviceState *dev)
{
    IsaSja1000State *card = ISA_SJA1000(dev);
    unsigned i;

    for (i = 0; i < SJA_CARD_CHANNELS; i++) {
        sja1000_chip_teardown(&card->chan[i]);
    }
    labbus_board_link_forget(card->link);
}

static void sja_card_reset(DeviceState *dev)
{
    IsaSja1000State *card = ISA_SJA1000(dev);
    unsigned i;

    for (i = 0; i < SJA_CARD_CHANNELS; i++) {
        sja1000_chip_hardware_reset(&card->chan[i]);
    }
}

static Property sja_card_properties[] = {
    DEFINE_PROP_UINT32("iobase", IsaSja1000State, iobase, 0x280),
    DEFINE_PROP_UINT32("irq0", IsaSja1000State, irq_line[0], 10),
    DEFINE_PROP_UINT32("irq1", IsaSja1000State, irq_line[1], 11),
    DEFINE_PROP_STRING("hub", IsaSja1000State, hub_path),
    DEFINE_PROP_STRING("hub-name", IsaSja1000State, hub_name),
    DEFINE_PROP_UINT32("hub-timeout", IsaSja1000State, hub_timeout_s, 60),
    DEFINE_PROP_BOOL("hub-realtime", IsaSja1000State, hub_realtime, false),
    DEFINE_PROP_STRING("bus0", IsaSja1000State, bus_name[0]),
    DEFINE_PROP_STRING("bus1", IsaSja1000State, bus_name[1]),
    DEFINE_PROP_END_OF_LIST(),
};

static void sja_card_class_init(ObjectClass *klass, void *data)
{
    DeviceClass *dc = DEVICE_CLASS(klass);

    dc->desc = "DCOS two-channel ISA SJA1000 CAN card (16 MHz)";
    dc->realize = sja_card_realize;
    dc->unrealize = sja_card_unrealize;
    dc->reset = sja_card_reset;
    device_class_set_props(dc, sja_card_properties);
    object_class_property_set_description(klass, "iobase",
        "base port: channel 0 at iobase, channel 1 at iobase + 0x20");
    object_class_property_set_description(klass, "irq0",
        "ISA interrupt line of channel 0 (jumper)");
    object_class_property_set_description(klass, "irq1",
        "ISA interrupt line of channel 1 (jumper)");
    object_class_property_set_description(klass, "hub",
        "unix socket of the lab bus hub (dcoslab/canbus.py); none: no hub");
    object_class_property_set_description(klass, "hub-name",
        "this board's participant name at the hub, e.g. board1");
    object_class_property_set_description(klass, "hub-timeout",
        "seconds to wait for a silent hub before stopping the board");
    object_class_property_set_description(klass, "hub-realtime",
        "join the hub as a real-time participant, for a machine run without "
        "-icount: never held at boundaries, events applied on arrival");
    object_class_property_set_description(klass, "bus0",
        "lab bus channel 0 is wired to (none: a bus without other nodes)");
    object_class_property_set_description(klass, "bus1",
        "lab bus channel 1 is wired to (none: a bus without other nodes)");
    set_bit(DEVICE_CATEGORY_NETWORK, dc->categories);
}

static const TypeInfo sja_card_info = {
    .name          = TYPE_ISA_SJA1000,
    .parent        = TYPE_ISA_DEVICE,
    .instance_size = sizeof(IsaSja1000State),
    .class_init    = sja_card_class_init,
};

static void sja_card_register_types(void)
{
    type_register_static(&sja_card_info);
}

type_init(sja_card_register_types)
