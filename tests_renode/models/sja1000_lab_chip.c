/*
 * One SJA1000 CAN controller on a lab bus: the chip core of the lab's CAN
 * cards (sja1000_lab_chip.h). The cards are thin bus front ends over it:
 * isa_sja1000.c ("isa-sja1000", two chips on the ISA bus) and
 * pci_kvaser_lab.c ("lab-kvaser-pci", the Kvaser PCIcan's one to four
 * chips behind its PCI bridge). The chips run from the usual 16 MHz
 * crystal (CAN clock 8 MHz) of both cards, so BRP 0 is a time quantum of
 * 125 ns.
 *
 * The chip itself is QEMU's reviewed SJA1000 core (hw/net/can/can_sja1000.c):
 * register file, acceptance filters, receive FIFO, frame buffers, BasicCAN
 * and PeliCAN modes. That core is idealised: a transmission completes inside
 * the register write, BTR0/BTR1 and the error counters read as constants and
 * there is no fault confinement. This file therefore takes over what
 * the core lacks, reading and writing the core's public state
 * (CanSJA1000State) where the two meet:
 *
 *  - the bus timing registers, decoded into a bit time and sample point;
 *  - transmission: TR, SRR and single shot (AT with TR or SRR) go to the bus
 *    with the exact emulated time of the register write, and complete only
 *    when the bus says so (TBS, TCS, TS, TI; ALI and ALC on lost
 *    arbitration); AT cancels a request not yet under way;
 *  - the error counters RXERR and TXERR, EWLR, ECC and the error states of
 *    ISO 11898-1 fault confinement (error active, warning ES, error passive
 *    with EPI, bus-off BS with the chip entering reset mode) and their
 *    interrupts EI, EPI and BEI;
 *  - reception: frames are handed to the core's can_sja_receive at their
 *    exact emulated completion time, from a QEMU_CLOCK_VIRTUAL timer;
 *  - listen-only (no acknowledge, no transmission, frozen counters), self
 *    test, sleep and wake-up.
 *
 * A chip attached to a lab bus joins the hub through the board's link
 * (labbus_link.c, shared with the RS-485 UART of isa_rs485.c), a child
 * object that holds the board's emulated time at quantum boundaries so
 * that every board on the hub stays in step; the card makes the link from
 * its properties hub, hub-name, hub-timeout and hub-realtime. A machine
 * that runs in real time (no -icount, such as the lab VM's Linux) cannot
 * be held that way, as its clock follows the host's; with hub-realtime=on
 * its link joins the hub as a real-time participant instead, which never
 * holds the boards, takes the hub's events as they arrive and lets its own
 * requests count from the hub's next boundary. The hub is
 * tests_renode/dcoslab/canbus.py; docs/protocols/labbus.md specifies the
 * protocol, the lock-step and the timing model this file follows. A chip
 * without a bus is a chip on a bus with no other node: it simulates that
 * lone bus itself, with the same timing model, so its frames are never
 * acknowledged.
 *
 * Register names and sections ("DS 6.4.5") refer to the SJA1000 data sheet
 * (Philips Semiconductors, product specification, 2000 Jan 04).
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
#include "qemu/queue.h"
#include "qemu/timer.h"
#include "qapi/error.h"
#include "hw/irq.h"
#include "hw/net/can/can_sja1000.h"
#include "net/can_emu.h"

#include "sja1000_lab_chip.h"

/* ======================================================================== */
/* SJA1000 registers and constants (data sheet sections in brackets)        */
/* ======================================================================== */

/*
 * The crystal of the usual cards, the ISA card's and the Kvaser PCIcan's
 * (Linux's KVASER_PCI_CAN_CLOCK is 16000000 / 2); CAN clock = crystal / 2
 * (DS 6.5.1).
 */
#define SJA_XTAL_HZ           16000000ULL

/* PeliCAN addresses the core's enum lacks (DS 6.4.1, Table 7). */
#define SJA_PEL_RESERVED5     0x05
#define SJA_PEL_TEST          0x09
#define SJA_PEL_RXERR         0x0e   /* RX error counter (DS 6.4.11) */
#define SJA_PEL_TXERR         0x0f   /* TX error counter (DS 6.4.12) */
#define SJA_PEL_FRAME_FIRST   0x10   /* transmit/receive buffer (DS 6.4.13) */
#define SJA_PEL_FRAME_LAST    0x1c
#define SJA_PEL_ACR_AMR_LAST  0x17   /* ACR0..3, AMR0..3 in reset mode */

/* BasicCAN addresses (DS 6.3.1, Table 2). */
#define SJA_BAS_ACR           0x04   /* acceptance code (DS 6.3.9) */
#define SJA_BAS_AMR           0x05   /* acceptance mask (DS 6.3.9) */
#define SJA_BAS_TXB_FIRST     0x0a   /* transmit buffer (DS 6.3.7) */
#define SJA_BAS_TXB_LAST      0x13
#define SJA_BAS_RXB_FIRST     0x14   /* receive buffer (DS 6.3.8) */

/* Common registers (DS 6.5). */
#define SJA_BTR0              0x06
#define SJA_BTR1              0x07
#define SJA_OCR_ADDR          0x08

/* MOD, mode register (DS 6.4.3). */
#define MOD_RM                0x01   /* reset mode */
#define MOD_LOM               0x02   /* listen only mode */
#define MOD_STM               0x04   /* self test mode */
#define MOD_AFM               0x08   /* acceptance filter mode */
#define MOD_SM                0x10   /* sleep mode */
#define MOD_WRITABLE          0x1f

/* CR, BasicCAN control register (DS 6.3.3). */
#define CR_RR                 0x01   /* reset request */
#define CR_RIE                0x02
#define CR_TIE                0x04
#define CR_EIE                0x08
#define CR_OIE                0x10

/* CMR, command register (DS 6.4.4; BasicCAN DS 6.3.4). */
#define CMR_TR                0x01   /* transmission request */
#define CMR_AT                0x02   /* abort transmission */
#define CMR_RRB               0x04   /* release receive buffer */
#define CMR_CDO               0x08   /* clear data overrun */
#define CMR_SRR               0x10   /* PeliCAN: self reception request */
#define CMR_GTS               0x10   /* BasicCAN: go to sleep */
/* A read of CMR returns all ones (DS 6.4.4). */
#define CMR_READ_VALUE        0xff

/* SR, status register (DS 6.4.5; BasicCAN DS 6.3.5). */
#define SR_RBS                0x01   /* receive buffer status */
#define SR_DOS                0x02   /* data overrun status */
#define SR_TBS                0x04   /* transmit buffer status: released */
#define SR_TCS                0x08   /* transmission complete status */
#define SR_RS                 0x10   /* receive status */
#define SR_TS                 0x20   /* transmit status */
#define SR_ES                 0x40   /* error status */
#define SR_BS                 0x80   /* bus status: bus-off */
/* The bits the core keeps (its receive FIFO); this file owns the rest. */
#define SR_CORE_BITS          (SR_RBS | SR_DOS)

/* IR and IER bits (DS 6.4.6, 6.4.7). */
#define IR_RI                 0x01   /* receive interrupt */
#define IR_TI                 0x02   /* transmit interrupt */
#define IR_EI                 0x04   /* error warning interrupt */
#define IR_DOI                0x08   /* data overrun interrupt */
#define IR_WUI                0x10   /* wake-up interrupt */
#define IR_EPI                0x20   /* error passive interrupt */
#define IR_ALI                0x40   /* arbitration lost interrupt */
#define IR_BEI                0x80   /* bus error interrupt */

/* CDR, clock divider register (DS 6.5.4). */
#define CDR_PELICAN           0x80   /* CAN mode */
#define CDR_CBP               0x40   /* comparator bypass */
/* CAN mode and CBP can be written only in reset mode. */
#define CDR_RESET_ONLY_BITS   (CDR_PELICAN | CDR_CBP)

/* BTR0 and BTR1 fields (DS 6.5.1, 6.5.2). */
#define BTR0_BRP_MASK         0x3f
#define BTR1_TSEG1_MASK       0x0f
#define BTR1_TSEG2_SHIFT      4
#define BTR1_TSEG2_MASK       0x07

/* Frame information byte of the PeliCAN buffers (DS 6.4.13). */
#define FRAME_FF              0x80   /* extended frame format */
#define FRAME_RTR             0x40
#define FRAME_DLC_MASK        0x0f
/* BasicCAN descriptor, second byte (DS 6.3.7). */
#define BAS_DESC_RTR          0x10

/* ECC, error code capture (DS 6.4.9, Tables 28 and 29). */
#define ECC_ERRC_BIT          0x00
#define ECC_ERRC_FORM         0x40
#define ECC_ERRC_STUFF        0x80
#define ECC_ERRC_OTHER        0xc0
#define ECC_DIR_RX            0x20
#define ECC_SEG_MASK          0x1f
#define ECC_SEG_ACK_SLOT      0x19

