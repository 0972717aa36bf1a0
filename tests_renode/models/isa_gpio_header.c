/*
 * DCOS lab GPIO header ("lab-gpio-header"): the ISA 486 board's jumper
 * block and reset line, driven from outside the emulator.
 *
 * A real controller in the field has a service header with two lines a
 * service adapter can pull low: the board's reset line and its recovery
 * strap (docs/guide/flashing.md, "Recovery through the reset and strap
 * lines"). The stage loader reads the strap on the board's jumper port as
 * it starts (firmware/bsp_486/include/bsp/RecoveryStrap.hpp) and goes into
 * recovery while it is low, whatever the card holds. In the lab the
 * adapter is an emulated Microchip MCP2221A in the lab VM
 * (tests_renode/labvm/mcp2221_bridge.py), whose GPIO lines arrive here
 * through a chardev.
 *
 * The port (one byte at iobase, read only; writes are ignored):
 *
 *   bit 0   the recovery strap: 0 pulled low (strapped), 1 released
 *   bit 1   the reset line: 0 pulled low, 1 released
 *   bits 7-2  no jumper: read 1
 *
 * Both lines are released until the outside says otherwise, so a board
 * whose header nobody drives reads 0xFF, as a board without the header
 * reads the floating ISA bus.
 *
 * The line protocol on the chardev (docs/protocols/lab-usb-devices.md,
 * "The board's header"): ASCII lines ended by LF (a CR before it is
 * ignored), one per change of a line, as the adapter's pins change:
 *
 *   strap=0 | strap=1     the recovery strap pulled low / released
 *   reset=0 | reset=1     the reset line pulled low / released
 *
 * The header answers each line with "ok <line>" and, when releasing the
 * reset line restarts the board, "restart" on a line of its own; a line it
 * cannot read with "error <what>". When the reset line goes from low back
 * to high the board restarts (qemu_system_reset_request): a processor held
 * in reset starts when the line is released, so that is when the board's
 * firmware starts again and samples the strap. While the line is low the
 * emulated processor is not stopped (stopping one board would hold every
 * board on its lab bus); nothing the firmware does meanwhile survives the
 * restart that follows. The lines' levels survive a system reset: they
 * are the adapter's, not the board's.
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
#include "qemu/log.h"
#include "qemu/module.h"
#include "qapi/error.h"
#include "qom/object.h"
#include "chardev/char-fe.h"
#include "hw/isa/isa.h"
#include "hw/qdev-properties.h"
#include "hw/qdev-properties-system.h"
#include "sysemu/runstate.h"

#define TYPE_LAB_GPIO_HEADER "lab-gpio-header"
OBJECT_DECLARE_SIMPLE_TYPE(LabGpioHeaderState, LAB_GPIO_HEADER)

/* The port's bits (firmware/bsp_486/include/bsp/RecoveryStrap.hpp). */
#define HEADER_STRAP_BIT   0x01
#define HEADER_RESET_BIT   0x02
#define HEADER_NO_JUMPERS  0xFC

/* The longest line the protocol has is 7 characters; longer ones are errors. */
#define HEADER_LINE_MAX 32

struct LabGpioHeaderState {
    ISADevice parent_obj;

    MemoryRegion io;
    CharBackend chr;
    uint32_t iobase;

    /* The lines' levels: true released (high), false pulled low. */
    bool strap_high;
    bool reset_high;

    char line[HEADER_LINE_MAX];
    size_t line_length;
    bool line_overflow;
};

static uint64_t header_read(void *opaque, hwaddr addr, unsigned size)
{
    LabGpioHeaderState *s = opaque;
    uint8_t value = HEADER_NO_JUMPERS;

    if (s->strap_high) {
        value |= HEADER_STRAP_BIT;
    }
    if (s->reset_high) {
        value |= HEADER_RESET_BIT;
    }
    return value;
}

static void header_write(void *opaque, hwaddr addr, uint64_t value,
                         unsigned size)
{
    /* The jumper block is read only: a write goes nowhere. */
}

static const MemoryRegionOps header_ops = {
    .read = header_read,
    .write = header_write,
    .valid.min_access_size = 1,
    .valid.max_access_size = 1,
    .impl.min_access_size = 1,
    .impl.max_access_size = 1,
    .endianness = DEVICE_LITTLE_ENDIAN,
};

