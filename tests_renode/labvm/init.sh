#!/bin/sh
# /init of the lab VM: PID 1 in the initramfs, run by busybox's sh.
#
# 1. loads the kernel modules named in /labvm/config.sh (9p first, then CAN);
# 2. mounts the host's root read-only over 9p on /host, with fresh /proc,
#    /sys, /dev, /dev/pts, /dev/shm and tmpfs on /tmp, /run and /var/tmp,
#    and this run's files (/labvm) on /host/run/labvm;
# 3. runs /labvm/setup.sh (vcan, slcan, ...) in a chroot of /host, with -e -x;
# 4. runs /labvm/command.sh in that chroot and prints its output between
#       @@LABVM-BEGIN <nonce>@@\n   and   \n@@LABVM-END <nonce> status=<n>@@
#    (a command killed after LABVM_TIMEOUT seconds reports " timed-out");
# 5. powers the machine off, which ends QEMU.
# A failing step prints "@@LABVM-SETUP-FAILED <nonce>@@ <what>" and the
# kernel log, then powers off. The host side (vm.py) parses these markers.

export PATH=/sbin:/bin:/usr/sbin:/usr/bin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev

# shellcheck source=/dev/null # written per run by vm.py
. /labvm/config.sh

power_off() {
    sync
    # The console's last lines (the command's end marker among them) may
    # still sit in the serial driver's buffer: poweroff -f would drop them,
    # and the host would see the VM end without a result. A busy host
    # drains the emulated UART slowly, so give it a second.
    sleep 1
    poweroff -f
    sleep 10
    echo o >/proc/sysrq-trigger
}

fail() {
    echo "@@LABVM-SETUP-FAILED $LABVM_NONCE@@ $*"
    echo "----- kernel log (last 40 lines) -----"
    dmesg | tail -n 40
    power_off
}

if [ "$LABVM_MODE" = batch ]; then
    # Exact bytes: no CR inserted before LF in the command's output.
    stty -F /dev/console -onlcr 2>/dev/null
fi
hostname labvm
echo "labvm: kernel $(uname -r) up after $(cut -d' ' -f1 /proc/uptime) s"

# The kernel's on-demand module loading runs this busybox modprobe, in the
# initramfs, whatever the chroot holds.
echo /sbin/modprobe >/proc/sys/kernel/modprobe
while read -r line; do
    [ -n "$line" ] || continue
    # shellcheck disable=SC2086 # a module name and its options
    modprobe $line || fail "modprobe $line failed"
done <<EOF
$LABVM_LOAD
EOF

mount -t 9p -o "trans=virtio,version=9p2000.L,ro,msize=512000,cache=$LABVM_9P_CACHE" hostroot /host \
    || fail "cannot mount the host's root over 9p (mount_tag hostroot)"
mount -t proc proc /host/proc || fail "cannot mount /proc in the chroot"
mount -t sysfs sysfs /host/sys || fail "cannot mount /sys in the chroot"
mount -t devtmpfs devtmpfs /host/dev || fail "cannot mount /dev in the chroot"
mkdir -p /host/dev/pts /host/dev/shm
mount -t devpts -o gid=5,mode=620,ptmxmode=666 devpts /host/dev/pts || fail "cannot mount /dev/pts"
mount -t tmpfs -o mode=1777 tmpfs /host/dev/shm || fail "cannot mount /dev/shm"
for directory in tmp var/tmp; do
    if [ -d "/host/$directory" ]; then
        mount -t tmpfs -o mode=1777 tmpfs "/host/$directory" || fail "cannot mount a tmpfs on /$directory"
    fi
done
[ -d /host/run ] || fail "the host has no /run to mount this run's files under"
mount -t tmpfs -o mode=755 tmpfs /host/run || fail "cannot mount a tmpfs on /run"
mkdir -p /host/run/labvm
mount --bind /labvm /host/run/labvm || fail "cannot bind this run's files to /run/labvm"

in_chroot() {
    env -i PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin HOME=/tmp LANG=C.UTF-8 \
        TERM="$LABVM_TERM" PYTHONDONTWRITEBYTECODE=1 LABVM=1 chroot /host "$@"
}

if [ -s /labvm/setup.sh ]; then
    echo "labvm: setup"
    in_chroot /bin/sh -e -x /run/labvm/setup.sh </dev/null || fail "the setup (/run/labvm/setup.sh) failed"
fi
echo "labvm: ready after $(cut -d' ' -f1 /proc/uptime) s"

if [ "$LABVM_MODE" = shell ]; then
    # Interactive: the console is the command's terminal, with job control.
    setsid cttyhack env -i PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin HOME=/tmp \
        LANG=C.UTF-8 TERM="$LABVM_TERM" LABVM=1 chroot /host /bin/sh /run/labvm/command.sh
    status=$?
    echo "labvm: the shell ended with status $status; powering off"
    power_off
fi

echo "@@LABVM-BEGIN $LABVM_NONCE@@"
rm -f /tmp/timed-out
in_chroot /bin/sh /run/labvm/command.sh </dev/null &
command_pid=$!
(sleep "$LABVM_TIMEOUT" && touch /tmp/timed-out && kill -KILL "$command_pid") 2>/dev/null &
watchdog_pid=$!
wait "$command_pid"
status=$?
kill "$watchdog_pid" 2>/dev/null
timed_out=""
[ -e /tmp/timed-out ] && timed_out=" timed-out"
printf '\n@@LABVM-END %s status=%s%s@@\n' "$LABVM_NONCE" "$status" "$timed_out"
if [ "$status" != 0 ]; then
    echo "----- kernel log (last 30 lines) -----"
    dmesg | tail -n 30
fi
power_off