/* EWLR after a hardware reset (DS 6.4.10). */
#define EWLR_RESET_VALUE      96
/* TXERR loaded on bus-off, to count 128 bus-free signals (DS 6.4.12). */
#define TXERR_AT_BUS_OFF      127
/* A CPU write of 255 to TXERR forces a bus-off event (DS 6.4.12). */
#define TXERR_FORCE_BUS_OFF   255

/* ISO 11898-1 fault confinement. */
#define FC_PASSIVE_LIMIT      128    /* error passive from 128 */
#define FC_BUS_OFF_LIMIT      256    /* bus-off above 255 */
#define FC_TX_ERROR_STEP      8      /* a transmitter's error */
#define FC_RX_ERROR_STEP      1      /* a receiver's error */
#define FC_REC_AFTER_PASSIVE  119    /* REC > 127 after a good frame */
#define FC_COUNTER_MAX        255    /* RXERR saturates in 8 bits */
#define FC_BUS_FREE_BITS      11     /* one bus-free signal */
#define FC_RECOVERY_SIGNALS   128    /* bus-free signals to leave bus-off */
#define FC_SUSPEND_BITS       8      /* error-passive suspend transmission */

/*
 * Frame geometry with worst-case bit stuffing, as in the hub
 * (docs/protocols/labbus.md, "Timing model"): g bits from SOF to the end of
 * the CRC sequence without data, 8n data bits, floor((g + 8n - 1) / 4)
 * stuff bits, then CRC delimiter, ACK slot, ACK delimiter, 7 EOF bits and 3
 * intermission bits.
 */
#define GEOM_STANDARD_BITS    34
#define GEOM_EXTENDED_BITS    54
#define GEOM_TAIL_BITS        13
#define GEOM_ERROR_FLAG_BITS  6
#define GEOM_ERROR_DELIM_BITS 8
#define GEOM_INTERMISSION     3

/* ======================================================================== */
/* The channel                                                               */
/* ======================================================================== */

static const char *const bus_mode_names[] = {
    [BUS_MODE_OFF] = "off",
    [BUS_MODE_WAIT] = "wait",
    [BUS_MODE_ON] = "on",
    [BUS_MODE_RECOVER] = "recover",
    [BUS_MODE_SLEEP] = "sleep",
};

/* What happens on the bus to one channel, at one emulated instant. */
typedef enum ChanEventKind {
    EV_SOF,          /* a frame starts: arg is SOF_TX, SOF_RX or SOF_WAKE */
    EV_LOST,         /* arbitration lost: arg is the ALC bit number */
    EV_TXOK,         /* own frame sent */
    EV_RX,           /* a frame received */
    EV_ERR,          /* a bus error: arg is the ECC byte */
    EV_IDLE,         /* the frame or error frame is over */
    EV_ABORTED,      /* the pending request was cancelled */
    EV_JOIN,         /* bus-free seen after reset mode */
    EV_BUSFREE,      /* a bus-free signal during bus-off recovery */
    EV_FAULT,        /* forced by the lab: arg is FAULT_PASSIVE/BUS_OFF */
    EV_LONE_ATTEMPT, /* lone bus: the next transmission attempt starts */
} ChanEventKind;

#define SOF_TX           0
#define SOF_RX           1
#define SOF_WAKE         2
#define FAULT_PASSIVE    0
#define FAULT_BUS_OFF    1

#define EVF_ACK          0x01   /* an ACK error (ISO 11898-1 exception) */
#define EVF_SELF         0x02   /* a self-received frame */

struct ChanEvent {
    int64_t time;
    uint32_t epoch;
    ChanEventKind kind;
    uint8_t arg;
    uint16_t count;
    unsigned flags;
    /* EV_RX: the frame, and its DLC as sent (the core keeps at most 8). */
    qemu_can_frame frame;
    uint8_t raw_dlc;
    QTAILQ_ENTRY(ChanEvent) next;
};

/* -- mode and register helpers ------------------------------------------- */

static bool chan_pelican(Sja1000Channel *ch)
{
    return ch->core.clock & CDR_PELICAN;
}

static bool chan_in_reset(Sja1000Channel *ch)
{
    return chan_pelican(ch) ? (ch->core.mode & MOD_RM) :
                              (ch->core.control & CR_RR);
}

/*
 * The chip has one reset bit, seen as MOD.RM in PeliCAN mode and CR.RR in
 * BasicCAN mode; the core keeps the two views apart, so both are set.
 */
static void chan_set_reset_bit(Sja1000Channel *ch, bool on)
{
    if (on) {
        ch->core.mode |= MOD_RM;
        ch->core.control |= CR_RR;
    } else {
        ch->core.mode &= ~MOD_RM;
        ch->core.control &= ~CR_RR;
    }
}

static bool chan_listen_only(Sja1000Channel *ch)
{
    return chan_pelican(ch) && (ch->core.mode & MOD_LOM);
}

static bool chan_self_test(Sja1000Channel *ch)
{
    return chan_pelican(ch) && (ch->core.mode & MOD_STM);
}

static int64_t chan_now(void)
{
    return qemu_clock_get_ns(QEMU_CLOCK_VIRTUAL);
}

/* One time quantum: 2 * tCLK * (BRP + 1) (DS 6.5.1). */
static uint64_t chan_tq_ns(Sja1000Channel *ch)
{
    return 2 * ((uint64_t)(ch->btr0 & BTR0_BRP_MASK) + 1) *
           NANOSECONDS_PER_SECOND / SJA_XTAL_HZ;
}

/* TSEG1 and TSEG2 in time quanta (DS 6.5.2). */
static unsigned chan_tseg1(Sja1000Channel *ch)
{
    return (ch->btr1 & BTR1_TSEG1_MASK) + 1;
}

static unsigned chan_tseg2(Sja1000Channel *ch)
{
    return ((ch->btr1 >> BTR1_TSEG2_SHIFT) & BTR1_TSEG2_MASK) + 1;
}

/* The nominal bit time: SYNC_SEG + TSEG1 + TSEG2 (DS 6.5.2). */
static uint64_t chan_bit_ns(Sja1000Channel *ch)
{
    return chan_tq_ns(ch) * (1 + chan_tseg1(ch) + chan_tseg2(ch));
}

/* The sample point, at the end of TSEG1, in thousandths of a bit. */
static unsigned chan_sample_permille(Sja1000Channel *ch)
{
    unsigned bit_tq = 1 + chan_tseg1(ch) + chan_tseg2(ch);

    return (1000 * (1 + chan_tseg1(ch)) + bit_tq / 2) / bit_tq;
}

/* -- interrupts ----------------------------------------------------------- */

/* The core's INT rule, for both modes (its update functions are static). */
static void chan_update_irq(Sja1000Channel *ch)
{
    bool level;

    if (chan_pelican(ch)) {
        level = ch->core.interrupt_en & ch->core.interrupt_pel;
    } else {
        level = (ch->core.control >> 1) & ch->core.interrupt_bas;
    }
    qemu_set_irq(ch->core.irq, level);
}

/*
 * Sets an IR bit if its enable bit is set: in PeliCAN mode every IR bit is
 * set only "if enabled" (DS 6.4.6); in BasicCAN mode TI and EI follow
 * CR.TIE and CR.EIE, and WUI has no enable bit (DS 6.3.6).
 */
static void chan_raise(Sja1000Channel *ch, uint8_t bit)
{
    if (chan_pelican(ch)) {
        if (ch->core.interrupt_en & bit) {
            ch->core.interrupt_pel |= bit;
        }
    } else if (bit == IR_TI || bit == IR_EI) {
        if ((ch->core.control >> 1) & bit) {
            ch->core.interrupt_bas |= bit;
        }
    } else if (bit == IR_WUI) {
        ch->core.interrupt_bas |= bit;
    }
    chan_update_irq(ch);
}

/*
 * The core sets RI and DOI whether or not they are enabled; the data sheet
 * sets RI only while the FIFO holds a message and RIE is set, and DOI only
 * if DOIE is set (DS 6.4.6). Called after every core access that may
 * change them.
 */
static void chan_normalise_rx_interrupts(Sja1000Channel *ch)
{
    if (chan_pelican(ch)) {
        if ((ch->core.interrupt_en & IR_RI) && ch->core.rxmsg_cnt) {
            ch->core.interrupt_pel |= IR_RI;
        } else {
            ch->core.interrupt_pel &= ~IR_RI;
        }
        if (!(ch->core.interrupt_en & IR_DOI)) {
            ch->core.interrupt_pel &= ~IR_DOI;
        }
    } else {
        if ((ch->core.control & CR_RIE) && ch->core.rxmsg_cnt) {
            ch->core.interrupt_bas |= IR_RI;
        } else {
            ch->core.interrupt_bas &= ~IR_RI;
        }
        if (!(ch->core.control & CR_OIE)) {
            ch->core.interrupt_bas &= ~IR_DOI;
        }
    }
    chan_update_irq(ch);
}