static void header_answer(LabGpioHeaderState *s, const char *text)
{
    char answer[2 * HEADER_LINE_MAX + 16];
    int length = snprintf(answer, sizeof(answer), "%s\n", text);

    if (length > 0 && qemu_chr_fe_backend_connected(&s->chr)) {
        qemu_chr_fe_write_all(&s->chr, (const uint8_t *)answer,
                              MIN((size_t)length, sizeof(answer) - 1));
    }
}

/* One complete line from the outside: a change of one of the lines. */
static void header_take_line(LabGpioHeaderState *s, const char *line)
{
    char answer[2 * HEADER_LINE_MAX];
    bool high;
    bool *level;

    if (!strcmp(line, "strap=0") || !strcmp(line, "strap=1")) {
        level = &s->strap_high;
    } else if (!strcmp(line, "reset=0") || !strcmp(line, "reset=1")) {
        level = &s->reset_high;
    } else {
        qemu_log_mask(LOG_GUEST_ERROR, "lab-gpio-header: unknown line '%s'\n",
                      line);
        snprintf(answer, sizeof(answer), "error unknown line '%s'", line);
        header_answer(s, answer);
        return;
    }
    high = line[6] == '1';
    snprintf(answer, sizeof(answer), "ok %s", line);
    header_answer(s, answer);
    if (level == &s->reset_high && high && !s->reset_high) {
        s->reset_high = true;
        header_answer(s, "restart");
        /*
         * The adapter is outside the board, as a reset button is: the
         * cause QEMU has for that is the user interface's.
         */
        qemu_system_reset_request(SHUTDOWN_CAUSE_HOST_UI);
        return;
    }
    *level = high;
}

static int header_can_receive(void *opaque)
{
    return HEADER_LINE_MAX;
}

static void header_receive(void *opaque, const uint8_t *buf, int size)
{
    LabGpioHeaderState *s = opaque;
    int i;

    for (i = 0; i < size; i++) {
        char c = (char)buf[i];

        if (c == '\r') {
            continue;
        }
        if (c != '\n') {
            if (s->line_length + 1 < sizeof(s->line)) {
                s->line[s->line_length++] = c;
            } else {
                s->line_overflow = true;
            }
            continue;
        }
        s->line[s->line_length] = '\0';
        if (s->line_overflow) {
            header_answer(s, "error line too long");
        } else if (s->line_length != 0) {
            header_take_line(s, s->line);
        }
        s->line_length = 0;
        s->line_overflow = false;
    }
}

static void header_realize(DeviceState *dev, Error **errp)
{
    ISADevice *isa = ISA_DEVICE(dev);
    LabGpioHeaderState *s = LAB_GPIO_HEADER(dev);

    if (s->iobase > 0xffff) {
        error_setg(errp, "lab-gpio-header: iobase 0x%" PRIx32 " is not an "
                   "I/O port", s->iobase);
        return;
    }
    s->strap_high = true;
    s->reset_high = true;
    memory_region_init_io(&s->io, OBJECT(dev), &header_ops, s,
                          TYPE_LAB_GPIO_HEADER, 1);
    isa_register_ioport(isa, &s->io, s->iobase);
    qemu_chr_fe_set_handlers(&s->chr, header_can_receive, header_receive,
                             NULL, NULL, s, NULL, true);
}

static Property header_properties[] = {
    DEFINE_PROP_UINT32("iobase", LabGpioHeaderState, iobase, 0x2c0),
    DEFINE_PROP_CHR("chardev", LabGpioHeaderState, chr),
    DEFINE_PROP_END_OF_LIST(),
};

static void header_class_init(ObjectClass *klass, void *data)
{
    DeviceClass *dc = DEVICE_CLASS(klass);

    dc->desc = "DCOS lab GPIO header: the recovery strap and reset line";
    dc->realize = header_realize;
    /*
     * No reset handler: the lines' levels are the adapter's and survive
     * the board's restart, which is the point of the strap.
     */
    device_class_set_props(dc, header_properties);
    object_class_property_set_description(klass, "iobase",
        "I/O port of the jumper block (default 0x2c0)");
    object_class_property_set_description(klass, "chardev",
        "chardev carrying the lines' changes ('strap=0', 'reset=1', ...)");
    set_bit(DEVICE_CATEGORY_MISC, dc->categories);
}

static const TypeInfo header_info = {
    .name          = TYPE_LAB_GPIO_HEADER,
    .parent        = TYPE_ISA_DEVICE,
    .instance_size = sizeof(LabGpioHeaderState),
    .class_init    = header_class_init,
};

static void header_register_types(void)
{
    type_register_static(&header_info);
}

type_init(header_register_types)
