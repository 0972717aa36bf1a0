/*
 * The link that joins a board to the lab's hub ("labbus-link"): see
 * labbus_link.h. It was the SJA1000 card's own until the RS-485 UART
 * (isa_rs485.c) joined the hub too; one board has one place in the
 * lock-step, so the devices of a board share one link.
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
#include "qemu/cutils.h"
#include "qemu/error-report.h"
#include "qemu/main-loop.h"
#include "qemu/module.h"
#include "qemu/timer.h"
#include "qapi/error.h"
#include "qom/object.h"
#include "sysemu/cpu-timers.h"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>

#include "labbus_link.h"

/* ======================================================================== */
/* The lab bus link                                                          */
/* ======================================================================== */

DECLARE_INSTANCE_CHECKER(LabBusLink, LABBUS_LINK, TYPE_LABBUS_LINK)

/* The protocol version of docs/protocols/labbus.md this file speaks. */
#define LABBUS_PROTOCOL_VERSION 1
/* Ports one board's link may attach (the card's channels take two). */
#define LABBUS_MAX_PORTS 8

typedef struct LabBusPort {
    char *bus;
    LabBusEventFn event;
    void *opaque;
} LabBusPort;

struct LabBusLink {
    Object parent_obj;

    /* Properties. */
    char *path;
    char *name;
    uint32_t timeout_s;
    /*
     * A real-time participant (docs/protocols/labbus.md, "Real-time
     * participants"): no quantum boundaries, events applied on arrival,
     * requests sent with the time "-".
     */
    bool realtime;

    int fd;
    uint64_t quantum_ns;
    QEMUTimer *boundary_timer;
    /* The boundary the timer is set for. */
    int64_t boundary;
    LabBusPort ports[LABBUS_MAX_PORTS];
    unsigned port_count;
    /* Bytes received and not yet consumed as lines. */
    char input[LABBUS_LINE_MAX * 8];
    size_t input_length;
    /* Quantum boundaries held so far; readable as "boundaries". */
    uint64_t boundaries;
    /* Boundaries reached late (see labbus_link_boundary). */
    uint64_t late_boundaries;
};

/*
 * The link cannot go on without the hub: the board's emulated time is only
 * meaningful in step with the others. A dead or silent hub therefore ends
 * the emulator with a message, which the lab prints with the console
 * transcript, instead of letting the board run on alone.
 */
void labbus_link_fatal(LabBusLink *link, const char *format, ...)
{
    va_list args;
    char *why;

    va_start(args, format);
    why = g_strdup_vprintf(format, args);
    va_end(args);
    error_report("labbus-link %s: %s; the board cannot keep in step with the "
                 "lab bus and stops", link->name ? link->name : "?", why);
    g_free(why);
    exit(EXIT_FAILURE);
}

int64_t labbus_remaining_ms(int64_t deadline_ms)
{
    int64_t remaining = deadline_ms - qemu_clock_get_ms(QEMU_CLOCK_REALTIME);

    return remaining > 0 ? remaining : 0;
}

bool labbus_send_all(int fd, const char *text, size_t length,
                     int64_t deadline_ms)
{
    size_t sent = 0;

    while (sent < length) {
        ssize_t count = send(fd, text + sent, length - sent,
                             MSG_NOSIGNAL | MSG_DONTWAIT);

        if (count > 0) {
            sent += count;
        } else if (count < 0 && errno == EINTR) {
            continue;
        } else if (count < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            struct pollfd pfd = { .fd = fd, .events = POLLOUT };
            int64_t remaining = labbus_remaining_ms(deadline_ms);

            if (remaining == 0 || poll(&pfd, 1, remaining) <= 0) {
                return false;
            }
        } else {
            return false;
        }
    }
    return true;
}

/* Sends one whole line; false if the hub is gone or took none in time. */
static bool labbus_send_raw(LabBusLink *link, const char *text, size_t length)
{
    return labbus_send_all(link->fd, text, length,
                           qemu_clock_get_ms(QEMU_CLOCK_REALTIME) +
                           (int64_t)link->timeout_s * 1000);
}