/* -- reporting to the hub -------------------------------------------------- */

static ChanBusMode chan_compute_mode(Sja1000Channel *ch)
{
    if (chan_in_reset(ch)) {
        return BUS_MODE_OFF;
    }
    if (ch->bus_off) {
        return BUS_MODE_RECOVER;
    }
    if (ch->sleeping) {
        return BUS_MODE_SLEEP;
    }
    return ch->joined ? BUS_MODE_ON : BUS_MODE_WAIT;
}

static void chan_lone_next_step(Sja1000Channel *ch);

/*
 * Re-derives the channel's bus mode and tells the hub when it or the
 * flags the hub needs changed. Leaving the bus (reset mode, bus-off,
 * sleep) starts a new epoch, so events the hub announced before it knew
 * (a frame the chip left by entering reset mode) are dropped when they
 * come due. Joining the bus keeps the epoch: the hub counts a channel in
 * from the bus-free signal it computed, before the board hears of it.
 */
static void chan_update_mode(Sja1000Channel *ch)
{
    ChanBusMode mode = chan_compute_mode(ch);
    bool mode_changed = mode != ch->mode;
    uint64_t bit_ns = chan_bit_ns(ch);
    uint8_t mod_flags = ch->core.mode & (MOD_LOM | MOD_STM);

    if (mode_changed) {
        ch->mode = mode;
        if (mode == BUS_MODE_OFF || mode == BUS_MODE_SLEEP) {
            ch->epoch++;
        }
        if (mode == BUS_MODE_RECOVER) {
            ch->recovery_signals = 0;
        }
    }
    if (ch->port >= 0) {
        if (!ch->reported || mode_changed || ch->reported_mode != mode ||
            ch->reported_passive != ch->passive ||
            ch->reported_bit_ns != bit_ns || ch->reported_mod != mod_flags) {
            char flags[32] = "";

            if (ch->passive) {
                g_strlcat(flags, ",passive", sizeof(flags));
            }
            if (chan_listen_only(ch)) {
                g_strlcat(flags, ",listen", sizeof(flags));
            }
            if (chan_self_test(ch)) {
                g_strlcat(flags, ",selftest", sizeof(flags));
            }
            char time_word[24];

            labbus_link_send(ch->link, "STATE %d %s %" PRIu32
                             " %s %" PRIu64 " %u %s", ch->port,
                             labbus_link_time(ch->link, chan_now(),
                                              time_word, sizeof(time_word)),
                             ch->epoch, bus_mode_names[mode], bit_ns,
                             chan_sample_permille(ch),
                             flags[0] ? flags + 1 : "-");
            ch->reported = true;
            ch->reported_mode = mode;
            ch->reported_passive = ch->passive;
            ch->reported_bit_ns = bit_ns;
            ch->reported_mod = mod_flags;
        }
    } else if (mode_changed) {
        chan_lone_next_step(ch);
    }
}

/* -- the event queue --------------------------------------------------------- */

static void chan_apply_event(Sja1000Channel *ch, ChanEvent *event);

static void chan_arm_event_timer(Sja1000Channel *ch)
{
    ChanEvent *first = QTAILQ_FIRST(&ch->events);

    if (first) {
        timer_mod_ns(ch->event_timer, first->time);
    } else {
        timer_del(ch->event_timer);
    }
}

/*
 * Applies every event that is due, in time order, then re-arms the timer.
 * A register access calls it too, and finds nothing due nearly always: the
 * timer is then left alone, since setting it again would make QEMU end
 * the guest's translation block at once.
 */
static void chan_run_events(Sja1000Channel *ch)
{
    int64_t now = chan_now();
    ChanEvent *event = QTAILQ_FIRST(&ch->events);

    if (ch->running_events) {
        /* The loop below picks up what an event queues for now. */
        return;
    }
    if (!event || event->time > now) {
        return;
    }
    ch->running_events = true;
    while ((event = QTAILQ_FIRST(&ch->events)) && event->time <= now) {
        QTAILQ_REMOVE(&ch->events, event, next);
        /*
         * A fault is the lab's command about the chip, not a consequence of
         * bus traffic the chip may have left: the hub tags it with the epoch
         * it knew at the boundary, which a reconfiguration in the quantum
         * before has already ended, so it applies whatever the epoch.
         */
        if (event->epoch == ch->epoch || event->kind == EV_FAULT) {
            chan_apply_event(ch, event);
        }
        g_free(event);
    }
    ch->running_events = false;
    chan_arm_event_timer(ch);
}

static void chan_event_timer_cb(void *opaque)
{
    Sja1000Channel *ch = opaque;

    /*
     * Back in its list for now while the events run (see
     * labbus_link_boundary): an idle skip of the clock triggered meanwhile
     * cannot pass this channel's next event. Then it is set for that
     * event, or deleted.
     */
    timer_mod_ns(ch->event_timer, chan_now());
    chan_run_events(ch);
    chan_arm_event_timer(ch);
}

/*
 * Queues an event at its emulated time, after any event already queued
 * for the same instant, so events keep the order they were announced in.
 */
static void chan_queue_event(Sja1000Channel *ch, ChanEvent *event)
{
    ChanEvent *before = QTAILQ_LAST(&ch->events);

    while (before && before->time > event->time) {
        before = QTAILQ_PREV(before, next);
    }
    if (before) {
        QTAILQ_INSERT_AFTER(&ch->events, before, event, next);
    } else {
        QTAILQ_INSERT_HEAD(&ch->events, event, next);
    }
    if (event->time <= chan_now()) {
        chan_run_events(ch);
    } else {
        chan_arm_event_timer(ch);
    }
}

static ChanEvent *chan_new_event(Sja1000Channel *ch, ChanEventKind kind,
                                 int64_t time)
{
    ChanEvent *event = g_new0(ChanEvent, 1);

    event->kind = kind;
    event->time = time;
    event->epoch = ch->epoch;
    return event;
}

static void chan_drop_events(Sja1000Channel *ch)
{
    ChanEvent *event;

    while ((event = QTAILQ_FIRST(&ch->events))) {
        QTAILQ_REMOVE(&ch->events, event, next);
        g_free(event);
    }
    timer_del(ch->event_timer);
}

/* -- fault confinement ------------------------------------------------------- */

static void chan_enter_reset(Sja1000Channel *ch);

/*
 * Bus-off (DS 6.4.3 note, 6.4.11, 6.4.12): BS set, the chip enters reset
 * mode, TXERR is loaded with 127 to count the bus-free signals of the
 * recovery, RXERR is cleared, and EI is raised. ES stays set until the
 * recovery is over.
 */
static void chan_enter_bus_off(Sja1000Channel *ch)
{
    ch->bus_off = true;
    ch->passive = false;
    ch->tec = TXERR_AT_BUS_OFF;
    ch->rec = 0;
    ch->status |= SR_BS | SR_ES;
    chan_enter_reset(ch);
    chan_raise(ch, IR_EI);
    chan_update_mode(ch);
}

/*
 * Re-evaluates ES and the error-passive state after the counters changed,
 * raising EI on a change of ES and EPI on entering or leaving error
 * passive (DS 6.4.6). In reset mode a CPU-forced change of the counters or
 * of EWLR takes effect only when reset mode ends (DS 6.4.11 note).
 */
static void chan_update_error_state(Sja1000Channel *ch)
{
    bool es;
    bool passive;

    if (ch->bus_off || chan_in_reset(ch)) {
        return;
    }
    if (ch->tec >= FC_BUS_OFF_LIMIT) {
        chan_enter_bus_off(ch);
        return;
    }
    es = ch->tec >= ch->ewlr || ch->rec >= ch->ewlr;
    passive = ch->tec >= FC_PASSIVE_LIMIT || ch->rec >= FC_PASSIVE_LIMIT;
    if (es != !!(ch->status & SR_ES) || ch->deferred_ei) {
        ch->deferred_ei = false;
        ch->status = es ? (ch->status | SR_ES) : (ch->status & ~SR_ES);
        chan_raise(ch, IR_EI);
    }
    if (passive != ch->passive) {
        ch->passive = passive;
        chan_raise(ch, IR_EPI);
    }
    chan_update_mode(ch);
}

/* Listen-only mode stops the error counters (DS 6.4.3). */
static bool chan_counters_frozen(Sja1000Channel *ch)
{
    return chan_listen_only(ch);
}

