/*
 * DCOS multi-function ISA I/O board ("isa-mfio").
 *
 * Eight 12-bit analog inputs behind programmable amplifiers (gain 1, 10,
 * 100, 1000), eight 12-bit analog outputs, 16 digital inputs and 16 digital
 * outputs, a conversion-complete interrupt. The register map, the scaling
 * and the plant protocol are specified in docs/iobus/mfio-register-map.md
 * (version 1.0); this file implements exactly that page.
 *
 * The board is wired either in loopback (DAC n drives ADC n, DO drives DI)
 * or to a plant simulator over a socket chardev, with which it exchanges one
 * SAMPLE/INPUT line pair at every conversion start (and, with plant-on-write,
 * at every DAC write). Noise is deterministic
 * from a seed, and faults (a stuck DI bit, a dead ADC channel, a missing
 * interrupt) are injected through properties.
 *
 * A "logic analyzer" on the digital outputs is optional: with the chardev
 * property do-trace set, every change of DO is written to that chardev as
 * one "DO <emulated ns> <hex>" line, so a test can measure the waveforms an
 * application produces in emulated time without asking the firmware.
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
#include "qemu/ctype.h"
#include "qemu/cutils.h"
#include "qemu/error-report.h"
#include "qemu/main-loop.h"
#include "qemu/module.h"
#include "qemu/timer.h"
#include "qapi/error.h"
#include "hw/irq.h"
#include "hw/isa/isa.h"
#include "hw/qdev-properties.h"
#include "hw/qdev-properties-system.h"
#include "chardev/char-fe.h"
#include "chardev/char-socket.h"
#include "io/channel-socket.h"
#include "qom/object.h"

#include "labbus_link.h"

#include <math.h>
#include <poll.h>
#include <sys/socket.h>

#define TYPE_ISA_MFIO "isa-mfio"
OBJECT_DECLARE_SIMPLE_TYPE(IsaMfioState, ISA_MFIO)

/* The decoded window of I/O ports. */
#define MFIO_WINDOW_SIZE 0x40

/* Register offsets. */
#define MFIO_ID         0x00
#define MFIO_REVISION   0x02
#define MFIO_CONTROL    0x04
#define MFIO_STATUS     0x06
#define MFIO_ADC_START  0x08
#define MFIO_ADC_DATA   0x0a
#define MFIO_GAIN       0x0c
#define MFIO_IRQ_ACK    0x0e
#define MFIO_DI         0x10
#define MFIO_DO         0x12
#define MFIO_DAC0       0x20
#define MFIO_DAC7       0x2e

#define MFIO_ID_VALUE       0x4d46
#define MFIO_REVISION_VALUE 0x0100

#define MFIO_CONTROL_IRQ_ENABLE 0x0001
#define MFIO_CONTROL_RESET      0x8000

#define MFIO_STATUS_BUSY        0x0001
#define MFIO_STATUS_DONE        0x0002
#define MFIO_STATUS_OVERRANGE   0x0004
#define MFIO_STATUS_IRQ_PENDING 0x0008

#define MFIO_ADC_DATA_OVERRANGE 0x8000

#define MFIO_CHANNELS   8
#define MFIO_CODE_MAX   4095
#define MFIO_CODE_ZERO  0x800

/* The longest plant line the model accepts, newline included. */
#define MFIO_PLANT_LINE_MAX 512
/* How long the model waits for the plant's reply, in host milliseconds. */
#define MFIO_PLANT_TIMEOUT_MS 1000
/* The longest DO trace line: "DO ", 20 digits of time, " ", 4 hex, "\n". */
#define MFIO_DO_TRACE_LINE_MAX 48

struct IsaMfioState {
    ISADevice parent_obj;

    MemoryRegion io;
    qemu_irq irq;
    QEMUTimer *conversion_timer;
    CharBackend plant;
    /* The logic analyzer on DO: a chardev (normally a file), or none. */
    CharBackend do_trace;

