/*
 * DCOS ISA RS-485 UART ("isa-rs485-uart"): a National Semiconductor PC16550D
 * whose serial line is the lab's RS-485 line, in emulated time.
 *
 * QEMU's own isa-serial hands a received byte to the guest as soon as its
 * back end has one, so the silences between characters that Modbus RTU
 * framing is built on (1.5 and 3.5 character times) do not exist on it, and
 * two talkers at once cannot garble each other. This model is the 16550 as
 * the DCOS firmware's driver (firmware/bsp_486 Uart16550) uses it, with
 * each character taking its exact time on the line:
 *
 *  - a character's length is start bit + 5-8 data bits + parity bit + 1,
 *    1.5 or 2 stop bits at the bit time the divisor latch gives with the PC's
 *    1.8432 MHz reference clock (16 clocks per bit);
 *  - the transmitter moves a byte from the holding register (or FIFO) to
 *    the shift register at once when it is idle, and the next one exactly
 *    when the character before it has ended, so THRE and TEMT follow the
 *    line's real timing;
 *  - on a lab line (properties hub, hub-name and line), each character the
 *    transmitter shifts out while the driver is enabled (MCR.RTS, the
 *    transceiver's DE, outside loopback) goes to the hub with its start
 *    time; driver enable changes go there too, since an enabled driver holds
 *    the line even between characters;
 *  - a character from the line reaches the receive FIFO (or RBR) at the
 *    emulated time its last stop bit ends, sampled in the middle of each
 *    of this receiver's bits, so one sent at another bit time or format
 *    arrives with wrong bits and the parity or framing error they give; one
 *    the hub says was garbled (two drivers at once) has a framing error;
 *  - the character time-out interrupt comes after four character times
 *    without a character received or read, as the datasheet gives it.
 *
 * The hub (tests_renode/dcoslab/canbus.py with the line model of
 * tests_renode/dcoslab/rs485.py) decides what each receiver hears; its
 * timing and collision model and the messages are in
 * docs/protocols/labbus.md, "The RS-485 line". The transceiver is the
 * usual half-duplex one with RE tied to /DE: a port does not hear its own
 * characters, nor anything else while its driver is enabled. The board's
 * link to the hub (labbus_link.c) is shared with the SJA1000 CAN card of
 * the same board. Without a line the UART is on a line with no other node:
 * what it sends goes nowhere, and loopback (MCR.LOOP) works alone.
 *
 * Register and bit names are the datasheet's: Texas Instruments (National
 * Semiconductor) PC16550D, "Universal Asynchronous Receiver/Transmitter with
 * FIFOs", SNLS378C; "DS 8.4" is its section 8.4, "Table II" its summary of
 * registers.
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
#include "qemu/host-utils.h"
#include "qemu/log.h"
#include "qemu/module.h"
#include "qemu/timer.h"
#include "qapi/error.h"
#include "qom/object.h"
#include "hw/irq.h"
#include "hw/isa/isa.h"
#include "hw/qdev-properties.h"

#include "labbus_link.h"

/* ======================================================================== */
/* PC16550D registers (Table II) and bits (DS 8.x)                          */
/* ======================================================================== */

/* Register offsets from the base port (Table II). */
#define UART_PORTS        8
#define UART_RBR          0      /* receiver buffer, read, DLAB 0 */
#define UART_THR          0      /* transmitter holding, write, DLAB 0 */
#define UART_DLL          0      /* divisor latch LSB, DLAB 1 */
#define UART_IER          1      /* interrupt enable, DLAB 0 */
#define UART_DLM          1      /* divisor latch MSB, DLAB 1 */
#define UART_IIR          2      /* interrupt identification, read */
#define UART_FCR          2      /* FIFO control, write */
#define UART_LCR          3      /* line control */
#define UART_MCR          4      /* modem control */
#define UART_LSR          5      /* line status */
#define UART_MSR          6      /* modem status */
#define UART_SCR          7      /* scratch */

/* IER (DS 8.7): the four interrupt sources; bits 7-4 are always 0. */
#define IER_ERBFI         0x01   /* received data available (and time-out) */
#define IER_ETBEI         0x02   /* transmitter holding register empty */
#define IER_ELSI          0x04   /* receiver line status */
#define IER_EDSSI         0x08   /* modem status */
#define IER_WRITABLE      0x0f

/* IIR (DS 8.6, Table IV): bit 0 set when nothing is pending. */
#define IIR_NO_INT        0x01
#define IIR_MODEM_STATUS  0x00   /* fourth priority */
#define IIR_THRE          0x02   /* third priority */
#define IIR_RX_DATA       0x04   /* second priority */
#define IIR_LINE_STATUS   0x06   /* highest priority */
#define IIR_CHAR_TIMEOUT  0x0c   /* second priority, FIFO mode */
#define IIR_FIFOS_ON      0xc0   /* bits 7-6 set when FCR0 is 1 */

/* FCR (DS 8.5). */
#define FCR_ENABLE        0x01   /* both FIFOs on */
#define FCR_RX_RESET      0x02   /* clear the receiver FIFO */
#define FCR_TX_RESET      0x04   /* clear the transmitter FIFO */
#define FCR_TRIGGER_SHIFT 6      /* bits 7-6: the receiver trigger level */