/* A transmitter's error (ISO 11898-1 fault confinement rules 3 and 4). */
static void chan_count_tx_error(Sja1000Channel *ch, bool ack_error)
{
    if (chan_counters_frozen(ch)) {
        return;
    }
    /*
     * The exception of rule 3: an error-passive transmitter that sees an
     * ACK error and no dominant bit during its passive error flag keeps its
     * count. On the lab bus nobody else signals an error after a missing
     * acknowledge, so the exception applies to every such ACK error.
     */
    if (ack_error && ch->passive) {
        return;
    }
    ch->tec += FC_TX_ERROR_STEP;
    chan_update_error_state(ch);
}

/* A receiver's error (rule 1). */
static void chan_count_rx_error(Sja1000Channel *ch)
{
    if (chan_counters_frozen(ch)) {
        return;
    }
    ch->rec = MIN(ch->rec + FC_RX_ERROR_STEP, FC_COUNTER_MAX);
    chan_update_error_state(ch);
}

/* A frame sent (rule 7) and a frame received (rule 8). */
static void chan_count_tx_success(Sja1000Channel *ch)
{
    if (!chan_counters_frozen(ch) && ch->tec > 0) {
        ch->tec--;
        chan_update_error_state(ch);
    }
}

static void chan_count_rx_success(Sja1000Channel *ch)
{
    if (chan_counters_frozen(ch)) {
        return;
    }
    if (ch->rec > FC_PASSIVE_LIMIT - 1) {
        ch->rec = FC_REC_AFTER_PASSIVE;
    } else if (ch->rec > 0) {
        ch->rec--;
    }
    chan_update_error_state(ch);
}

/* Captures ECC unless it still holds an unread error (DS 6.4.9). */
static void chan_capture_ecc(Sja1000Channel *ch, uint8_t ecc)
{
    if (!ch->ecc_captured) {
        ch->ecc = ecc;
        ch->ecc_captured = true;
    }
    chan_raise(ch, IR_BEI);
}

/* -- transmission ----------------------------------------------------------- */

/* The transmit buffer is released: TBS set, TI (DS 6.4.6). */
static void chan_release_tx(Sja1000Channel *ch, bool complete)
{
    ch->tx_pending = false;
    ch->tx_abort_requested = false;
    ch->status |= SR_TBS;
    if (complete) {
        ch->status |= SR_TCS;
    }
    chan_raise(ch, IR_TI);
}

/* Does an unsuccessful attempt end the request (single shot or AT)? */
static bool chan_tx_final(Sja1000Channel *ch)
{
    return ch->tx_single_shot || ch->tx_abort_requested;
}

static void chan_frame_text(const qemu_can_frame *frame, uint8_t raw_dlc,
                            char *text, size_t size)
{
    bool ext = frame->can_id & QEMU_CAN_EFF_FLAG;
    bool rtr = frame->can_id & QEMU_CAN_RTR_FLAG;
    uint32_t id = frame->can_id & (ext ? QEMU_CAN_EFF_MASK : QEMU_CAN_SFF_MASK);
    size_t used;
    int i;

    used = snprintf(text, size, "%" PRIx32 " %c%c %u ", id, ext ? 'X' : 'S',
                    rtr ? 'R' : 'D', raw_dlc);
    if (rtr || frame->can_dlc == 0) {
        g_strlcat(text, "-", size);
        return;
    }
    for (i = 0; i < frame->can_dlc && used + 3 < size; i++) {
        used += snprintf(text + used, size - used, "%02x", frame->data[i]);
    }
}

/* Decodes the transmit buffer in the current mode (DS 6.4.13, 6.3.7). */
static void chan_decode_tx_buffer(Sja1000Channel *ch)
{
    const uint8_t *buff = ch->core.tx_buff;
    qemu_can_frame *frame = &ch->tx_frame;
    const uint8_t *data;
    int i;

    memset(frame, 0, sizeof(*frame));
    if (chan_pelican(ch)) {
        ch->tx_raw_dlc = buff[0] & FRAME_DLC_MASK;
        if (buff[0] & FRAME_FF) {
            frame->can_id = QEMU_CAN_EFF_FLAG |
                            ((uint32_t)buff[1] << 21) |
                            ((uint32_t)buff[2] << 13) |
                            ((uint32_t)buff[3] << 5) | (buff[4] >> 3);
            data = buff + 5;
        } else {
            frame->can_id = ((uint32_t)buff[1] << 3) | (buff[2] >> 5);
            data = buff + 3;
        }
        if (buff[0] & FRAME_RTR) {
            frame->can_id |= QEMU_CAN_RTR_FLAG;
        }
    } else {
        ch->tx_raw_dlc = buff[1] & FRAME_DLC_MASK;
        frame->can_id = ((uint32_t)buff[0] << 3) | (buff[1] >> 5);
        if (buff[1] & BAS_DESC_RTR) {
            frame->can_id |= QEMU_CAN_RTR_FLAG;
        }
        data = buff + 2;
    }
    /* DLC 9..15 are sent as they are, with eight data bytes (ISO 11898-1). */
    frame->can_dlc = MIN(ch->tx_raw_dlc, 8);
    for (i = 0; i < frame->can_dlc; i++) {
        frame->data[i] = data[i];
    }
}

/* Frame geometry in bits; see GEOM_* above. */
static unsigned geom_data_bits(const qemu_can_frame *frame)
{
    return (frame->can_id & QEMU_CAN_RTR_FLAG) ? 0 : 8 * frame->can_dlc;
}

/* Bit index of the CRC delimiter from SOF, with worst-case stuffing. */
static unsigned geom_crc_delimiter(const qemu_can_frame *frame)
{
    unsigned stuffable = ((frame->can_id & QEMU_CAN_EFF_FLAG) ?
                          GEOM_EXTENDED_BITS : GEOM_STANDARD_BITS) +
                         geom_data_bits(frame);

    return stuffable + (stuffable - 1) / 4;
}

/*
 * The lone bus: a channel without a hub is the only node on its bus, so no
 * frame is ever acknowledged. Each attempt is the frame up to its ACK slot,
 * where the transmitter sees the ACK error, then its error flag, error
 * delimiter and intermission; an error-passive transmitter waits another 8
 * bits (suspend transmission) before the next attempt. In self test mode
 * the transmission succeeds without acknowledge. The times are those the
 * hub computes for a bus with one node (docs/protocols/labbus.md).
 */
static void chan_lone_attempt(Sja1000Channel *ch)
{
    int64_t s = chan_now();
    uint64_t bit = chan_bit_ns(ch);
    unsigned crc_delimiter = geom_crc_delimiter(&ch->tx_frame);
    ChanEvent *event;

    ch->lone_in_attempt = true;
    chan_queue_event(ch, chan_new_event(ch, EV_SOF, s));
    if (chan_self_test(ch)) {
        int64_t eof_end = s + (crc_delimiter + 10) * bit;

        chan_queue_event(ch, chan_new_event(ch, EV_TXOK, eof_end));
        if (ch->tx_self) {
            event = chan_new_event(ch, EV_RX, eof_end);
            event->frame = ch->tx_frame;
            event->raw_dlc = ch->tx_raw_dlc;
            event->flags = EVF_SELF;
            chan_queue_event(ch, event);
        }
        chan_queue_event(ch, chan_new_event(ch, EV_IDLE, eof_end));
        ch->lone_free_at = eof_end + GEOM_INTERMISSION * bit;
        return;
    }
    /* The ACK error is seen at the end of the ACK slot. */
    event = chan_new_event(ch, EV_ERR, s + (crc_delimiter + 2) * bit);
    event->arg = ECC_ERRC_OTHER | ECC_SEG_ACK_SLOT;
    event->flags = EVF_ACK;
    chan_queue_event(ch, event);
    chan_queue_event(ch, chan_new_event(ch, EV_IDLE,
                     s + (crc_delimiter + 2 + GEOM_ERROR_FLAG_BITS +
                          GEOM_ERROR_DELIM_BITS) * bit));
    ch->lone_free_at = s + (crc_delimiter + 2 + GEOM_ERROR_FLAG_BITS +
                            GEOM_ERROR_DELIM_BITS + GEOM_INTERMISSION) * bit;
}

/*
 * Schedules what the lone bus does next for this channel: a bus-free
 * signal after reset mode or during bus-off recovery (one every 11 bit
 * times, as the bus is idle), or the next transmission attempt.
 */
