/*
 * The link that joins a board to the lab's hub ("labbus-link"): the
 * lock-step of the board's emulated clock with the other boards', and the
 * message channel of every device of the board that takes part in a lab
 * bus or line (the SJA1000 CAN cards, isa_sja1000.c and pci_kvaser_lab.c,
 * through their chips, sja1000_lab_chip.c; the RS-485 UART, isa_rs485.c).
 * docs/protocols/labbus.md specifies the protocol.
 *
 * This program is free software; you can redistribute it and/or
 * modify it under the terms of the GNU General Public License as
 * published by the Free Software Foundation; either version 2 or
 * (at your option) any later version.
 */

#ifndef LABBUS_LINK_H
#define LABBUS_LINK_H

#include "qom/object.h"

#define TYPE_LABBUS_LINK "labbus-link"
typedef struct LabBusLink LabBusLink;

/* The longest line either side may send, newline included. */
#define LABBUS_LINE_MAX 256
/* The most words in one line (the longest, RX, has 9). */
#define LABBUS_MAX_WORDS 16

/*
 * Called with the words of each event the hub sends for a port; argv[1] is
 * the port number, argv[2] the epoch and argv[3] the event's time.
 */
typedef void (*LabBusEventFn)(void *opaque, int argc, char **argv);

/* What a device names when it joins the board to a hub (its properties). */
typedef struct LabBusLinkConfig {
    const char *path;
    const char *name;
    uint32_t timeout_s;
    bool realtime;
} LabBusLinkConfig;

/*
 * The board's one link to the hub at config->path: made, connected and
 * made a child of owner by the first device that asks, and shared by the
 * next ones, which must name the same hub, board name and kind (one board
 * holds one place in the lock-step). Returns NULL with errp set on failure.
 */
LabBusLink *labbus_board_link_join(Object *owner, const LabBusLinkConfig *config,
                                   Error **errp);

/* Forgets the board's link when the device that made it goes away. */
void labbus_board_link_forget(LabBusLink *link);

/*
 * Attaches one port to the named bus or line; called by a device at
 * realize. Returns the port number, or -1 with errp set.
 */
int labbus_link_attach(LabBusLink *link, const char *bus, const char *label,
                       LabBusEventFn event, void *opaque, Error **errp);

/* Sends one message line (without its newline); a dead hub stops the board. */
void G_GNUC_PRINTF(2, 3) labbus_link_send(LabBusLink *link,
                                          const char *format, ...);

/*
 * The time word of a message to the hub: the exact emulated time, or "-"
 * from a real-time link.
 */
const char *labbus_link_time(LabBusLink *link, int64_t now, char *buffer,
                             size_t size);

/* Stops the board with a message: it cannot go on without the hub. */
G_NORETURN void labbus_link_fatal(LabBusLink *link, const char *format, ...)
    G_GNUC_PRINTF(2, 3);

/*
 * Milliseconds of QEMU_CLOCK_REALTIME left until deadline_ms, 0 when past:
 * the lab's sockets (the hub, the I/O board's plant) wait at most that.
 */
int64_t labbus_remaining_ms(int64_t deadline_ms);

/*
 * Sends length bytes on a stream socket without blocking the board for
 * longer than until deadline_ms (QEMU_CLOCK_REALTIME); false if the peer is
 * gone or took nothing in time.
 */
bool labbus_send_all(int fd, const char *text, size_t length,
                     int64_t deadline_ms);

/* Whether the link is a real-time participant's (hub-realtime=on). */
bool labbus_link_realtime(LabBusLink *link);

/* Parses a whole decimal number; false for anything else. */
bool labbus_parse_u64(const char *text, uint64_t *value);

#endif