void labbus_link_send(LabBusLink *link, const char *format, ...)
{
    char line[LABBUS_LINE_MAX];
    va_list args;
    int length;

    va_start(args, format);
    length = vsnprintf(line, sizeof(line) - 1, format, args);
    va_end(args);
    if (length < 0 || length >= (int)sizeof(line) - 1) {
        labbus_link_fatal(link, "a message did not fit in %d bytes",
                          LABBUS_LINE_MAX);
    }
    line[length++] = '\n';
    if (!labbus_send_raw(link, line, length)) {
        labbus_link_fatal(link, "could not send to the hub at %s (%s)",
                          link->path, strerror(errno));
    }
}

/*
 * Takes the next whole line received from the hub out of the input buffer,
 * without its newline; NULL when there is none yet, with *why set if the
 * buffer is full without one or the line is too long. The line stays
 * valid until the next call.
 */
static char *labbus_buffered_line(LabBusLink *link, const char **why)
{
    static char line[LABBUS_LINE_MAX];
    char *newline = memchr(link->input, '\n', link->input_length);
    size_t length;

    if (!newline) {
        if (link->input_length >= sizeof(link->input)) {
            *why = "the hub sent a line that is too long";
        }
        return NULL;
    }
    length = newline - link->input;
    if (length >= sizeof(line)) {
        *why = "the hub sent a line that is too long";
        return NULL;
    }
    memcpy(line, link->input, length);
    line[length] = '\0';
    if (length > 0 && line[length - 1] == '\r') {
        line[length - 1] = '\0';
    }
    link->input_length -= length + 1;
    memmove(link->input, newline + 1, link->input_length);
    return line;
}

/*
 * Returns the next line from the hub without its newline, or NULL with
 * *why set when the hub closed the connection, sent a line that is too
 * long, or sent nothing for timeout_s seconds. The line stays valid until
 * the next call.
 */
static char *labbus_read_line(LabBusLink *link, const char **why)
{
    int64_t deadline_ms = qemu_clock_get_ms(QEMU_CLOCK_REALTIME) +
                          (int64_t)link->timeout_s * 1000;

    *why = NULL;
    for (;;) {
        char *line = labbus_buffered_line(link, why);
        ssize_t count;

        if (line || *why) {
            return line;
        }
        count = recv(link->fd, link->input + link->input_length,
                     sizeof(link->input) - link->input_length, MSG_DONTWAIT);
        if (count > 0) {
            link->input_length += count;
        } else if (count == 0) {
            *why = "the hub closed the connection";
            return NULL;
        } else if (errno == EINTR) {
            continue;
        } else if (errno == EAGAIN || errno == EWOULDBLOCK) {
            struct pollfd pfd = { .fd = link->fd, .events = POLLIN };
            int64_t remaining = labbus_remaining_ms(deadline_ms);
            int ready;

            if (remaining == 0) {
                *why = "the hub did not answer in time";
                return NULL;
            }
            ready = poll(&pfd, 1, remaining);
            if (ready < 0 && errno != EINTR) {
                *why = "poll() on the hub connection failed";
                return NULL;
            }
        } else {
            *why = "reading from the hub failed";
            return NULL;
        }
    }
}

/* Splits line in place at spaces; returns the number of words. */
static int labbus_split(char *line, char **argv)
{
    int argc = 0;
    char *cursor = line;

    while (*cursor && argc < LABBUS_MAX_WORDS) {
        while (*cursor == ' ') {
            cursor++;
        }
        if (!*cursor) {
            break;
        }
        argv[argc++] = cursor;
        while (*cursor && *cursor != ' ') {
            cursor++;
        }
        if (*cursor) {
            *cursor++ = '\0';
        }
    }
    return argc;
}

bool labbus_parse_u64(const char *text, uint64_t *value)
{
    const char *end;

    return qemu_strtou64(text, &end, 10, value) == 0 && *end == '\0';
}

/* Hands one event line to the port it names. */
static void labbus_dispatch(LabBusLink *link, char *line)
{
    char *argv[LABBUS_MAX_WORDS];
    int argc = labbus_split(line, argv);
    uint64_t port;

    if (argc == 0) {
        return;
    }
    if (!strcmp(argv[0], "ERROR")) {
        labbus_link_fatal(link, "the hub reported an error: %s",
                          argc > 1 ? argv[1] : "(no reason)");
    }
    if (argc < 4 || !labbus_parse_u64(argv[1], &port) ||
        port >= link->port_count) {
        labbus_link_fatal(link, "the hub sent '%s', which is no event for a "
                          "port of this board", argv[0]);
    }
    link->ports[port].event(link->ports[port].opaque, argc, argv);
}