static void chan_lone_next_step(Sja1000Channel *ch)
{
    uint64_t bit = chan_bit_ns(ch);
    int64_t now = chan_now();
    int64_t at;

    switch (ch->mode) {
    case BUS_MODE_WAIT:
        chan_queue_event(ch, chan_new_event(ch, EV_JOIN,
                         now + FC_BUS_FREE_BITS * bit));
        break;
    case BUS_MODE_RECOVER: {
        ChanEvent *event = chan_new_event(ch, EV_BUSFREE,
                                          now + FC_BUS_FREE_BITS * bit);

        event->count = ch->recovery_signals + 1;
        chan_queue_event(ch, event);
        break;
    }
    case BUS_MODE_ON:
        if (ch->tx_pending && !ch->lone_in_attempt &&
            ch->lone_next_attempt < 0) {
            /*
             * The channel sent the last frame on its lone bus: error passive,
             * it suspends transmission for 8 bits after the intermission.
             */
            at = MAX(now, ch->lone_free_at +
                          (ch->passive ? FC_SUSPEND_BITS * bit : 0));
            ch->lone_next_attempt = at;
            chan_queue_event(ch, chan_new_event(ch, EV_LONE_ATTEMPT, at));
        }
        break;
    default:
        break;
    }
}

/*
 * TR, SRR, and the single-shot forms AT+TR, AT+SRR and TR+SRR (DS 6.4.4
 * notes): the request goes to the bus with the time of this register write.
 */
static void chan_request_transmission(Sja1000Channel *ch, bool single_shot,
                                      bool self)
{
    if (chan_in_reset(ch) || ch->tx_pending || chan_listen_only(ch)) {
        /*
         * Nothing is sent in reset mode, while the buffer is locked, or in
         * listen-only mode, where the chip never drives the bus.
         */
        return;
    }
    chan_decode_tx_buffer(ch);
    ch->tx_pending = true;
    ch->tx_single_shot = single_shot;
    ch->tx_self = self;
    ch->tx_abort_requested = false;
    ch->status &= ~(SR_TBS | SR_TCS);
    if (ch->port >= 0) {
        char frame[64];
        char options[16] = "";
        char time_word[24];

        chan_frame_text(&ch->tx_frame, ch->tx_raw_dlc, frame, sizeof(frame));
        if (single_shot) {
            g_strlcat(options, ",once", sizeof(options));
        }
        if (self) {
            g_strlcat(options, ",self", sizeof(options));
        }
        labbus_link_send(ch->link, "TX %d %s %s %s", ch->port,
                         labbus_link_time(ch->link, chan_now(),
                                          time_word, sizeof(time_word)),
                         frame, options[0] ? options + 1 : "-");
    } else {
        chan_lone_next_step(ch);
    }
}

/*
 * AT alone: a request not yet under way is cancelled (TBS set, TCS clear,
 * TI); one on the bus finishes, and is not repeated if it fails (DS 6.4.4).
 */
static void chan_abort_transmission(Sja1000Channel *ch)
{
    if (!ch->tx_pending) {
        return;
    }
    ch->tx_abort_requested = true;
    if (ch->port >= 0) {
        char time_word[24];

        labbus_link_send(ch->link, "ABORT %d %s", ch->port,
                         labbus_link_time(ch->link, chan_now(),
                                          time_word, sizeof(time_word)));
    } else if (!ch->lone_in_attempt) {
        /* Between attempts on the lone bus: nothing is under way. */
        chan_release_tx(ch, false);
    }
}

/* -- reset, sleep ------------------------------------------------------------ */

/*
 * Entering reset mode, by the CPU or by bus-off (DS 6.4.2, Table 8, and
 * DS 6.3.2): the receive FIFO is emptied, a pending transmission is
 * dropped (TBS set, no TI), RS and TS are set, sleep ends.
 */
static void chan_enter_reset(Sja1000Channel *ch)
{
    chan_set_reset_bit(ch, true);
    ch->core.rxmsg_cnt = 0;
    ch->core.rx_cnt = 0;
    ch->core.rxbuf_start = 0;
    ch->core.rx_ptr = 0;
    ch->core.status_pel &= ~SR_CORE_BITS;
    ch->core.status_bas &= ~SR_CORE_BITS;
    ch->core.interrupt_pel &= ~(IR_RI | IR_DOI);
    ch->core.interrupt_bas &= ~(IR_RI | IR_DOI);
    ch->tx_pending = false;
    ch->tx_abort_requested = false;
    ch->status |= SR_TBS | SR_RS | SR_TS;
    ch->sleeping = false;
    ch->joined = false;
    ch->lone_in_attempt = false;
    ch->lone_next_attempt = -1;
    chan_drop_events(ch);
    chan_update_irq(ch);
}

/*
 * Leaving reset mode: the chip waits for one bus-free signal, or for 128
 * after bus-off (DS 6.3.3 note 4), and then takes part in the bus. Counter
 * and EWLR changes made in reset mode take effect now.
 */
static void chan_leave_reset(Sja1000Channel *ch)
{
    chan_set_reset_bit(ch, false);
    ch->joined = false;
    ch->status |= SR_RS | SR_TS;
    chan_update_error_state(ch);
    chan_update_mode(ch);
}

/*
 * MOD.SM / CMR.GTS: the chip sleeps only if the bus is idle and no
 * interrupt is pending; otherwise the request gives a wake-up interrupt
 * (DS 6.4.3, 6.3.4 note 1).
 */
static void chan_request_sleep(Sja1000Channel *ch, bool sleep)
{
    if (sleep == ch->sleeping) {
        return;
    }
    if (!sleep) {
        ch->sleeping = false;
        ch->core.mode &= ~MOD_SM;
        ch->joined = false;
        chan_raise(ch, IR_WUI);
        chan_update_mode(ch);
        return;
    }
    if (chan_in_reset(ch) ||
        (ch->status & (SR_RS | SR_TS)) || ch->tx_pending ||
        (chan_pelican(ch) ?
         (ch->core.interrupt_en & ch->core.interrupt_pel) :
         ((ch->core.control >> 1) & ch->core.interrupt_bas))) {
        ch->core.mode &= ~MOD_SM;
        if (!chan_in_reset(ch)) {
            chan_raise(ch, IR_WUI);
        }
        return;
    }
    ch->sleeping = true;
    ch->core.mode |= MOD_SM;
    chan_update_mode(ch);
}

/* -- bus events --------------------------------------------------------------- */

/*
 * The single acceptance filter's test of a standard frame's identifier and
 * RTR bit (DS 6.4.15, single filter, standard frame): ACR0 and ACR1 bits
 * 7-4 hold ID.10-ID.0 and RTR, AMR0 and AMR1 bits 7-4 mark the bits that
 * do not matter; ACR1 bits 3-0 are unused.
 */
static bool chan_single_filter_id_matches(Sja1000Channel *ch,
                                          const qemu_can_frame *frame)
{
    const uint8_t *acr = ch->core.code_mask;
    const uint8_t *amr = ch->core.code_mask + 4;
    uint16_t code = ((uint16_t)acr[0] << 4) | (acr[1] >> 4);
    uint16_t mask = ((uint16_t)amr[0] << 4) | (amr[1] >> 4);
    uint16_t value = ((frame->can_id & QEMU_CAN_SFF_MASK) << 1) |
                     !!(frame->can_id & QEMU_CAN_RTR_FLAG);

    return !((value ^ code) & ~mask & 0xfff);
}

/*
 * Hands a received frame to the core, keeping the DLC as it was sent.
 *
 * The receive FIFO holds a PeliCAN remote frame's descriptor and no data
 * bytes (DS 6.4.14): the core releases it so (can_sja_mem_write_pel, RRB)
 * but stores DLC bytes of data for it, which would misalign every frame
 * after it. Such a frame is therefore given to the core with no data and
 * its DLC is written back into the stored frame information, as it is for
 * a DLC of 9-15, which the core refuses to store.
 */