/* LCR (DS 8.1). */
#define LCR_WLS_MASK      0x03   /* word length - 5 */
#define LCR_STB           0x04   /* 2 stop bits (1.5 for 5-bit words) */
#define LCR_PEN           0x08   /* parity enable */
#define LCR_EPS           0x10   /* even parity select */
#define LCR_STICK         0x20   /* stick parity */
#define LCR_BREAK         0x40   /* set break */
#define LCR_DLAB          0x80   /* divisor latch access */

/* MCR (DS 8.8); bits 7-5 are always 0. */
#define MCR_DTR           0x01
#define MCR_RTS           0x02   /* here: the RS-485 driver enable (DE) */
#define MCR_OUT1          0x04
#define MCR_OUT2          0x08   /* a PC gates the interrupt with OUT2 */
#define MCR_LOOP          0x10   /* local loopback */
#define MCR_WRITABLE      0x1f

/* LSR (DS 8.4). */
#define LSR_DR            0x01   /* data ready */
#define LSR_OE            0x02   /* overrun error */
#define LSR_PE            0x04   /* parity error */
#define LSR_FE            0x08   /* framing error */
#define LSR_BI            0x10   /* break interrupt */
#define LSR_THRE          0x20   /* transmitter holding register empty */
#define LSR_TEMT          0x40   /* transmitter empty */
#define LSR_RX_FIFO_ERROR 0x80   /* an error somewhere in the receiver FIFO */
#define LSR_CHAR_ERRORS   (LSR_PE | LSR_FE | LSR_BI)
#define LSR_INT_ERRORS    (LSR_OE | LSR_PE | LSR_FE | LSR_BI)

/* MSR (DS 8.9): deltas in bits 3-0, the inputs' complements in 7-4. */
#define MSR_DCTS          0x01
#define MSR_DDSR          0x02
#define MSR_TERI          0x04   /* trailing edge of ring indicator */
#define MSR_DDCD          0x08
#define MSR_CTS           0x10
#define MSR_DSR           0x20
#define MSR_RI            0x40
#define MSR_DCD           0x80
#define MSR_DELTAS        0x0f

/* The FIFOs hold 16 characters each (DS 6.0, "FIFO Operation"). */
#define UART_FIFO_DEPTH   16
/* The receiver trigger levels FCR bits 7-6 select (DS 8.5). */
static const unsigned uart_trigger_levels[4] = { 1, 4, 8, 14 };
/* The time-out interrupt: no character in or out of the FIFO for four character times (DS 8.6). */
#define UART_TIMEOUT_CHARACTERS 4

/*
 * The PC's reference clock is 1.8432 MHz and the baud generator divides
 * it by 16 times the divisor (DS 8.10), so one bit lasts
 * divisor * 16 / 1843200 s = divisor * 78125000 / 9 ps. Bit times are kept
 * in picoseconds, rounded, the unit the hub's messages use.
 */
#define UART_BIT_PS_NUMERATOR   78125000ULL
#define UART_BIT_PS_DENOMINATOR 9ULL
/* A divisor of 0 counts as 65536, as the 16-bit counter does. */
#define UART_DIVISOR_WRAP       65536ULL

/* Characters from the line announced but not yet due: a quantum's worth. */
#define UART_PENDING_MAX  32
/* The longest format text: "8N1.5". */
#define UART_FORMAT_MAX   8

/* ======================================================================== */
/* The device                                                               */
/* ======================================================================== */

#define TYPE_ISA_RS485_UART "isa-rs485-uart"
OBJECT_DECLARE_SIMPLE_TYPE(IsaRs485UartState, ISA_RS485_UART)

/* One received character and its errors (LSR_PE, LSR_FE, LSR_BI). */
typedef struct UartChar {
    uint8_t byte;
    uint8_t errors;
} UartChar;

/* A character the hub announced, due at the end of its stop bit. */
typedef struct UartPending {
    int64_t time;
    uint64_t bit_ps;
    char format[UART_FORMAT_MAX];
    uint8_t byte;
    bool garbled;
    /* Sent by this UART in loopback, not received from the line. */
    bool looped;
} UartPending;

struct IsaRs485UartState {
    ISADevice parent_obj;

    /* Properties. */
    uint32_t iobase;
    uint32_t irq_line;
    char *hub_path;
    char *hub_name;
    uint32_t hub_timeout_s;
    char *line_name;

    MemoryRegion io;
    qemu_irq irq;
    LabBusLink *link;
    /* The port number at the hub, or -1 without a line. */
    int port;

    /* Registers. */
    uint8_t ier;
    uint8_t lcr;
    uint8_t mcr;
    uint8_t scr;
    uint16_t divisor;
    uint8_t fcr;
    /* LSR's error bits, latched until LSR is read (DS 8.4). */
    uint8_t lsr_errors;
    /* MSR's delta bits, latched until MSR is read (DS 8.9). */
    uint8_t msr_deltas;
    /* The modem inputs as last seen (MSR bits 7-4). */
    uint8_t msr_inputs;

    /* The receiver FIFO (one entry deep with FIFOs off, as RBR). */
    UartChar rx_fifo[UART_FIFO_DEPTH];
    unsigned rx_head;
    unsigned rx_count;
    /* A time-out indication is pending (IIR 0x0C), cleared by reading RBR. */
    bool timeout_pending;
    QEMUTimer *timeout_timer;