/*
 * The lock-step (docs/protocols/labbus.md, "Lock-step"): at every quantum
 * boundary the board reports SYNC and waits for the hub's GO, taking in the
 * events the hub sends before it. Under -icount this callback runs in the
 * vCPU thread with the big lock held and the guest's budget ends exactly
 * at the deadline, so the board stands still at the boundary to the
 * nanosecond. The lock is kept while waiting: releasing it would let the
 * main loop stop or reset the machine while this callback cannot return.
 */
static void labbus_link_boundary(void *opaque)
{
    LabBusLink *link = opaque;
    int64_t now = qemu_clock_get_ns(QEMU_CLOCK_VIRTUAL);
    const char *why = NULL;

    /*
     * A timer is out of its list while its callback runs, and QEMU's
     * icount skips an idle vCPU's clock to the next deadline whenever a
     * QEMU_CLOCK_VIRTUAL timer becomes the first of its list
     * (timerlist_rearm). The events taken in below arm the card's timers:
     * without this timer in the list, such a skip would carry the board
     * past the boundary it is holding at. Set for now, it keeps the
     * deadline at zero until GO sets the next boundary.
     */
    timer_mod_ns(link->boundary_timer, now);

    /*
     * The boundary is the one the hub set, even if the clock is past it.
     * Under -icount,sleep=off the main loop skips an idle vCPU's clock to
     * the next deadline; a vCPU that an I/O thread woke a moment before can
     * still execute a few hundred instructions during that skip, so now and
     * then the timer runs that many nanoseconds late. The hub is told by
     * how much, and takes what the board sent in that time as sent in the
     * next quantum.
     */
    if (now > link->boundary) {
        link->late_boundaries++;
        labbus_link_send(link, "SYNC %" PRId64 " %" PRId64, link->boundary,
                         now - link->boundary);
    } else {
        labbus_link_send(link, "SYNC %" PRId64, link->boundary);
    }
    for (;;) {
        char *line = labbus_read_line(link, &why);
        uint64_t next;

        if (!line) {
            labbus_link_fatal(link, "at boundary %" PRId64 " ns: %s", now,
                              why);
        }
        if (!strncmp(line, "GO ", 3)) {
            if (!labbus_parse_u64(line + 3, &next) ||
                (int64_t)next <= link->boundary) {
                labbus_link_fatal(link, "the hub sent '%s' at boundary %"
                                  PRId64 " ns", line, now);
            }
            link->boundaries++;
            link->boundary = next;
            timer_mod_ns(link->boundary_timer, next);
            return;
        }
        labbus_dispatch(link, line);
    }
}

/*
 * A real-time link's socket has data: every whole line is applied at once.
 * This runs in the main loop with the big lock held, like the card's
 * timers and register accesses, so it needs no lock of its own. The link
 * never waits for the hub here: nothing it does depends on an answer, and
 * a real-time machine could not stand still for one anyway.
 */
static void labbus_link_readable(void *opaque)
{
    LabBusLink *link = opaque;
    const char *why = NULL;

    for (;;) {
        char *line = labbus_buffered_line(link, &why);
        ssize_t count;

        if (line) {
            labbus_dispatch(link, line);
            continue;
        }
        if (why) {
            labbus_link_fatal(link, "%s", why);
        }
        count = recv(link->fd, link->input + link->input_length,
                     sizeof(link->input) - link->input_length, MSG_DONTWAIT);
        if (count > 0) {
            link->input_length += count;
        } else if (count == 0) {
            labbus_link_fatal(link, "the hub closed the connection");
        } else if (errno == EAGAIN || errno == EWOULDBLOCK) {
            return;
        } else if (errno != EINTR) {
            labbus_link_fatal(link, "reading from the hub failed (%s)",
                              strerror(errno));
        }
    }
}

/*
 * The time word of a message to the hub: the exact emulated time, or "-"
 * from a real-time link, whose clock follows the host and means nothing to
 * the hub (such a message counts from the next boundary the hub reaches).
 */
const char *labbus_link_time(LabBusLink *link, int64_t now, char *buffer,
                             size_t size)
{
    if (link->realtime) {
        return "-";
    }
    snprintf(buffer, size, "%" PRId64, now);
    return buffer;
}