static void chan_deliver_frame(Sja1000Channel *ch, const qemu_can_frame *in,
                               uint8_t raw_dlc)
{
    qemu_can_frame stored = *in;
    const qemu_can_frame *frame = &stored;
    uint8_t messages = ch->core.rxmsg_cnt;
    uint32_t start = ch->core.rx_ptr;
    bool single_standard = chan_pelican(ch) && (ch->core.mode & MOD_AFM) &&
                           !(frame->can_id & QEMU_CAN_EFF_FLAG);
    uint8_t saved[2][2] = {
        { ch->core.code_mask[0], ch->core.code_mask[1] },
        { ch->core.code_mask[4], ch->core.code_mask[5] },
    };

    if (!chan_pelican(ch)) {
        /*
         * BasicCAN receives standard frames only, through its 8-bit
         * acceptance filter on ID.10..ID.3 (DS 6.3.9); the core's BasicCAN
         * path applies no filter of its own.
         */
        uint8_t top = (frame->can_id & QEMU_CAN_SFF_MASK) >> 3;

        if ((frame->can_id & QEMU_CAN_EFF_FLAG) ||
            ((top ^ ch->core.code) & ~ch->core.mask)) {
            return;
        }
    }
    if (single_standard) {
        /*
         * The core builds this filter's identifier mask from AMR1 << 5
         * where the layout needs AMR1 >> 5 (can_sja_single_filter), so
         * its mask never covers ID.2-0 and it compares them with ACR1
         * bits 7-5 whatever AMR1 says: "accept all" would drop most
         * frames. The identifier and RTR are matched here instead, and for
         * the call the core's ACR0 and ACR1 hold the frame's own
         * identifier, AMR0 and AMR1 all ones. It still compares the two
         * data bytes with ACR2 and ACR3, which it does right.
         */
        uint32_t id = frame->can_id & QEMU_CAN_SFF_MASK;

        if (!chan_single_filter_id_matches(ch, frame)) {
            return;
        }
        ch->core.code_mask[0] = id >> 3;
        ch->core.code_mask[1] = (id & 7) << 5;
        ch->core.code_mask[4] = 0xff;
        ch->core.code_mask[5] = 0xff;
    }
    if (chan_pelican(ch) && (stored.can_id & QEMU_CAN_RTR_FLAG)) {
        stored.can_dlc = 0;
    }
    can_sja_receive(&ch->core.bus_client, frame, 1);
    if (single_standard) {
        ch->core.code_mask[0] = saved[0][0];
        ch->core.code_mask[1] = saved[0][1];
        ch->core.code_mask[4] = saved[1][0];
        ch->core.code_mask[5] = saved[1][1];
    }
    if (ch->core.rxmsg_cnt != messages && raw_dlc != stored.can_dlc) {
        /* The chip keeps the DLC received. */
        uint32_t at = chan_pelican(ch) ? start : start + 1;

        at %= SJA_RCV_BUF_LEN;
        ch->core.rx_buff[at] = (ch->core.rx_buff[at] & ~FRAME_DLC_MASK) |
                               raw_dlc;
    }
    chan_normalise_rx_interrupts(ch);
}

static void chan_apply_event(Sja1000Channel *ch, ChanEvent *event)
{
    switch (event->kind) {
    case EV_SOF:
        if (event->arg == SOF_WAKE) {
            /*
             * A sleeping chip wakes on bus activity and misses that frame
             * until it has seen a bus-free signal (DS 6.4.4 note 1).
             */
            if (ch->sleeping) {
                chan_request_sleep(ch, false);
            }
        } else if (event->arg == SOF_TX) {
            ch->status |= SR_TS;
            ch->status &= ~SR_RS;
        } else {
            ch->status |= SR_RS;
        }
        break;
    case EV_LOST:
        ch->status &= ~SR_TS;
        ch->status |= SR_RS;
        if (!ch->alc_captured) {
            ch->alc = event->arg;
            ch->alc_captured = true;
        }
        chan_raise(ch, IR_ALI);
        if (ch->tx_pending && chan_tx_final(ch)) {
            chan_release_tx(ch, false);
        }
        break;
    case EV_TXOK:
        ch->status &= ~SR_TS;
        ch->lone_in_attempt = false;
        if (ch->tx_pending) {
            chan_release_tx(ch, true);
        }
        chan_count_tx_success(ch);
        break;
    case EV_RX:
        ch->status &= ~SR_RS;
        chan_deliver_frame(ch, &event->frame, event->raw_dlc);
        if (!(event->flags & EVF_SELF)) {
            chan_count_rx_success(ch);
        }
        break;
    case EV_ERR:
        chan_capture_ecc(ch, event->arg);
        if (event->arg & ECC_DIR_RX) {
            chan_count_rx_error(ch);
        } else {
            bool final = ch->tx_pending && chan_tx_final(ch);

            chan_count_tx_error(ch, event->flags & EVF_ACK);
            /* Bus-off may have dropped the request already. */
            if (final && ch->tx_pending) {
                chan_release_tx(ch, false);
            }
        }
        break;
    case EV_IDLE:
        if (!chan_in_reset(ch)) {
            ch->status &= ~(SR_RS | SR_TS);
        }
        if (ch->port < 0 && ch->lone_in_attempt) {
            ch->lone_in_attempt = false;
            if (ch->tx_pending && ch->tx_abort_requested) {
                chan_release_tx(ch, false);
            } else if (ch->tx_pending && ch->mode == BUS_MODE_ON) {
                uint64_t bit = chan_bit_ns(ch);
                int64_t at = ch->lone_free_at +
                             (ch->passive ? FC_SUSPEND_BITS * bit : 0);

                ch->lone_next_attempt = at;
                chan_queue_event(ch, chan_new_event(ch, EV_LONE_ATTEMPT, at));
            }
        }
        break;
    case EV_ABORTED:
        if (ch->tx_pending) {
            chan_release_tx(ch, false);
        }
        break;
    case EV_JOIN:
        ch->joined = true;
        ch->status &= ~(SR_RS | SR_TS);
        chan_update_mode(ch);
        break;
    case EV_BUSFREE:
        /* TXERR counts the recovery down (DS 6.4.12). */
        ch->recovery_signals = event->count;
        if (ch->recovery_signals >= FC_RECOVERY_SIGNALS) {
            ch->bus_off = false;
            ch->tec = 0;
            ch->rec = 0;
            ch->joined = true;
            ch->status &= ~(SR_BS | SR_ES | SR_RS | SR_TS);
            chan_raise(ch, IR_EI);
            chan_update_mode(ch);
        } else {
            ch->tec = TXERR_AT_BUS_OFF - ch->recovery_signals;
            if (ch->port < 0) {
                chan_lone_next_step(ch);
            }
        }
        break;
    case EV_FAULT:
        if (chan_in_reset(ch)) {
            /* In reset mode the chip takes no part in the bus: nothing to force. */
            break;
        }
        if (event->arg == FAULT_BUS_OFF) {
            if (!ch->bus_off) {
                ch->tec = FC_BUS_OFF_LIMIT;
                chan_enter_bus_off(ch);
            }
        } else if (!ch->bus_off && ch->tec < FC_PASSIVE_LIMIT) {
            ch->tec = FC_PASSIVE_LIMIT;
            chan_update_error_state(ch);
        }
        break;
    case EV_LONE_ATTEMPT:
        if (event->time != ch->lone_next_attempt) {
            /* Superseded: the request it was for has gone. */
            break;
        }
        ch->lone_next_attempt = -1;
        if (ch->tx_pending && ch->mode == BUS_MODE_ON && !ch->lone_in_attempt) {
            if (ch->tx_abort_requested) {
                chan_release_tx(ch, false);
            } else {
                chan_lone_attempt(ch);
            }
        }
        break;
    }
    chan_update_irq(ch);
}

/* -- events from the hub ---------------------------------------------------- */

static G_NORETURN void chan_bad_event(Sja1000Channel *ch, int argc,
                                      char **argv)
{
    labbus_link_fatal(ch->link, "the hub sent a malformed %s event for "
                      "channel %s (%d words)", argv[0], ch->label, argc);
}

static uint64_t chan_event_number(Sja1000Channel *ch, int argc, char **argv,
                                  int index, int base)
{
    const char *end;
    uint64_t value;

    if (index >= argc || qemu_strtou64(argv[index], &end, base, &value) ||
        *end) {
        chan_bad_event(ch, argc, argv);
    }
    return value;
}

/* Parses "<id> <format> <dlc> <data>" from argv[index]. */
static void chan_parse_frame(Sja1000Channel *ch, int argc, char **argv,
                             int index, ChanEvent *event)
{
    uint64_t id = chan_event_number(ch, argc, argv, index, 16);
    uint64_t dlc = chan_event_number(ch, argc, argv, index + 2, 10);
    const char *format = index + 1 < argc ? argv[index + 1] : "";
    const char *data = index + 3 < argc ? argv[index + 3] : "";
    qemu_can_frame *frame = &event->frame;
    int i;

    if (strlen(format) != 2 || (format[0] != 'S' && format[0] != 'X') ||
        (format[1] != 'D' && format[1] != 'R') || dlc > 15 ||
        id > (format[0] == 'X' ? QEMU_CAN_EFF_MASK : QEMU_CAN_SFF_MASK)) {
        chan_bad_event(ch, argc, argv);
    }
    frame->can_id = id;
    if (format[0] == 'X') {
        frame->can_id |= QEMU_CAN_EFF_FLAG;
    }
    if (format[1] == 'R') {
        frame->can_id |= QEMU_CAN_RTR_FLAG;
    }
    event->raw_dlc = dlc;
    frame->can_dlc = MIN(dlc, 8);
    if (format[1] == 'R' || frame->can_dlc == 0) {
        if (strcmp(data, "-")) {
            chan_bad_event(ch, argc, argv);
        }
        return;
    }
    if (strlen(data) != 2u * frame->can_dlc) {
        chan_bad_event(ch, argc, argv);
    }
    for (i = 0; i < frame->can_dlc; i++) {
        char byte[3] = { data[2 * i], data[2 * i + 1], '\0' };
        const char *end;
        unsigned long value;

        if (qemu_strtoul(byte, &end, 16, &value) || *end) {
            chan_bad_event(ch, argc, argv);
        }
        frame->data[i] = value;
    }
}