    /* The transmitter FIFO (one entry deep with FIFOs off, as THR). */
    uint8_t tx_fifo[UART_FIFO_DEPTH];
    unsigned tx_head;
    unsigned tx_count;
    /* The shift register holds a character until tx_end. */
    bool tx_shifting;
    int64_t tx_end;
    QEMUTimer *tx_timer;
    /* The THRE interrupt is pending (DS 8.6: cleared by reading IIR or writing THR). */
    bool thre_pending;

    /* Characters from the line, in time order, not yet due. */
    UartPending pending[UART_PENDING_MAX];
    unsigned pending_head;
    unsigned pending_count;
    QEMUTimer *rx_timer;

    /* The driver enable last reported to the hub. */
    bool driver_reported;

    /* Counters, readable as properties, for tests and diagnostics. */
    uint64_t chars_sent;
    uint64_t chars_received;
    uint64_t chars_garbled;
    uint64_t overruns;
};

static int64_t uart_now(void)
{
    return qemu_clock_get_ns(QEMU_CLOCK_VIRTUAL);
}

static bool uart_fifo_mode(IsaRs485UartState *s)
{
    return s->fcr & FCR_ENABLE;
}

static unsigned uart_fifo_depth(IsaRs485UartState *s)
{
    return uart_fifo_mode(s) ? UART_FIFO_DEPTH : 1;
}

/* -- character timing ---------------------------------------------------- */

static uint64_t uart_bit_ps(IsaRs485UartState *s)
{
    uint64_t divisor = s->divisor ? s->divisor : UART_DIVISOR_WRAP;

    return (divisor * UART_BIT_PS_NUMERATOR + UART_BIT_PS_DENOMINATOR / 2) /
           UART_BIT_PS_DENOMINATOR;
}

static unsigned uart_data_bits(IsaRs485UartState *s)
{
    return 5 + (s->lcr & LCR_WLS_MASK);
}

/* Stop bits in half bits: 2, or with STB 3 for 5-bit words and 4 otherwise (DS 8.1). */
static unsigned uart_stop_half_bits(IsaRs485UartState *s)
{
    if (!(s->lcr & LCR_STB)) {
        return 2;
    }
    return uart_data_bits(s) == 5 ? 3 : 4;
}

/*
 * A character's length in half bits: start, data, parity and stop. The
 * hub computes the same from the format text (rs485.py, char_half_bits).
 */
static unsigned uart_char_half_bits(IsaRs485UartState *s)
{
    return 2 * (1 + uart_data_bits(s) + ((s->lcr & LCR_PEN) ? 1 : 0)) +
           uart_stop_half_bits(s);
}

static int64_t uart_char_ns(IsaRs485UartState *s)
{
    return (uart_char_half_bits(s) * uart_bit_ps(s) + 1000) / 2000;
}

/*
 * The format as the hub's messages write it: data bits, parity (N none,
 * O odd, E even, M mark and S space for stick parity, DS 8.1 Table VI) and
 * stop bits (1, 1.5 or 2).
 */
static void uart_format(IsaRs485UartState *s, char *text, size_t size)
{
    char parity = 'N';
    unsigned stop = uart_stop_half_bits(s);

    if (s->lcr & LCR_PEN) {
        if (s->lcr & LCR_STICK) {
            parity = (s->lcr & LCR_EPS) ? 'S' : 'M';
        } else {
            parity = (s->lcr & LCR_EPS) ? 'E' : 'O';
        }
    }
    snprintf(text, size, "%u%c%s", uart_data_bits(s), parity,
             stop == 2 ? "1" : stop == 3 ? "1.5" : "2");
}

/* -- interrupts ------------------------------------------------------------ */

static bool uart_rx_trigger_reached(IsaRs485UartState *s)
{
    unsigned level = uart_fifo_mode(s) ?
        uart_trigger_levels[s->fcr >> FCR_TRIGGER_SHIFT] : 1;

    return s->rx_count >= level;
}

/* The IIR value: the highest-priority enabled source (DS 8.6, Table IV). */
static uint8_t uart_iir(IsaRs485UartState *s)
{
    uint8_t fifos = uart_fifo_mode(s) ? IIR_FIFOS_ON : 0;

    if ((s->ier & IER_ELSI) && (s->lsr_errors & LSR_INT_ERRORS)) {
        return fifos | IIR_LINE_STATUS;
    }
    if ((s->ier & IER_ERBFI) && uart_rx_trigger_reached(s)) {
        return fifos | IIR_RX_DATA;
    }
    if ((s->ier & IER_ERBFI) && s->timeout_pending) {
        return fifos | IIR_CHAR_TIMEOUT;
    }
    if ((s->ier & IER_ETBEI) && s->thre_pending) {
        return fifos | IIR_THRE;
    }
    if ((s->ier & IER_EDSSI) && (s->msr_deltas & MSR_DELTAS)) {
        return fifos | IIR_MODEM_STATUS;
    }
    return fifos | IIR_NO_INT;
}

/*
 * The ISA line follows the UART's INTRPT output, which a PC board passes
 * to the bus only while OUT2 is set (the driver sets it for that reason).
 */
static void uart_update_irq(IsaRs485UartState *s)
{
    bool pending = !(uart_iir(s) & IIR_NO_INT);

    qemu_set_irq(s->irq, pending && (s->mcr & MCR_OUT2));
}