    /* Properties: the board's switches and jumpers. */
    uint32_t iobase;
    uint32_t irq_line;
    /* Properties: the world the board is wired to, and injected faults. */
    char *wiring;
    char *noise_lsb_text;
    uint64_t noise_seed;
    uint64_t conversion_ns;
    int32_t stuck_di_bit;
    uint32_t stuck_di_value;
    int32_t dead_adc_channel;
    bool no_irq;
    /* wiring=plant: a DAC write is an exchange too (plant-on-write). */
    bool plant_on_write;

    /* Derived from the properties at realize time. */
    bool plant_wiring;
    double noise_lsb;

    /* Registers. */
    uint16_t control;
    uint16_t status;
    uint16_t adc_data;
    uint16_t gain;
    uint16_t digital_out;
    uint16_t dac[MFIO_CHANNELS];

    /* The conversion that is running: its result is latched at the end. */
    uint16_t pending_data;

    /* The deterministic noise generator (xorshift64*). */
    uint64_t noise_state;

    /* The inputs the plant gave last (wiring=plant). */
    double plant_volts[MFIO_CHANNELS];
    uint16_t plant_digital_in;
    char plant_line[MFIO_PLANT_LINE_MAX];
    size_t plant_line_length;
    /* Exchanges that got no usable reply; readable as "plant-missed". */
    uint32_t plant_missed;
    /* DO trace lines the chardev did not take; readable as "do-trace-errors". */
    uint32_t do_trace_errors;
};

static const unsigned mfio_gains[4] = { 1, 10, 100, 1000 };

/*
 * The noise generator: xorshift64* for uniform numbers and the Box-Muller
 * transform for a standard normal one. It never touches host randomness, so
 * the same seed gives the same sequence of codes.
 */
static void mfio_noise_seed(IsaMfioState *s)
{
    /* xorshift has one fixed point, zero; seed 0 is mapped away from it. */
    s->noise_state = s->noise_seed ? s->noise_seed : 0x9e3779b97f4a7c15ULL;
}

static double mfio_noise_uniform(IsaMfioState *s)
{
    uint64_t x = s->noise_state;

    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    s->noise_state = x;
    x *= 0x2545f4914f6cdd1dULL;
    /* 53 random bits give a number in (0, 1], never 0, so log() is finite. */
    return ((x >> 11) + 1) * (1.0 / 9007199254740992.0);
}

static double mfio_noise_normal(IsaMfioState *s)
{
    double u1 = mfio_noise_uniform(s);
    double u2 = mfio_noise_uniform(s);

    return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}

static double mfio_dac_volts(uint16_t code)
{
    return ((double)code - 2048.0) * 20.0 / 4096.0;
}

static uint16_t mfio_digital_in(IsaMfioState *s)
{
    uint16_t value = s->plant_wiring ? s->plant_digital_in : s->digital_out;

    if (s->stuck_di_bit >= 0) {
        uint16_t bit = 1u << s->stuck_di_bit;

        value = s->stuck_di_value ? (value | bit) : (value & ~bit);
    }
    return value;
}

/*
 * The logic analyzer on DO: one line "DO <emulated ns> <DO as 4 hex
 * digits>" per change of the outputs. The time is the virtual clock, which
 * under -icount is the exact emulated time of the guest's OUT instruction,
 * so periods and duty cycles measured from the trace do not depend on how
 * fast the host runs. Tracing must never stop or slow the board: a line the
 * chardev does not take (a full disk, a closed pipe) is counted and
 * dropped, and only the first misses are reported.
 */
static void mfio_trace_digital_out(IsaMfioState *s)
{
    char line[MFIO_DO_TRACE_LINE_MAX];
    int length;

    if (!qemu_chr_fe_backend_connected(&s->do_trace)) {
        return;
    }
    length = snprintf(line, sizeof(line), "DO %" PRId64 " %04x\n",
                      qemu_clock_get_ns(QEMU_CLOCK_VIRTUAL), s->digital_out);
    if (length <= 0 || length >= (int)sizeof(line) ||
        qemu_chr_fe_write_all(&s->do_trace, (const uint8_t *)line,
                              length) != length) {
        s->do_trace_errors++;
        if (s->do_trace_errors <= 10 || s->do_trace_errors % 1000 == 0) {
            warn_report("isa-mfio: could not write a DO trace line (%" PRIu32
                        " lost so far); the trace has a gap here",
                        s->do_trace_errors);
        }
    }
}

