/*
 * One Philips/NXP SJA1000 stand-alone CAN controller on a lab bus: the chip
 * the lab's CAN cards carry (isa_sja1000.c, the two-channel ISA card;
 * pci_kvaser_lab.c, the Kvaser PCIcan). sja1000_lab_chip.c explains what
 * the chip does; a card is a thin bus front end that maps each chip's 32
 * registers, wires its interrupt and gives it the board's link to the hub,
 * as Linux's and Zephyr's SJA1000 drivers put one chip core behind thin
 * bus front ends.
 *
 * A front end embeds one Sja1000Channel per chip and touches it only
 * through the functions below: init at realize, attach for a chip wired to
 * a lab bus, read and write for its register window, hardware reset at
 * the card's reset, teardown at unrealize.
 *
 * This program is free software; you can redistribute it and/or
 * modify it under the terms of the GNU General Public License as
 * published by the Free Software Foundation; either version 2 or
 * (at your option) any later version.
 */

#ifndef SJA1000_LAB_CHIP_H
#define SJA1000_LAB_CHIP_H

#include "qemu/queue.h"
#include "qemu/timer.h"
#include "hw/irq.h"
#include "hw/net/can/can_sja1000.h"
#include "net/can_emu.h"

#include "labbus_link.h"

/*
 * The chip's register window: 32 addresses, register n at offset n (DS
 * 6.4.1, Table 7; DS 6.3.1, Table 2), as every card of the lab maps it.
 */
#define SJA1000_CHIP_REGISTERS  0x20

/*
 * How the channel takes part in the bus, as reported to the hub
 * (docs/protocols/labbus.md, STATE): off in reset mode or bus-off, wait
 * after reset mode until a bus-free signal, recover while counting the 128
 * bus-free signals after bus-off, sleep in sleep mode, on otherwise.
 */
typedef enum ChanBusMode {
    BUS_MODE_OFF,
    BUS_MODE_WAIT,
    BUS_MODE_ON,
    BUS_MODE_RECOVER,
    BUS_MODE_SLEEP,
} ChanBusMode;

/* What happens on the bus to one channel (sja1000_lab_chip.c). */
typedef struct ChanEvent ChanEvent;

typedef struct Sja1000Channel {
    /* The board's link to the hub, or NULL on a board without a hub. */
    LabBusLink *link;
    /* The channel's name at the hub and in messages ("0" for board1.0). */
    char label[8];

    /* QEMU's SJA1000: registers, filters, FIFO, buffers. */
    CanSJA1000State core;

    /* Registers the core does not model. */
    uint8_t btr0;
    uint8_t btr1;
    uint8_t ocr;
    uint8_t alc;
    uint8_t ecc;
    uint8_t ewlr;
    bool alc_captured;     /* ALC is held until read (DS 6.4.8) */
    bool ecc_captured;     /* ECC is held until read (DS 6.4.9) */
    unsigned tec;          /* transmit error count, 0..256 */
    unsigned rec;          /* receive error count, 0..255 */
    /* SR bits TBS, TCS, RS, TS, ES and BS. */
    uint8_t status;

    /* Error states. */
    bool bus_off;
    bool passive;
    /* A bus-off flag cleared by a TXERR write: EI when reset mode ends. */
    bool deferred_ei;
    bool joined;           /* a bus-free signal seen since reset mode */
    bool sleeping;
    unsigned recovery_signals;

    /* The transmit buffer's request. */
    bool tx_pending;
    bool tx_single_shot;
    bool tx_self;
    bool tx_abort_requested;
    qemu_can_frame tx_frame;
    uint8_t tx_raw_dlc;

    /* Participation as last reported; epoch drops stale events. */
    ChanBusMode mode;
    uint32_t epoch;
    bool reported;
    ChanBusMode reported_mode;
    bool reported_passive;
    uint64_t reported_bit_ns;
    uint8_t reported_mod;

    /* The hub port, or -1 for a lone bus. */
    int port;

    QTAILQ_HEAD(, ChanEvent) events;
    QEMUTimer *event_timer;
    /* Set while due events are applied, which may queue more. */
    bool running_events;

    /* The lone bus (no hub): when it is free and whether a frame is on it. */
    int64_t lone_free_at;
    bool lone_in_attempt;
    /* The one attempt scheduled, or -1: a request has one at a time. */
    int64_t lone_next_attempt;
} Sja1000Channel;

/*
 * Makes the chip: its interrupt output drives irq (level: high while an
 * enabled interrupt is pending), and it takes part in a lab bus through
 * link, the board's one link to the hub (labbus_board_link_join), or NULL
 * for a board without a hub. The chip is on a lone bus until attached; a
 * hardware reset (the card's) gives it its reset state.
 */
void sja1000_chip_init(Sja1000Channel *ch, qemu_irq irq, LabBusLink *link);

/*
 * Wires the chip to the lab bus named bus, as port <hub-name>.<label> of
 * the board's link (label: one short word, e.g. the channel's number).
 * Needs a link; false with errp set if the hub refuses the port.
 */
bool sja1000_chip_attach(Sja1000Channel *ch, const char *bus,
                         const char *label, Error **errp);

/*
 * What a card's realize does for its chips' buses, the same on every card:
 * a chip named to a bus (bus_names[i] set and not empty, for the first
 * chips of them) needs a hub (config->path); with a hub, the board's link
 * is joined (labbus_board_link_join, shared with the board's other lab
 * devices) and stored in *link, which is NULL without one. device names
 * the card in the messages. false with errp set on failure.
 */
bool sja1000_card_join_hub(Object *card, const char *device,
                           char *const *bus_names, unsigned chips,
                           const LabBusLinkConfig *config, LabBusLink **link,
                           Error **errp);

/*
 * Makes chip index of a card (sja1000_chip_init) and, when bus is set and
 * not empty, wires it to that lab bus as the port labelled with its index
 * (<hub-name>.<index>). false with errp set if the hub refuses the port.
 */
bool sja1000_card_chip_start(Sja1000Channel *ch, unsigned index, qemu_irq irq,
                             LabBusLink *link, const char *bus, Error **errp);

/* A CPU read of register addr (0..SJA1000_CHIP_REGISTERS - 1). */
uint8_t sja1000_chip_read(Sja1000Channel *ch, unsigned addr);

/* A CPU write of register addr (0..SJA1000_CHIP_REGISTERS - 1). */
void sja1000_chip_write(Sja1000Channel *ch, unsigned addr, uint8_t value);

/* The chip's hardware reset (its RST pin, DS 6.3.2 and 6.4.2). */
void sja1000_chip_hardware_reset(Sja1000Channel *ch);

/* Drops the chip's pending events and frees its timer, at unrealize. */
void sja1000_chip_teardown(Sja1000Channel *ch);

#endif