/* -- the modem inputs ------------------------------------------------------- */

/*
 * An RS-485 transceiver has no modem lines, so outside loopback CTS, DSR,
 * RI and DCD are inactive. In loopback the outputs drive them (DS 8.8):
 * RTS to CTS, DTR to DSR, OUT1 to RI and OUT2 to DCD.
 */
static void uart_update_modem_inputs(IsaRs485UartState *s)
{
    uint8_t inputs = 0;
    uint8_t changed;

    if (s->mcr & MCR_LOOP) {
        inputs = ((s->mcr & MCR_RTS) ? MSR_CTS : 0) |
                 ((s->mcr & MCR_DTR) ? MSR_DSR : 0) |
                 ((s->mcr & MCR_OUT1) ? MSR_RI : 0) |
                 ((s->mcr & MCR_OUT2) ? MSR_DCD : 0);
    }
    changed = inputs ^ s->msr_inputs;
    if (changed & MSR_CTS) {
        s->msr_deltas |= MSR_DCTS;
    }
    if (changed & MSR_DSR) {
        s->msr_deltas |= MSR_DDSR;
    }
    if ((changed & MSR_RI) && !(inputs & MSR_RI)) {
        s->msr_deltas |= MSR_TERI;
    }
    if (changed & MSR_DCD) {
        s->msr_deltas |= MSR_DDCD;
    }
    s->msr_inputs = inputs;
}

/* -- reception ------------------------------------------------------------- */

static void uart_arm_timeout(IsaRs485UartState *s)
{
    /*
     * The time-out counts from the last character received or read while
     * characters wait in the FIFO (DS 8.6); in FIFO mode only.
     */
    if (uart_fifo_mode(s) && s->rx_count > 0) {
        timer_mod_ns(s->timeout_timer, uart_now() +
                     UART_TIMEOUT_CHARACTERS * uart_char_ns(s));
    } else {
        timer_del(s->timeout_timer);
    }
}

static void uart_timeout_cb(void *opaque)
{
    IsaRs485UartState *s = opaque;

    if (s->rx_count > 0) {
        s->timeout_pending = true;
        uart_update_irq(s);
    }
}

/* The character now at the top of the FIFO shows its errors in LSR (DS 8.4). */
static void uart_reveal_top_errors(IsaRs485UartState *s)
{
    if (s->rx_count > 0) {
        s->lsr_errors |= s->rx_fifo[s->rx_head].errors;
    }
}

/* A character has been assembled in the receiver shift register. */
static void uart_receive_char(IsaRs485UartState *s, uint8_t byte,
                              uint8_t errors)
{
    unsigned mask = (1u << uart_data_bits(s)) - 1;

    s->chars_received++;
    if (s->rx_count >= uart_fifo_depth(s)) {
        /*
         * Overrun (DS 8.4): the FIFO (or RBR) is full; the new character
         * is lost and the ones stored are kept.
         */
        s->lsr_errors |= LSR_OE;
        s->overruns++;
    } else {
        unsigned slot = (s->rx_head + s->rx_count) % UART_FIFO_DEPTH;

        s->rx_fifo[slot].byte = byte & mask;
        s->rx_fifo[slot].errors = errors;
        s->rx_count++;
        if (s->rx_count == 1) {
            uart_reveal_top_errors(s);
        }
    }
    s->timeout_pending = false;
    uart_arm_timeout(s);
    uart_update_irq(s);
}

static uint8_t uart_read_rbr(IsaRs485UartState *s)
{
    uint8_t byte = 0;

    if (s->rx_count > 0) {
        byte = s->rx_fifo[s->rx_head].byte;
        s->rx_head = (s->rx_head + 1) % UART_FIFO_DEPTH;
        s->rx_count--;
        uart_reveal_top_errors(s);
    }
    s->timeout_pending = false;
    uart_arm_timeout(s);
    uart_update_irq(s);
    return byte;
}

static bool uart_fifo_has_errors(IsaRs485UartState *s)
{
    unsigned i;

    for (i = 0; i < s->rx_count; i++) {
        if (s->rx_fifo[(s->rx_head + i) % UART_FIFO_DEPTH].errors) {
            return true;
        }
    }
    return false;
}

/* The parity bit a format's letter gives for these data bits (DS 8.1, Table VI). */
static unsigned uart_parity_bit(char parity, unsigned data)
{
    unsigned ones = ctpop32(data) & 1;

    switch (parity) {
    case 'E':
        return ones;
    case 'O':
        return ones ^ 1;
    case 'M':
        return 1;
    default:
        return 0;
    }
}

/*
 * The level a character drives offset_ps after its start bit began: the
 * start bit (0), the data bits from the least significant, the parity bit,
 * then the stop bits and the idle line (1).
 */
static unsigned uart_char_level(const UartPending *c, uint64_t offset_ps)
{
    unsigned data_bits = c->format[0] - '0';
    char parity = c->format[1];
    uint64_t bit = offset_ps / c->bit_ps;

    if (bit == 0) {
        return 0;
    }
    if (bit <= data_bits) {
        return (c->byte >> (bit - 1)) & 1;
    }
    if (parity != 'N' && bit == data_bits + 1) {
        return uart_parity_bit(parity, c->byte & ((1u << data_bits) - 1));
    }
    return 1;
}