/*
 * Every path that can change DO goes through here, so the trace sees each
 * edge once: a write of the value DO already has is no edge and gives no
 * line, as on a real analyzer.
 */
static void mfio_set_digital_out(IsaMfioState *s, uint16_t value)
{
    if (value == s->digital_out) {
        return;
    }
    s->digital_out = value;
    mfio_trace_digital_out(s);
}

static void mfio_update_irq(IsaMfioState *s)
{
    if (s->status & MFIO_STATUS_IRQ_PENDING) {
        qemu_irq_raise(s->irq);
    } else {
        qemu_irq_lower(s->irq);
    }
}

/*
 * The plant exchange. The plant chardev must be a plain socket; the model
 * reads its file descriptor itself with poll(), so that a silent plant
 * costs at most MFIO_PLANT_TIMEOUT_MS of host time. No front-end handlers
 * are installed, so the chardev layer never reads from the socket itself.
 */
static int mfio_plant_fd(IsaMfioState *s)
{
    Chardev *chr = qemu_chr_fe_get_driver(&s->plant);
    SocketChardev *socket_chr;

    if (!chr || !object_dynamic_cast(OBJECT(chr), TYPE_CHARDEV_SOCKET)) {
        return -1;
    }
    socket_chr = SOCKET_CHARDEV(chr);
    if (socket_chr->state != TCP_CHARDEV_STATE_CONNECTED || !socket_chr->sioc ||
        socket_chr->ioc != QIO_CHANNEL(socket_chr->sioc)) {
        return -1;
    }
    return socket_chr->sioc->fd;
}

/*
 * Reads one line into s->plant_line (without the newline). Returns false on
 * time-out, on a closed connection and on a line that is too long.
 */
static bool mfio_plant_receive_line(IsaMfioState *s, int fd,
                                    int64_t deadline_ms)
{
    for (;;) {
        char *newline = memchr(s->plant_line, '\n', s->plant_line_length);
        ssize_t count;

        if (newline) {
            *newline = '\0';
            return true;
        }
        if (s->plant_line_length >= sizeof(s->plant_line) - 1) {
            s->plant_line_length = 0;
            return false;
        }
        count = recv(fd, s->plant_line + s->plant_line_length,
                     sizeof(s->plant_line) - 1 - s->plant_line_length,
                     MSG_DONTWAIT);
        if (count > 0) {
            s->plant_line_length += count;
        } else if (count < 0 && errno == EINTR) {
            continue;
        } else if (count < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            struct pollfd pfd = { .fd = fd, .events = POLLIN };
            int64_t remaining = labbus_remaining_ms(deadline_ms);

            if (remaining == 0 || poll(&pfd, 1, remaining) <= 0) {
                return false;
            }
        } else {
            return false;
        }
    }
}

/* Discards whatever the plant sent outside an exchange, e.g. a late reply. */
static void mfio_plant_drain(IsaMfioState *s, int fd)
{
    char scratch[256];

    s->plant_line_length = 0;
    while (recv(fd, scratch, sizeof(scratch), MSG_DONTWAIT) > 0) {
        /* Nothing is kept. */
    }
}

/* Parses "INPUT <8 volts> <DI hex>"; the state changes only if all parse. */
static bool mfio_plant_parse_input(IsaMfioState *s, const char *line)
{
    double volts[MFIO_CHANNELS];
    uint64_t digital_in;
    const char *cursor = line;
    int i;

    if (strncmp(cursor, "INPUT", 5) != 0 || !qemu_isspace(cursor[5])) {
        return false;
    }
    cursor += 5;
    for (i = 0; i < MFIO_CHANNELS; i++) {
        if (qemu_strtod_finite(cursor, &cursor, &volts[i]) != 0) {
            return false;
        }
    }
    while (qemu_isspace(*cursor)) {
        cursor++;
    }
    if (qemu_strtou64(cursor, &cursor, 16, &digital_in) != 0 ||
        digital_in > 0xffff) {
        return false;
    }
    while (*cursor == ' ' || *cursor == '\t' || *cursor == '\r') {
        cursor++;
    }
    if (*cursor != '\0') {
        return false;
    }
    memcpy(s->plant_volts, volts, sizeof(volts));
    s->plant_digital_in = digital_in;
    return true;
}