/*
 * Attaches one port to the named bus; called by a device at realize.
 * Returns the port number, or -1 with errp set.
 */
int labbus_link_attach(LabBusLink *link, const char *bus, const char *label,
                       LabBusEventFn event, void *opaque, Error **errp)
{
    unsigned port = link->port_count;
    const char *why = NULL;
    char *line;

    if (port >= LABBUS_MAX_PORTS) {
        error_setg(errp, "labbus-link %s: no more than %d ports per board",
                   link->name, LABBUS_MAX_PORTS);
        return -1;
    }
    link->ports[port].bus = g_strdup(bus);
    link->ports[port].event = event;
    link->ports[port].opaque = opaque;
    link->port_count++;
    labbus_link_send(link, "ATTACH %u %s %s", port, bus, label);
    line = labbus_read_line(link, &why);
    if (!line) {
        error_setg(errp, "labbus-link %s: attaching to bus %s: %s",
                   link->name, bus, why);
        return -1;
    }
    if (!strncmp(line, "ATTACHED ", 9)) {
        return port;
    }
    if (!strncmp(line, "REFUSED ", 8)) {
        /* "REFUSED <port> <reason...>": the reason follows the number. */
        const char *reason = strchr(line + 8, ' ');

        error_setg(errp, "labbus-link %s: the hub refused bus %s: %s",
                   link->name, bus, reason ? reason + 1 : line + 8);
        return -1;
    }
    error_setg(errp, "labbus-link %s: the hub answered ATTACH with '%s'",
               link->name, line);
    return -1;
}

/*
 * Connects to the hub and greets it; the first quantum boundary is armed.
 * Called by the card at realize, so the socket is open before the machine
 * runs (a chardev would not do: the main loop stands still during a hold).
 */
static void labbus_link_connect(LabBusLink *link, Error **errp)
{
    struct sockaddr_un address = { .sun_family = AF_UNIX };
    const char *why = NULL;
    char *argv[LABBUS_MAX_WORDS];
    char *line;
    int argc;
    uint64_t version;

    if (!link->path || !*link->path) {
        error_setg(errp, "labbus-link: path=<hub socket> is required");
        return;
    }
    if (strlen(link->path) >= sizeof(address.sun_path)) {
        error_setg(errp, "labbus-link: the socket path %s is too long",
                   link->path);
        return;
    }
    if (!link->name || !*link->name) {
        g_free(link->name);
        link->name = g_strdup_printf("board%d", (int)getpid());
    }
    if (strchr(link->name, ' ') || strchr(link->name, '.') ||
        strlen(link->name) > 32) {
        error_setg(errp, "labbus-link: the name '%s' must be one word of at "
                   "most 32 characters without dots", link->name);
        return;
    }
    if (link->timeout_s == 0) {
        error_setg(errp, "labbus-link: hub-timeout must be at least 1 s");
        return;
    }
    if (!icount_enabled() && !link->realtime) {
        warn_report("labbus-link %s: without -icount the board's emulated "
                    "time follows the host, so bus timing is not exact "
                    "(hub-realtime=on joins such a machine as a real-time "
                    "participant)", link->name);
    }

    link->fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (link->fd < 0) {
        error_setg_errno(errp, errno, "labbus-link: socket");
        return;
    }
    pstrcpy(address.sun_path, sizeof(address.sun_path), link->path);
    if (connect(link->fd, (struct sockaddr *)&address, sizeof(address)) < 0) {
        error_setg_errno(errp, errno, "labbus-link %s: cannot connect to the "
                         "lab bus hub at %s", link->name, link->path);
        close(link->fd);
        link->fd = -1;
        return;
    }
    labbus_link_send(link, "HELLO %d %s %s", LABBUS_PROTOCOL_VERSION,
                     link->name, link->realtime ? "realtime" : "emulated");
    line = labbus_read_line(link, &why);
    if (!line) {
        error_setg(errp, "labbus-link %s: no WELCOME from the hub: %s",
                   link->name, why);
        return;
    }
    argc = labbus_split(line, argv);
    if (argc >= 2 && !strcmp(argv[0], "ERROR")) {
        error_setg(errp, "labbus-link %s: the hub refused the board: %s",
                   link->name, line + strlen(argv[0]) + 1);
        return;
    }
    if (argc < 4 || strcmp(argv[0], "WELCOME") ||
        !labbus_parse_u64(argv[1], &version) ||
        version != LABBUS_PROTOCOL_VERSION ||
        !labbus_parse_u64(argv[2], &link->quantum_ns) ||
        link->quantum_ns == 0) {
        error_setg(errp, "labbus-link %s: the hub's greeting '%s' is not "
                   "protocol version %d", link->name, argv[0],
                   LABBUS_PROTOCOL_VERSION);
        return;
    }
    if (link->realtime) {
        /*
         * Events arrive whenever the hub passes a boundary; the main loop
         * hands them over as they come.
         */
        qemu_set_fd_handler(link->fd, labbus_link_readable, NULL, link);
        return;
    }
    /*
     * Boundaries count from QEMU's start: realize runs at emulated time 0,
     * so the first is one quantum in.
     */
    link->boundary_timer = timer_new_ns(QEMU_CLOCK_VIRTUAL,
                                        labbus_link_boundary, link);
    link->boundary = qemu_clock_get_ns(QEMU_CLOCK_VIRTUAL) + link->quantum_ns;
    timer_mod_ns(link->boundary_timer, link->boundary);
}