/*
 * A character from the line is due. The receiver samples it in the middle
 * of each of its own bits, at its own bit time and format (DS 8.0: the
 * receiver checks the first stop bit only), so a character sent at another
 * rate or format arrives with wrong bits, and with a parity or framing
 * error when those bits say so, as on a real line; one sent at the
 * receiver's own settings arrives intact. A garbled character (two
 * drivers at once, the hub says) carries a framing error and the data the
 * hub gives: the receiver could not tell the bits apart.
 */
static void uart_deliver(IsaRs485UartState *s, const UartPending *c)
{
    uint64_t bit_ps = uart_bit_ps(s);
    unsigned data_bits = uart_data_bits(s);
    unsigned position = 1;
    unsigned byte = 0;
    uint8_t errors = 0;
    unsigned i;

    if (!(s->mcr & MCR_LOOP) != !c->looped) {
        /*
         * In loopback the serial input is disconnected (DS 8.8), and a
         * looped character whose loopback ended before its stop bit is
         * lost with it.
         */
        return;
    }
    if (c->format[0] < '5' || c->format[0] > '8') {
        labbus_link_fatal(s->link, "a character with the format %s", c->format);
    }
    for (i = 0; i < data_bits; i++, position++) {
        byte |= uart_char_level(c, position * bit_ps + bit_ps / 2) << i;
    }
    if (s->lcr & LCR_PEN) {
        char parity = (s->lcr & LCR_STICK) ?
            ((s->lcr & LCR_EPS) ? 'S' : 'M') :
            ((s->lcr & LCR_EPS) ? 'E' : 'O');

        if (uart_char_level(c, position * bit_ps + bit_ps / 2) !=
            uart_parity_bit(parity, byte)) {
            errors |= LSR_PE;
        }
        position++;
    }
    if (!uart_char_level(c, position * bit_ps + bit_ps / 2)) {
        errors |= LSR_FE;
    }
    if (c->garbled) {
        errors |= LSR_FE;
        byte = c->byte;
    }
    if (errors) {
        s->chars_garbled++;
    }
    uart_receive_char(s, byte, errors);
}

static void uart_arm_rx_timer(IsaRs485UartState *s)
{
    if (s->pending_count > 0) {
        timer_mod_ns(s->rx_timer, s->pending[s->pending_head].time);
    } else {
        timer_del(s->rx_timer);
    }
}

static void uart_run_pending(IsaRs485UartState *s)
{
    int64_t now = uart_now();
    unsigned handled = 0;

    /* Bounded by the queue's size: each round takes one character out. */
    while (s->pending_count > 0 && handled < UART_PENDING_MAX &&
           s->pending[s->pending_head].time <= now) {
        UartPending c = s->pending[s->pending_head];

        s->pending_head = (s->pending_head + 1) % UART_PENDING_MAX;
        s->pending_count--;
        uart_deliver(s, &c);
        handled++;
    }
    uart_arm_rx_timer(s);
}

static void uart_rx_timer_cb(void *opaque)
{
    IsaRs485UartState *s = opaque;

    /*
     * Back in its list for now while characters are delivered (see
     * labbus_link_boundary): an idle skip of the clock triggered meanwhile
     * cannot pass the next one. Then it is set for that one, or deleted.
     */
    timer_mod_ns(s->rx_timer, uart_now());
    uart_run_pending(s);
}

/* -- transmission ------------------------------------------------------------ */

/* The transceiver's driver is enabled by RTS; loopback forces RTS's pin inactive (DS 8.8). */
static bool uart_driver_enabled(IsaRs485UartState *s)
{
    return (s->mcr & MCR_RTS) && !(s->mcr & MCR_LOOP);
}

static void uart_report_driver(IsaRs485UartState *s)
{
    bool on = uart_driver_enabled(s);
    char time[24];

    if (s->port < 0 || on == s->driver_reported) {
        return;
    }
    s->driver_reported = on;
    labbus_link_send(s->link, "DRIVE %d %s %s", s->port,
                     labbus_link_time(s->link, uart_now(), time, sizeof(time)),
                     on ? "on" : "off");
}

/*
 * Moves the next byte from the FIFO into the shift register at start: the
 * character is on the line from start to start + its length.
 */
static void uart_start_char(IsaRs485UartState *s, int64_t start)
{
    uint8_t byte = s->tx_fifo[s->tx_head];
    char time[24];
    char format[UART_FORMAT_MAX];
    unsigned mask = (1u << uart_data_bits(s)) - 1;

    s->tx_head = (s->tx_head + 1) % UART_FIFO_DEPTH;
    s->tx_count--;
    s->tx_shifting = true;
    s->tx_end = start + uart_char_ns(s);
    s->chars_sent++;
    if (s->tx_count == 0) {
        /* THRE: the holding register (FIFO) is empty (DS 8.4). */
        s->thre_pending = true;
    }
    if (s->mcr & MCR_LOOP) {
        /*
         * Loopback (DS 8.8): the shift register feeds the receiver, and
         * the character arrives when its stop bit ends.
         */
        if (s->pending_count < UART_PENDING_MAX) {
            UartPending *c = &s->pending[(s->pending_head + s->pending_count) %
                                         UART_PENDING_MAX];

            c->time = s->tx_end;
            c->bit_ps = uart_bit_ps(s);
            uart_format(s, c->format, sizeof(c->format));
            c->byte = byte & mask;
            c->garbled = false;
            c->looped = true;
            s->pending_count++;
            uart_arm_rx_timer(s);
        }
    } else if (s->port >= 0 && uart_driver_enabled(s)) {
        uart_format(s, format, sizeof(format));
        labbus_link_send(s->link, "CHAR %d %s %" PRIu64 " %s %02x", s->port,
                         labbus_link_time(s->link, start, time, sizeof(time)),
                         uart_bit_ps(s), format, byte & mask);
    }
    /*
     * Without the driver enabled the character goes into a disabled
     * transceiver and reaches no one, as on a real RS-485 board.
     */
    timer_mod_ns(s->tx_timer, s->tx_end);
    uart_update_irq(s);
}