static void mfio_plant_missed(IsaMfioState *s, const char *why)
{
    s->plant_missed++;
    /* The first misses are reported one by one, later ones now and then. */
    if (s->plant_missed <= 10 || s->plant_missed % 100 == 0) {
        warn_report("isa-mfio: plant exchange %" PRIu32 " missed (%s); "
                    "keeping the previous inputs", s->plant_missed, why);
    }
}

/*
 * One lock-step exchange at a conversion start: SAMPLE out, INPUT back.
 * Emulated time stands still meanwhile, so the loop is deterministic.
 */
static void mfio_plant_exchange(IsaMfioState *s)
{
    int64_t deadline_ms = qemu_clock_get_ms(QEMU_CLOCK_REALTIME) +
                          MFIO_PLANT_TIMEOUT_MS;
    GString *sample = g_string_new("SAMPLE");
    int fd = mfio_plant_fd(s);
    int i;

    g_string_append_printf(sample, " %" PRId64,
                           qemu_clock_get_ns(QEMU_CLOCK_VIRTUAL));
    for (i = 0; i < MFIO_CHANNELS; i++) {
        g_string_append_printf(sample, " %.6f", mfio_dac_volts(s->dac[i]));
    }
    g_string_append_printf(sample, " %04x\n", s->digital_out);

    if (fd < 0) {
        mfio_plant_missed(s, "no plant connected");
    } else {
        mfio_plant_drain(s, fd);
        if (!labbus_send_all(fd, sample->str, strlen(sample->str), deadline_ms)) {
            mfio_plant_missed(s, "could not send SAMPLE");
        } else if (!mfio_plant_receive_line(s, fd, deadline_ms)) {
            mfio_plant_missed(s, "no INPUT line within 1 s");
        } else if (!mfio_plant_parse_input(s, s->plant_line)) {
            mfio_plant_missed(s, "malformed INPUT line");
        }
    }
    s->plant_line_length = 0;
    g_string_free(sample, true);
}

/*
 * Samples channel at its current gain: the result is computed at the start
 * of the conversion (sample and hold) and latched when the conversion time
 * has passed.
 */
static uint16_t mfio_convert(IsaMfioState *s, unsigned channel)
{
    unsigned gain = mfio_gains[(s->gain >> (2 * channel)) & 3];
    double volts;
    double exact;
    double rounded;
    uint16_t code;
    bool overrange = false;

    if (s->plant_wiring) {
        mfio_plant_exchange(s);
        volts = s->plant_volts[channel];
    } else {
        volts = mfio_dac_volts(s->dac[channel]);
    }
    if ((int32_t)channel == s->dead_adc_channel) {
        return MFIO_CODE_ZERO | (channel << 12);
    }
    exact = (volts * gain + 10.0) * 4096.0 / 20.0;
    if (s->noise_lsb > 0.0) {
        exact += s->noise_lsb * mfio_noise_normal(s);
    }
    rounded = round(exact);
    if (rounded < 0.0) {
        code = 0;
        overrange = true;
    } else if (rounded > MFIO_CODE_MAX) {
        code = MFIO_CODE_MAX;
        overrange = true;
    } else {
        code = (uint16_t)rounded;
    }
    return code | (channel << 12) | (overrange ? MFIO_ADC_DATA_OVERRANGE : 0);
}

static void mfio_conversion_done(void *opaque)
{
    IsaMfioState *s = opaque;

    s->adc_data = s->pending_data;
    s->status &= ~(MFIO_STATUS_BUSY | MFIO_STATUS_OVERRANGE);
    s->status |= MFIO_STATUS_DONE;
    if (s->adc_data & MFIO_ADC_DATA_OVERRANGE) {
        s->status |= MFIO_STATUS_OVERRANGE;
    }
    if ((s->control & MFIO_CONTROL_IRQ_ENABLE) && !s->no_irq) {
        s->status |= MFIO_STATUS_IRQ_PENDING;
    }
    mfio_update_irq(s);
}