static void labbus_link_instance_init(Object *obj)
{
    LabBusLink *link = LABBUS_LINK(obj);

    link->fd = -1;
    object_property_add_uint64_ptr(obj, "boundaries", &link->boundaries,
                                   OBJ_PROP_FLAG_READ);
    object_property_add_uint64_ptr(obj, "late-boundaries",
                                   &link->late_boundaries, OBJ_PROP_FLAG_READ);
}

static void labbus_link_instance_finalize(Object *obj)
{
    LabBusLink *link = LABBUS_LINK(obj);
    unsigned i;

    if (link->boundary_timer) {
        timer_free(link->boundary_timer);
    }
    if (link->fd >= 0) {
        if (link->realtime) {
            qemu_set_fd_handler(link->fd, NULL, NULL, NULL);
        }
        close(link->fd);
    }
    for (i = 0; i < link->port_count; i++) {
        g_free(link->ports[i].bus);
    }
    g_free(link->path);
    g_free(link->name);
}

static const TypeInfo labbus_link_info = {
    .name = TYPE_LABBUS_LINK,
    .parent = TYPE_OBJECT,
    .instance_size = sizeof(LabBusLink),
    .instance_init = labbus_link_instance_init,
    .instance_finalize = labbus_link_instance_finalize,
};

/* The board's one link, made by the first device that names a hub. */
static LabBusLink *labbus_board_link;

LabBusLink *labbus_board_link_join(Object *owner, const LabBusLinkConfig *config,
                                   Error **errp)
{
    LabBusLink *link;

    if (labbus_board_link) {
        link = labbus_board_link;
        /*
         * A board holds one place in the lock-step, so every device on it
         * must name the same hub, under the same name and kind.
         */
        if (g_strcmp0(link->path, config->path) ||
            (config->name && *config->name &&
             g_strcmp0(link->name, config->name)) ||
            link->realtime != config->realtime) {
            error_setg(errp, "labbus-link: this board is joined to the hub at "
                       "%s as %s already; every device of a board must name "
                       "the same hub, hub-name and hub-realtime", link->path,
                       link->name);
            return NULL;
        }
        return link;
    }
    link = LABBUS_LINK(object_new(TYPE_LABBUS_LINK));
    link->path = g_strdup(config->path);
    link->name = g_strdup(config->name);
    link->timeout_s = config->timeout_s;
    link->realtime = config->realtime;
    object_property_add_child(owner, "link", OBJECT(link));
    object_unref(OBJECT(link));
    labbus_link_connect(link, errp);
    if (*errp) {
        object_unparent(OBJECT(link));
        return NULL;
    }
    labbus_board_link = link;
    return link;
}

bool labbus_link_realtime(LabBusLink *link)
{
    return link->realtime;
}

void labbus_board_link_forget(LabBusLink *link)
{
    if (link && labbus_board_link == link) {
        labbus_board_link = NULL;
    }
}

static void labbus_link_register_types(void)
{
    type_register_static(&labbus_link_info);
}

type_init(labbus_link_register_types)