static void uart_tx_timer_cb(void *opaque)
{
    IsaRs485UartState *s = opaque;

    /* Back in its list while it runs, as uart_rx_timer_cb explains. */
    timer_mod_ns(s->tx_timer, uart_now());
    s->tx_shifting = false;
    if (s->tx_count > 0) {
        /* The next character follows the stop bit without a gap. */
        uart_start_char(s, s->tx_end);
    } else {
        timer_del(s->tx_timer);
        uart_update_irq(s);
    }
}

static void uart_write_thr(IsaRs485UartState *s, uint8_t byte)
{
    if (s->tx_count >= uart_fifo_depth(s)) {
        /* A write to a full FIFO is lost, as on the chip. */
        return;
    }
    s->tx_fifo[(s->tx_head + s->tx_count) % UART_FIFO_DEPTH] = byte;
    s->tx_count++;
    s->thre_pending = false;
    if (!s->tx_shifting) {
        uart_start_char(s, uart_now());
    }
    uart_update_irq(s);
}

static uint8_t uart_read_lsr(IsaRs485UartState *s)
{
    uint8_t value = s->lsr_errors & LSR_INT_ERRORS;

    if (s->rx_count > 0) {
        value |= LSR_DR;
    }
    if (s->tx_count == 0) {
        value |= LSR_THRE;
        if (!s->tx_shifting) {
            value |= LSR_TEMT;
        }
    }
    if (uart_fifo_mode(s) && uart_fifo_has_errors(s)) {
        value |= LSR_RX_FIFO_ERROR;
    }
    /* Reading LSR clears OE, PE, FE and BI (DS 8.4). */
    s->lsr_errors = 0;
    uart_update_irq(s);
    return value;
}

static void uart_reset_rx_fifo(IsaRs485UartState *s)
{
    s->rx_head = 0;
    s->rx_count = 0;
    s->timeout_pending = false;
    timer_del(s->timeout_timer);
}

static void uart_reset_tx_fifo(IsaRs485UartState *s)
{
    /* The shift register finishes the character it holds (DS 8.5). */
    s->tx_head = 0;
    s->tx_count = 0;
    s->thre_pending = true;
}

static void uart_write_fcr(IsaRs485UartState *s, uint8_t value)
{
    if ((value ^ s->fcr) & FCR_ENABLE) {
        /* Changing FCR0 clears both FIFOs (DS 8.5). */
        uart_reset_rx_fifo(s);
        uart_reset_tx_fifo(s);
    }
    if (value & FCR_RX_RESET) {
        uart_reset_rx_fifo(s);
    }
    if (value & FCR_TX_RESET) {
        uart_reset_tx_fifo(s);
    }
    /* The reset bits clear themselves; DMA mode (bit 3) changes nothing here. */
    s->fcr = value & (FCR_ENABLE | (3u << FCR_TRIGGER_SHIFT));
    uart_update_irq(s);
}

/* -- register access ------------------------------------------------------------ */

static uint64_t uart_io_read(void *opaque, hwaddr addr, unsigned size)
{
    IsaRs485UartState *s = opaque;
    uint8_t value = 0;

    switch (addr) {
    case UART_RBR:
        value = (s->lcr & LCR_DLAB) ? (s->divisor & 0xff) : uart_read_rbr(s);
        break;
    case UART_IER:
        value = (s->lcr & LCR_DLAB) ? (s->divisor >> 8) : s->ier;
        break;
    case UART_IIR:
        value = uart_iir(s);
        /* Reading IIR when THRE is the source clears it (DS 8.6, Table IV). */
        if ((value & ~IIR_FIFOS_ON) == IIR_THRE) {
            s->thre_pending = false;
            uart_update_irq(s);
        }
        break;
    case UART_LCR:
        value = s->lcr;
        break;
    case UART_MCR:
        value = s->mcr;
        break;
    case UART_LSR:
        value = uart_read_lsr(s);
        break;
    case UART_MSR:
        value = s->msr_inputs | s->msr_deltas;
        /* Reading MSR clears its delta bits (DS 8.9). */
        s->msr_deltas = 0;
        uart_update_irq(s);
        break;
    case UART_SCR:
        value = s->scr;
        break;
    }
    return value;
}