static void mfio_start_conversion(IsaMfioState *s, unsigned channel)
{
    if (s->status & MFIO_STATUS_BUSY) {
        return;
    }
    s->status |= MFIO_STATUS_BUSY;
    s->pending_data = mfio_convert(s, channel);
    timer_mod(s->conversion_timer,
              qemu_clock_get_ns(QEMU_CLOCK_VIRTUAL) + s->conversion_ns);
}

/*
 * Every register to its reset value; the wiring and the faults stay. A DO
 * that was not 0 falls to 0, which the trace records as an edge.
 */
static void mfio_reset_registers(IsaMfioState *s)
{
    int i;

    timer_del(s->conversion_timer);
    s->control = 0;
    s->status = 0;
    s->adc_data = 0;
    s->pending_data = 0;
    s->gain = 0;
    mfio_set_digital_out(s, 0);
    for (i = 0; i < MFIO_CHANNELS; i++) {
        s->dac[i] = MFIO_CODE_ZERO;
    }
    mfio_noise_seed(s);
    mfio_update_irq(s);
}

static uint64_t mfio_read(void *opaque, hwaddr addr, unsigned size)
{
    IsaMfioState *s = opaque;

    /*
     * Only 16-bit accesses at even offsets are decoded; any other read sees
     * a floating bus, all ones.
     */
    if (size != 2 || (addr & 1)) {
        return size == 4 ? 0xffffffffu : (size == 2 ? 0xffff : 0xff);
    }
    switch (addr) {
    case MFIO_ID:
        return MFIO_ID_VALUE;
    case MFIO_REVISION:
        return MFIO_REVISION_VALUE;
    case MFIO_CONTROL:
        return s->control;
    case MFIO_STATUS:
        return s->status;
    case MFIO_ADC_DATA:
        return s->adc_data;
    case MFIO_GAIN:
        return s->gain;
    case MFIO_DI:
        return mfio_digital_in(s);
    case MFIO_DO:
        return s->digital_out;
    case MFIO_DAC0 ... MFIO_DAC7:
        return s->dac[(addr - MFIO_DAC0) / 2];
    default:
        /* Write-only and unused offsets read as zero. */
        return 0;
    }
}

static void mfio_write(void *opaque, hwaddr addr, uint64_t value,
                       unsigned size)
{
    IsaMfioState *s = opaque;

    if (size != 2 || (addr & 1)) {
        return;
    }
    switch (addr) {
    case MFIO_CONTROL:
        if (value & MFIO_CONTROL_RESET) {
            mfio_reset_registers(s);
        } else {
            s->control = value & MFIO_CONTROL_IRQ_ENABLE;
        }
        break;
    case MFIO_ADC_START:
        mfio_start_conversion(s, value & 7);
        break;
    case MFIO_GAIN:
        s->gain = value;
        break;
    case MFIO_IRQ_ACK:
        if (value & 1) {
            s->status &= ~(MFIO_STATUS_DONE | MFIO_STATUS_IRQ_PENDING);
            mfio_update_irq(s);
        }
        break;
    case MFIO_DO:
        mfio_set_digital_out(s, value);
        break;
    case MFIO_DAC0 ... MFIO_DAC7:
        s->dac[(addr - MFIO_DAC0) / 2] = value & MFIO_CODE_MAX;
        /*
         * The plant otherwise learns the DACs at the next conversion, which
         * a board that only drives outputs never starts.
         */
        if (s->plant_wiring && s->plant_on_write) {
            mfio_plant_exchange(s);
        }
        break;
    default:
        /* Read-only and unused offsets ignore writes. */
        break;
    }
}

static const MemoryRegionOps mfio_ops = {
    .read = mfio_read,
    .write = mfio_write,
    /*
     * Every access reaches the handlers, which decode only 16-bit ones at
     * even offsets: 8-bit, 32-bit and odd 16-bit reads see all ones, and
     * such writes are ignored.
     */
    .valid.min_access_size = 1,
    .valid.max_access_size = 4,
    .valid.unaligned = true,
    .impl.min_access_size = 1,
    .impl.max_access_size = 4,
    .impl.unaligned = true,
    .endianness = DEVICE_LITTLE_ENDIAN,
};