static bool chan_has_flag(const char *list, const char *flag)
{
    size_t length = strlen(flag);
    const char *cursor = list;

    while ((cursor = strstr(cursor, flag))) {
        if ((cursor == list || cursor[-1] == ',') &&
            (cursor[length] == '\0' || cursor[length] == ',')) {
            return true;
        }
        cursor += length;
    }
    return false;
}

/*
 * "<EVENT> <port> <epoch> <time> [arguments]" (docs/protocols/labbus.md,
 * "Events"): queued for its emulated time; the hub never announces an
 * event before the boundary it sends it at. A real-time link applies it on
 * arrival instead.
 */
static void chan_link_event(void *opaque, int argc, char **argv)
{
    Sja1000Channel *ch = opaque;
    const char *verb = argv[0];
    ChanEvent *event = g_new0(ChanEvent, 1);

    event->epoch = chan_event_number(ch, argc, argv, 2, 10);
    event->time = chan_event_number(ch, argc, argv, 3, 10);
    if (labbus_link_realtime(ch->link)) {
        /*
         * The time is the hub's emulated time, which a real-time machine's
         * clock does not share: the event happens now, as it arrives, and
         * events keep the order the hub sent them in.
         */
        event->time = chan_now();
    }
    if (!strcmp(verb, "SOF") && argc == 5) {
        event->kind = EV_SOF;
        if (!strcmp(argv[4], "tx")) {
            event->arg = SOF_TX;
        } else if (!strcmp(argv[4], "rx")) {
            event->arg = SOF_RX;
        } else if (!strcmp(argv[4], "wake")) {
            event->arg = SOF_WAKE;
        } else {
            chan_bad_event(ch, argc, argv);
        }
    } else if (!strcmp(verb, "LOST") && argc == 6) {
        event->kind = EV_LOST;
        event->arg = chan_event_number(ch, argc, argv, 4, 10) & 0x1f;
    } else if (!strcmp(verb, "TXOK") && argc == 4) {
        event->kind = EV_TXOK;
    } else if (!strcmp(verb, "RX") && argc == 9) {
        event->kind = EV_RX;
        chan_parse_frame(ch, argc, argv, 4, event);
        if (!strcmp(argv[8], "1")) {
            event->flags |= EVF_SELF;
        }
    } else if (!strcmp(verb, "ERR") && argc == 7) {
        event->kind = EV_ERR;
        event->arg = chan_event_number(ch, argc, argv, 5, 16);
        if ((!strcmp(argv[4], "rx")) != !!(event->arg & ECC_DIR_RX)) {
            chan_bad_event(ch, argc, argv);
        }
        if (chan_has_flag(argv[6], "ack")) {
            event->flags |= EVF_ACK;
        }
    } else if (!strcmp(verb, "IDLE") && argc == 4) {
        event->kind = EV_IDLE;
    } else if (!strcmp(verb, "ABORTED") && argc == 4) {
        event->kind = EV_ABORTED;
    } else if (!strcmp(verb, "JOIN") && argc == 4) {
        event->kind = EV_JOIN;
    } else if (!strcmp(verb, "BUSFREE") && argc == 5) {
        event->kind = EV_BUSFREE;
        event->count = MIN(chan_event_number(ch, argc, argv, 4, 10),
                           FC_RECOVERY_SIGNALS);
    } else if (!strcmp(verb, "FAULT") && argc == 5) {
        event->kind = EV_FAULT;
        if (!strcmp(argv[4], "passive")) {
            event->arg = FAULT_PASSIVE;
        } else if (!strcmp(argv[4], "busoff")) {
            event->arg = FAULT_BUS_OFF;
        } else {
            chan_bad_event(ch, argc, argv);
        }
    } else {
        chan_bad_event(ch, argc, argv);
    }
    chan_queue_event(ch, event);
}

/* -- register access ---------------------------------------------------------- */

static uint8_t chan_read_status(Sja1000Channel *ch)
{
    uint8_t core_bits = chan_pelican(ch) ? ch->core.status_pel :
                                           ch->core.status_bas;

    return (core_bits & SR_CORE_BITS) | (ch->status & ~SR_CORE_BITS);
}

uint8_t sja1000_chip_read(Sja1000Channel *ch, unsigned addr)
{
    uint8_t value;

    /* Events due now (a frame that ends at this instant) come first. */
    chan_run_events(ch);
    switch (addr) {
    case SJA_CMR:
        return CMR_READ_VALUE;
    case SJA_SR:
        return chan_read_status(ch);
    case SJA_BTR0:
        return ch->btr0;
    case SJA_BTR1:
        return ch->btr1;
    case SJA_OCR_ADDR:
        return ch->ocr;
    case SJA_CDR:
        return ch->core.clock;
    default:
        break;
    }
    if (!chan_pelican(ch)) {
        value = can_sja_mem_read(&ch->core, addr, 1);
        if (addr == SJA_BCAN_IR) {
            chan_normalise_rx_interrupts(ch);
        }
        return value;
    }
    switch (addr) {
    case SJA_ALC:
        /* Reading ALC lets the next lost arbitration be captured. */
        ch->alc_captured = false;
        return ch->alc;
    case SJA_ECC:
        ch->ecc_captured = false;
        return ch->ecc;
    case SJA_EWLR:
        return ch->ewlr;
    case SJA_PEL_RXERR:
        return ch->rec;
    case SJA_PEL_TXERR:
        /* In bus-off TXERR counts the recovery; 256 never shows. */
        return MIN(ch->tec, FC_COUNTER_MAX);
    case SJA_RMC:
        return ch->core.rxmsg_cnt;
    case SJA_RBSA:
        return ch->core.rxbuf_start;
    default:
        value = can_sja_mem_read(&ch->core, addr, 1);
        if (addr == SJA_IR) {
            chan_normalise_rx_interrupts(ch);
        }
        return value;
    }
}

/* A write to MOD (DS 6.4.3): LOM, STM and AFM only in reset mode, SM only
 * in operating mode. */
static void chan_write_mode(Sja1000Channel *ch, uint8_t value)
{
    bool was_reset = chan_in_reset(ch);
    uint8_t mode = ch->core.mode;

    value &= MOD_WRITABLE;
    if (was_reset) {
        mode = (mode & ~(MOD_LOM | MOD_STM | MOD_AFM)) |
               (value & (MOD_LOM | MOD_STM | MOD_AFM));
    }
    /* The core stores the result (its only action on MOD). */
    can_sja_mem_write(&ch->core, SJA_MOD, mode, 1);
    if (!was_reset && (value & MOD_RM)) {
        chan_enter_reset(ch);
        chan_update_mode(ch);
    } else if (was_reset && !(value & MOD_RM)) {
        chan_leave_reset(ch);
        if (value & MOD_SM) {
            /* Sleep cannot be entered before a bus-free signal. */
            chan_request_sleep(ch, true);
        }
    } else if (!was_reset) {
        chan_request_sleep(ch, value & MOD_SM);
    } else {
        chan_update_mode(ch);
    }
}

/* BasicCAN CR (DS 6.3.3): RR and the four interrupt enables. */
static void chan_write_control(Sja1000Channel *ch, uint8_t value)
{
    bool was_reset = chan_in_reset(ch);

    /*
     * The core's CR write treats a write with RR clear in operating mode
     * as a software reset; the chip only changes the enables then, so the
     * register is written here.
     */
    ch->core.control = (value & (CR_RR | CR_RIE | CR_TIE | CR_EIE | CR_OIE));
    if (!was_reset && (value & CR_RR)) {
        chan_enter_reset(ch);
        chan_update_mode(ch);
    } else if (was_reset && !(value & CR_RR)) {
        chan_leave_reset(ch);
    }
    chan_normalise_rx_interrupts(ch);
}

/*
 * RRB and CDO go to the core. The core releases a frame of DLC 9-15 as if
 * it held that many data bytes, where it stored 8: for that one release
 * the frame's stored DLC reads 8, and the frame is gone after it.
 */
static void chan_release_receive_buffer(Sja1000Channel *ch, uint8_t command)
{
    uint32_t at = ch->core.rxbuf_start;

    if (!chan_pelican(ch)) {
        at++;
    }
    at %= SJA_RCV_BUF_LEN;
    if ((command & CMR_RRB) && ch->core.rxmsg_cnt > 0 &&
        (ch->core.rx_buff[at] & FRAME_DLC_MASK) > 8) {
        ch->core.rx_buff[at] = (ch->core.rx_buff[at] & ~FRAME_DLC_MASK) | 8;
    }
    can_sja_mem_write(&ch->core, SJA_CMR, command, 1);
}