static void uart_io_write(void *opaque, hwaddr addr, uint64_t data,
                          unsigned size)
{
    IsaRs485UartState *s = opaque;
    uint8_t value = data;

    switch (addr) {
    case UART_THR:
        if (s->lcr & LCR_DLAB) {
            s->divisor = (s->divisor & 0xff00) | value;
        } else {
            uart_write_thr(s, value);
        }
        break;
    case UART_IER:
        if (s->lcr & LCR_DLAB) {
            s->divisor = (s->divisor & 0x00ff) | (value << 8);
        } else {
            uint8_t enabled = (value & IER_WRITABLE) & ~s->ier;

            s->ier = value & IER_WRITABLE;
            /*
             * Enabling ETBEI while the holding register is empty raises
             * the THRE interrupt at once, as the chip does.
             */
            if ((enabled & IER_ETBEI) && s->tx_count == 0) {
                s->thre_pending = true;
            }
            uart_update_irq(s);
        }
        break;
    case UART_FCR:
        uart_write_fcr(s, value);
        break;
    case UART_LCR:
        s->lcr = value;
        if (value & LCR_BREAK) {
            qemu_log_mask(LOG_UNIMP, "isa-rs485-uart: a break (LCR bit 6) "
                          "is not put on the lab line\n");
        }
        break;
    case UART_MCR:
        s->mcr = value & MCR_WRITABLE;
        uart_update_modem_inputs(s);
        uart_report_driver(s);
        uart_update_irq(s);
        break;
    case UART_LSR:
    case UART_MSR:
        /* Read-only in use; the factory test writes are not modelled. */
        break;
    case UART_SCR:
        s->scr = value;
        break;
    }
}

static const MemoryRegionOps uart_io_ops = {
    .read = uart_io_read,
    .write = uart_io_write,
    .endianness = DEVICE_LITTLE_ENDIAN,
    .impl = {
        .min_access_size = 1,
        .max_access_size = 1,
    },
    .valid = {
        .min_access_size = 1,
        .max_access_size = 1,
    },
};

/* -- events from the hub ----------------------------------------------------- */

/*
 * "RX <port> <epoch> <time> <bit ps> <format> <byte hex> <flags>"
 * (docs/protocols/labbus.md, "The RS-485 line"): a character that ends at
 * <time>; <flags> is "-" or "garbled". Queued for its time; the hub never
 * announces one before the boundary it sends it at. A real-time link
 * delivers it on arrival.
 */
static void uart_link_event(void *opaque, int argc, char **argv)
{
    IsaRs485UartState *s = opaque;
    UartPending *c;
    uint64_t time;
    uint64_t bit_ps;
    uint64_t byte;
    const char *end;

    if (argc != 8 || strcmp(argv[0], "RX") ||
        !labbus_parse_u64(argv[3], &time) ||
        !labbus_parse_u64(argv[4], &bit_ps) ||
        strlen(argv[5]) >= UART_FORMAT_MAX || bit_ps == 0 ||
        argv[5][0] < '5' || argv[5][0] > '8' ||
        qemu_strtou64(argv[6], &end, 16, &byte) || *end || byte > 0xff ||
        (strcmp(argv[7], "-") && strcmp(argv[7], "garbled"))) {
        labbus_link_fatal(s->link, "the hub sent a malformed %s event for "
                          "the RS-485 port (%d words)", argv[0], argc);
    }
    if (s->pending_count >= UART_PENDING_MAX) {
        labbus_link_fatal(s->link, "the hub announced more than %d "
                          "characters ahead", UART_PENDING_MAX);
    }
    if (labbus_link_realtime(s->link)) {
        /* The hub's time is not this machine's: the character is due now. */
        time = uart_now();
    }
    c = &s->pending[(s->pending_head + s->pending_count) % UART_PENDING_MAX];
    if (s->pending_count > 0) {
        const UartPending *last = &s->pending[(s->pending_head +
            s->pending_count - 1) % UART_PENDING_MAX];

        if ((int64_t)time < last->time) {
            labbus_link_fatal(s->link, "the hub announced characters out of "
                              "time order");
        }
    }
    c->time = time;
    c->bit_ps = bit_ps;
    pstrcpy(c->format, sizeof(c->format), argv[5]);
    c->byte = byte;
    c->garbled = !strcmp(argv[7], "garbled");
    c->looped = false;
    s->pending_count++;
    if ((int64_t)time <= uart_now()) {
        uart_run_pending(s);
    } else {
        uart_arm_rx_timer(s);
    }
}

/* -- the device ---------------------------------------------------------------- */