static void mfio_realize(DeviceState *dev, Error **errp)
{
    ISADevice *isa = ISA_DEVICE(dev);
    IsaMfioState *s = ISA_MFIO(dev);
    const char *end;

    if (s->iobase > 0xffff - MFIO_WINDOW_SIZE + 1 ||
        (s->iobase & (MFIO_WINDOW_SIZE - 1))) {
        error_setg(errp, "isa-mfio: iobase 0x%" PRIx32 " must be a multiple "
                   "of 0x%x below 0x10000", s->iobase, MFIO_WINDOW_SIZE);
        return;
    }
    if (s->irq_line >= ISA_NUM_IRQS) {
        error_setg(errp, "isa-mfio: irq %" PRIu32 " is not an ISA line "
                   "(0..15)", s->irq_line);
        return;
    }
    if (!s->wiring || !strcmp(s->wiring, "loopback")) {
        s->plant_wiring = false;
    } else if (!strcmp(s->wiring, "plant")) {
        s->plant_wiring = true;
    } else {
        error_setg(errp, "isa-mfio: wiring '%s' is neither 'loopback' nor "
                   "'plant'", s->wiring);
        return;
    }
    if (s->plant_wiring && !qemu_chr_fe_backend_connected(&s->plant)) {
        error_setg(errp, "isa-mfio: wiring=plant needs a plant chardev "
                   "(plant=<chardev id>)");
        return;
    }
    if (s->plant_wiring &&
        !object_dynamic_cast(OBJECT(qemu_chr_fe_get_driver(&s->plant)),
                             TYPE_CHARDEV_SOCKET)) {
        error_setg(errp, "isa-mfio: the plant chardev must be a socket");
        return;
    }
    s->noise_lsb = 0.0;
    if (s->noise_lsb_text &&
        (qemu_strtod_finite(s->noise_lsb_text, &end, &s->noise_lsb) != 0 ||
         *end != '\0' || s->noise_lsb < 0.0)) {
        error_setg(errp, "isa-mfio: noise-lsb '%s' is not a number >= 0",
                   s->noise_lsb_text);
        return;
    }
    if (s->stuck_di_bit < -1 || s->stuck_di_bit > 15) {
        error_setg(errp, "isa-mfio: stuck-di-bit %" PRId32 " is not -1 (none) "
                   "or a DI bit 0..15", s->stuck_di_bit);
        return;
    }
    if (s->stuck_di_value > 1) {
        error_setg(errp, "isa-mfio: stuck-di-value must be 0 or 1");
        return;
    }
    if (s->dead_adc_channel < -1 || s->dead_adc_channel >= MFIO_CHANNELS) {
        error_setg(errp, "isa-mfio: dead-adc-channel %" PRId32 " is not -1 "
                   "(none) or a channel 0..7", s->dead_adc_channel);
        return;
    }

    memory_region_init_io(&s->io, OBJECT(dev), &mfio_ops, s, TYPE_ISA_MFIO,
                          MFIO_WINDOW_SIZE);
    isa_register_ioport(isa, &s->io, s->iobase);
    s->irq = isa_get_irq(isa, s->irq_line);
    s->conversion_timer = timer_new_ns(QEMU_CLOCK_VIRTUAL,
                                       mfio_conversion_done, s);
    object_property_add_uint32_ptr(OBJECT(dev), "plant-missed",
                                   &s->plant_missed, OBJ_PROP_FLAG_READ);
    object_property_add_uint32_ptr(OBJECT(dev), "do-trace-errors",
                                   &s->do_trace_errors, OBJ_PROP_FLAG_READ);
}

static void mfio_unrealize(DeviceState *dev)
{
    IsaMfioState *s = ISA_MFIO(dev);

    timer_free(s->conversion_timer);
    s->conversion_timer = NULL;
}