static void chan_write_command(Sja1000Channel *ch, uint8_t value)
{
    bool pelican = chan_pelican(ch);

    if (pelican && (value & (CMR_TR | CMR_SRR))) {
        /*
         * AT with TR or SRR, and TR with SRR, send once (DS 6.4.4 notes);
         * SRR receives the frame itself.
         */
        bool single = (value & CMR_AT) ||
                      ((value & CMR_TR) && (value & CMR_SRR));

        chan_request_transmission(ch, single,
                                  (value & CMR_SRR) && !(value & CMR_TR));
    } else if (!pelican && (value & CMR_TR)) {
        chan_request_transmission(ch, value & CMR_AT, false);
    } else if (value & CMR_AT) {
        chan_abort_transmission(ch);
    }
    if (!pelican && (value & CMR_GTS)) {
        chan_request_sleep(ch, true);
    } else if (!pelican && ch->sleeping) {
        /* GTS cleared: wake up (DS 6.3.4 note 1). */
        chan_request_sleep(ch, false);
    }
    /* The core releases the receive buffer and clears the overrun. */
    if (value & (CMR_RRB | CMR_CDO)) {
        chan_release_receive_buffer(ch, value & (CMR_RRB | CMR_CDO));
        chan_normalise_rx_interrupts(ch);
    }
}

void sja1000_chip_write(Sja1000Channel *ch, unsigned addr, uint8_t value)
{
    bool reset = chan_in_reset(ch);
    bool pelican = chan_pelican(ch);

    chan_run_events(ch);
    switch (addr) {
    case SJA_CMR:
        chan_write_command(ch, value);
        return;
    case SJA_SR:
    case SJA_IR:
        return;
    case SJA_BTR0:
    case SJA_BTR1:
    case SJA_OCR_ADDR:
        /* Written in reset mode only, read only otherwise (DS 6.5). */
        if (reset) {
            if (addr == SJA_BTR0) {
                ch->btr0 = value;
            } else if (addr == SJA_BTR1) {
                ch->btr1 = value;
            } else {
                ch->ocr = value;
            }
            chan_update_mode(ch);
        }
        return;
    case SJA_CDR:
        if (!reset) {
            value = (value & ~CDR_RESET_ONLY_BITS) |
                    (ch->core.clock & CDR_RESET_ONLY_BITS);
        }
        can_sja_mem_write(&ch->core, SJA_CDR, value, 1);
        chan_normalise_rx_interrupts(ch);
        chan_update_mode(ch);
        return;
    default:
        break;
    }
    if (!pelican) {
        switch (addr) {
        case SJA_BCAN_CTR:
            chan_write_control(ch, value);
            return;
        case SJA_BAS_ACR:
        case SJA_BAS_AMR:
            /* The acceptance filter is programmed in reset mode (DS 6.3.9). */
            if (reset) {
                can_sja_mem_write(&ch->core, addr, value, 1);
            }
            return;
        case SJA_BAS_TXB_FIRST ... SJA_BAS_TXB_LAST:
            /* A locked buffer loses the byte (DS 6.3.5 note 5). */
            if (!reset && !ch->tx_pending) {
                can_sja_mem_write(&ch->core, addr, value, 1);
            }
            return;
        default:
            return;
        }
    }
    switch (addr) {
    case SJA_MOD:
        chan_write_mode(ch, value);
        return;
    case SJA_IER:
        can_sja_mem_write(&ch->core, addr, value, 1);
        chan_normalise_rx_interrupts(ch);
        return;
    case SJA_EWLR:
        if (reset) {
            ch->ewlr = value;
        }
        return;
    case SJA_PEL_RXERR:
        /* Reset mode only; no effect while bus-off (DS 6.4.11). */
        if (reset && !ch->bus_off) {
            ch->rec = value;
        }
        return;
    case SJA_PEL_TXERR:
        if (!reset) {
            return;
        }
        if (value == TXERR_FORCE_BUS_OFF) {
            /* A CPU-driven bus-off event (DS 6.4.12). */
            if (!ch->bus_off) {
                chan_enter_bus_off(ch);
            }
        } else {
            if (ch->bus_off) {
                /*
                 * 0..254 in bus-off clears BS; the chip then waits for one
                 * bus-free signal once reset mode ends (DS 6.4.12).
                 */
                ch->bus_off = false;
                ch->status &= ~SR_BS;
                ch->deferred_ei = true;
            }
            ch->tec = value;
        }
        return;
    case SJA_RBSA:
        /* RBSA is writable in reset mode, where the FIFO is empty. */
        if (reset) {
            ch->core.rxbuf_start = value % SJA_RCV_BUF_LEN;
            ch->core.rx_ptr = ch->core.rxbuf_start;
        }
        return;
    case SJA_PEL_FRAME_FIRST ... SJA_PEL_FRAME_LAST:
        if (!reset && ch->tx_pending) {
            /* A locked transmit buffer loses the byte (DS 6.4.5 note). */
            return;
        }
        can_sja_mem_write(&ch->core, addr, value, 1);
        return;
    default:
        /* ALC, ECC, RMC, the test and reserved registers ignore writes. */
        return;
    }
}

/* -- life cycle ----------------------------------------------------------------- */

/*
 * Hardware reset of one chip (DS 6.3.2 and 6.4.2, Tables 3 and 8): the
 * core's registers, this file's counters and captures, EWLR 96, no
 * request; BTR0, BTR1 and OCR keep their contents as on the chip, where a
 * hardware reset leaves them undefined.
 */
void sja1000_chip_hardware_reset(Sja1000Channel *ch)
{
    can_sja_hardware_reset(&ch->core);
    /*
     * The core's reset empties the receive FIFO (RMC 0, RBSA 0) but leaves
     * its write position where the last frame ended: the next frame would
     * land there while the CPU reads from RBSA 0, a frame's bytes read from
     * the wrong place after every restart of the board. A chip's FIFO
     * starts empty at address 0 (DS 6.4.17, RBSA after a hardware reset).
     */
    ch->core.rx_ptr = 0;
    chan_drop_events(ch);
    ch->alc = 0;
    ch->ecc = 0;
    ch->alc_captured = false;
    ch->ecc_captured = false;
    ch->ewlr = EWLR_RESET_VALUE;
    ch->tec = 0;
    ch->rec = 0;
    ch->status = SR_TBS | SR_TCS | SR_RS | SR_TS;
    ch->bus_off = false;
    ch->passive = false;
    ch->deferred_ei = false;
    ch->joined = false;
    ch->sleeping = false;
    ch->recovery_signals = 0;
    ch->tx_pending = false;
    ch->tx_abort_requested = false;
    ch->lone_free_at = 0;
    ch->lone_in_attempt = false;
    ch->lone_next_attempt = -1;
    chan_set_reset_bit(ch, true);
    chan_update_irq(ch);
    chan_update_mode(ch);
}

void sja1000_chip_init(Sja1000Channel *ch, qemu_irq irq, LabBusLink *link)
{
    ch->link = link;
    ch->port = -1;
    ch->lone_next_attempt = -1;
    QTAILQ_INIT(&ch->events);
    ch->event_timer = timer_new_ns(QEMU_CLOCK_VIRTUAL, chan_event_timer_cb,
                                   ch);
    can_sja_init(&ch->core, irq);
}

bool sja1000_chip_attach(Sja1000Channel *ch, const char *bus,
                         const char *label, Error **errp)
{
    g_assert(ch->link);
    g_strlcpy(ch->label, label, sizeof(ch->label));
    ch->port = labbus_link_attach(ch->link, bus, ch->label, chan_link_event,
                                  ch, errp);
    return ch->port >= 0;
}

bool sja1000_card_join_hub(Object *card, const char *device,
                           char *const *bus_names, unsigned chips,
                           const LabBusLinkConfig *config, LabBusLink **link,
                           Error **errp)
{
    bool hub = config->path && *config->path;
    unsigned i;

    *link = NULL;
    for (i = 0; i < chips; i++) {
        if (bus_names[i] && *bus_names[i] && !hub) {
            error_setg(errp, "%s: bus%u=%s needs hub=<socket of the lab bus "
                       "hub>", device, i, bus_names[i]);
            return false;
        }
    }
    if (hub) {
        *link = labbus_board_link_join(card, config, errp);
        return *link != NULL;
    }
    return true;
}

bool sja1000_card_chip_start(Sja1000Channel *ch, unsigned index, qemu_irq irq,
                             LabBusLink *link, const char *bus, Error **errp)
{
    char label[8];

    sja1000_chip_init(ch, irq, link);
    if (!bus || !*bus) {
        return true;
    }
    snprintf(label, sizeof(label), "%u", index);
    return sja1000_chip_attach(ch, bus, label, errp);
}

void sja1000_chip_teardown(Sja1000Channel *ch)
{
    chan_drop_events(ch);
    timer_free(ch->event_timer);
    ch->event_timer = NULL;
}