static void uart_realize(DeviceState *dev, Error **errp)
{
    ISADevice *isa = ISA_DEVICE(dev);
    IsaRs485UartState *s = ISA_RS485_UART(dev);
    bool on_line = s->line_name && *s->line_name;

    if (s->iobase > 0xffff - UART_PORTS + 1) {
        error_setg(errp, "isa-rs485-uart: iobase 0x%" PRIx32 " is past the "
                   "ISA port space", s->iobase);
        return;
    }
    if (s->irq_line >= ISA_NUM_IRQS) {
        error_setg(errp, "isa-rs485-uart: irq %" PRIu32 " is not an ISA line "
                   "(0..15)", s->irq_line);
        return;
    }
    if (on_line && !(s->hub_path && *s->hub_path)) {
        error_setg(errp, "isa-rs485-uart: line=%s needs hub=<socket of the "
                   "lab hub>", s->line_name);
        return;
    }
    s->port = -1;
    s->irq = isa_get_irq(isa, s->irq_line);
    s->tx_timer = timer_new_ns(QEMU_CLOCK_VIRTUAL, uart_tx_timer_cb, s);
    s->rx_timer = timer_new_ns(QEMU_CLOCK_VIRTUAL, uart_rx_timer_cb, s);
    s->timeout_timer = timer_new_ns(QEMU_CLOCK_VIRTUAL, uart_timeout_cb, s);
    memory_region_init_io(&s->io, OBJECT(dev), &uart_io_ops, s,
                          TYPE_ISA_RS485_UART, UART_PORTS);
    isa_register_ioport(isa, &s->io, s->iobase);
    if (s->hub_path && *s->hub_path) {
        LabBusLinkConfig config = {
            .path = s->hub_path,
            .name = s->hub_name,
            .timeout_s = s->hub_timeout_s,
            .realtime = false,
        };

        s->link = labbus_board_link_join(OBJECT(s), &config, errp);
        if (!s->link) {
            return;
        }
    }
    if (on_line) {
        s->port = labbus_link_attach(s->link, s->line_name, "rs485",
                                     uart_link_event, s, errp);
    }
}

static void uart_unrealize(DeviceState *dev)
{
    IsaRs485UartState *s = ISA_RS485_UART(dev);

    timer_free(s->tx_timer);
    timer_free(s->rx_timer);
    timer_free(s->timeout_timer);
    labbus_board_link_forget(s->link);
}

/* The state after a master reset (DS 8.11, Table VIII). */
static void uart_reset(DeviceState *dev)
{
    IsaRs485UartState *s = ISA_RS485_UART(dev);

    s->ier = 0;
    s->lcr = 0;
    s->mcr = 0;
    s->fcr = 0;
    s->lsr_errors = 0;
    s->msr_deltas = 0;
    s->msr_inputs = 0;
    uart_reset_rx_fifo(s);
    uart_reset_tx_fifo(s);
    s->thre_pending = false;
    s->tx_shifting = false;
    timer_del(s->tx_timer);
    s->pending_head = 0;
    s->pending_count = 0;
    timer_del(s->rx_timer);
    /* The driver enable falls with MCR; the hub hears of it if it was on. */
    if (s->port >= 0 && s->driver_reported) {
        uart_report_driver(s);
    }
    uart_update_irq(s);
}

static Property uart_properties[] = {
    DEFINE_PROP_UINT32("iobase", IsaRs485UartState, iobase, 0x2f8),
    DEFINE_PROP_UINT32("irq", IsaRs485UartState, irq_line, 3),
    DEFINE_PROP_STRING("hub", IsaRs485UartState, hub_path),
    DEFINE_PROP_STRING("hub-name", IsaRs485UartState, hub_name),
    DEFINE_PROP_UINT32("hub-timeout", IsaRs485UartState, hub_timeout_s, 60),
    DEFINE_PROP_STRING("line", IsaRs485UartState, line_name),
    DEFINE_PROP_END_OF_LIST(),
};

static void uart_instance_init(Object *obj)
{
    IsaRs485UartState *s = ISA_RS485_UART(obj);

    object_property_add_uint64_ptr(obj, "chars-sent", &s->chars_sent,
                                   OBJ_PROP_FLAG_READ);
    object_property_add_uint64_ptr(obj, "chars-received", &s->chars_received,
                                   OBJ_PROP_FLAG_READ);
    object_property_add_uint64_ptr(obj, "chars-garbled", &s->chars_garbled,
                                   OBJ_PROP_FLAG_READ);
    object_property_add_uint64_ptr(obj, "overruns", &s->overruns,
                                   OBJ_PROP_FLAG_READ);
}

static void uart_class_init(ObjectClass *klass, void *data)
{
    DeviceClass *dc = DEVICE_CLASS(klass);

    dc->desc = "DCOS ISA 16550A UART on the lab's RS-485 line "
               "(1.8432 MHz, driver enable on RTS)";
    dc->realize = uart_realize;
    dc->unrealize = uart_unrealize;
    dc->reset = uart_reset;
    device_class_set_props(dc, uart_properties);
    object_class_property_set_description(klass, "iobase",
        "base port of the eight registers (COM2: 0x2f8)");
    object_class_property_set_description(klass, "irq",
        "ISA interrupt line (COM2: 3)");
    object_class_property_set_description(klass, "hub",
        "unix socket of the lab hub (dcoslab/canbus.py); none: no hub");
    object_class_property_set_description(klass, "hub-name",
        "this board's participant name at the hub, e.g. board1");
    object_class_property_set_description(klass, "hub-timeout",
        "seconds to wait for a silent hub before stopping the board");
    object_class_property_set_description(klass, "line",
        "the lab's RS-485 line the port is wired to (none: no other node)");
    set_bit(DEVICE_CATEGORY_INPUT, dc->categories);
}

static const TypeInfo uart_info = {
    .name          = TYPE_ISA_RS485_UART,
    .parent        = TYPE_ISA_DEVICE,
    .instance_size = sizeof(IsaRs485UartState),
    .instance_init = uart_instance_init,
    .class_init    = uart_class_init,
};

static void uart_register_types(void)
{
    type_register_static(&uart_info);
}

type_init(uart_register_types)