static void mfio_reset(DeviceState *dev)
{
    IsaMfioState *s = ISA_MFIO(dev);
    int i;

    /*
     * DO is cleared here without an edge, because the line below states the
     * level anyway: a system reset gives one line, never two.
     */
    s->digital_out = 0;
    mfio_reset_registers(s);
    for (i = 0; i < MFIO_CHANNELS; i++) {
        s->plant_volts[i] = 0.0;
    }
    s->plant_digital_in = 0;
    s->plant_line_length = 0;
    /*
     * The trace starts from a known level: at power-on, and again after
     * every system reset, one line states DO whether or not it changed.
     * Realize writes nothing, because the power-on reset follows it at the
     * same instant and would repeat the line.
     */
    mfio_trace_digital_out(s);
}

static Property mfio_properties[] = {
    DEFINE_PROP_UINT32("iobase", IsaMfioState, iobase, 0x300),
    DEFINE_PROP_UINT32("irq", IsaMfioState, irq_line, 5),
    DEFINE_PROP_STRING("wiring", IsaMfioState, wiring),
    DEFINE_PROP_CHR("plant", IsaMfioState, plant),
    DEFINE_PROP_CHR("do-trace", IsaMfioState, do_trace),
    DEFINE_PROP_STRING("noise-lsb", IsaMfioState, noise_lsb_text),
    DEFINE_PROP_UINT64("noise-seed", IsaMfioState, noise_seed, 1),
    DEFINE_PROP_UINT64("conversion-ns", IsaMfioState, conversion_ns, 20000),
    DEFINE_PROP_INT32("stuck-di-bit", IsaMfioState, stuck_di_bit, -1),
    DEFINE_PROP_UINT32("stuck-di-value", IsaMfioState, stuck_di_value, 0),
    DEFINE_PROP_INT32("dead-adc-channel", IsaMfioState, dead_adc_channel, -1),
    DEFINE_PROP_BOOL("no-irq", IsaMfioState, no_irq, false),
    DEFINE_PROP_BOOL("plant-on-write", IsaMfioState, plant_on_write, false),
    DEFINE_PROP_END_OF_LIST(),
};

static void mfio_class_init(ObjectClass *klass, void *data)
{
    DeviceClass *dc = DEVICE_CLASS(klass);

    dc->desc = "DCOS multi-function I/O board (8 AI, 8 AO, 16 DI, 16 DO)";
    dc->realize = mfio_realize;
    dc->unrealize = mfio_unrealize;
    dc->reset = mfio_reset;
    device_class_set_props(dc, mfio_properties);
    object_class_property_set_description(klass, "iobase",
        "base I/O port of the 64-byte window (DIP switches)");
    object_class_property_set_description(klass, "irq",
        "ISA interrupt line (jumper)");
    object_class_property_set_description(klass, "wiring",
        "loopback (DAC n to ADC n, DO to DI, the default) or plant");
    object_class_property_set_description(klass, "plant",
        "socket chardev of the plant simulator, for wiring=plant");
    object_class_property_set_description(klass, "do-trace",
        "chardev (normally a file) receiving 'DO <ns> <hex>' per DO change");
    object_class_property_set_description(klass, "noise-lsb",
        "standard deviation of the input noise in LSB (default 0)");
    object_class_property_set_description(klass, "noise-seed",
        "seed of the deterministic noise generator");
    object_class_property_set_description(klass, "conversion-ns",
        "conversion time in emulated nanoseconds");
    object_class_property_set_description(klass, "stuck-di-bit",
        "fault: this DI bit reads stuck at stuck-di-value (-1: none)");
    object_class_property_set_description(klass, "stuck-di-value",
        "fault: the level (0 or 1) of the stuck DI bit");
    object_class_property_set_description(klass, "dead-adc-channel",
        "fault: this ADC channel always converts 0x800 (-1: none)");
    object_class_property_set_description(klass, "no-irq",
        "fault: conversions complete but never raise the interrupt");
    object_class_property_set_description(klass, "plant-on-write",
        "with wiring=plant, a DAC write is an exchange with the plant too");
    set_bit(DEVICE_CATEGORY_MISC, dc->categories);
}

static const TypeInfo mfio_info = {
    .name          = TYPE_ISA_MFIO,
    .parent        = TYPE_ISA_DEVICE,
    .instance_size = sizeof(IsaMfioState),
    .class_init    = mfio_class_init,
};

static void mfio_register_types(void)
{
    type_register_static(&mfio_info);
}

type_init(mfio_register_types)
