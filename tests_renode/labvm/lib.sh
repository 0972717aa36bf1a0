# Shell helpers for commands run in the lab VM: `. /run/labvm/lib.sh`.
# (Every run carries this file; it runs under the host's /bin/sh, dash.
# Under TCG every process start costs a good fraction of a second, so the
# loops here use shell builtins where they can.)

# labvm_uptime: prints the VM's uptime in whole seconds (no process started).
labvm_uptime() {
    read -r _uptime _idle </proc/uptime
    echo "${_uptime%.*}"
}

# labvm_wait_receiver DEVICE IDENT [CAN_ID [SECONDS]]
#   Waits (10 s unless SECONDS is given) until a CAN socket of kind IDENT
#   ("raw" for candump and python-can, "isotp", ...) receives on DEVICE, and,
#   if CAN_ID is given (hex, e.g. 7e0, or "" for any), for that id. Use it
#   between starting a receiver in the background and sending, instead of a
#   sleep. Returns 1, with the receive lists on stderr, on time-out.
labvm_wait_receiver() {
    labvm_wait_receivers "$1" "$2" "${3:-}" 1 "${4:-10}"
}

# labvm_count_receivers DEVICE IDENT [CAN_ID]
#   Prints how many CAN sockets of kind IDENT receive on DEVICE (for CAN_ID).
labvm_count_receivers() {
    _device=$1 _ident=$2 _id=${3:-[0-9a-fA-F]+}
    grep -Eich "^ +$_device +0*$_id +[0-9a-f]+ +[0-9a-f]+ +[0-9a-f]+ +[0-9]+ +$_ident\$" \
        /proc/net/can/rcvlist_* | { _sum=0; while read -r _n; do _sum=$((_sum + _n)); done; echo $_sum; }
}

# labvm_wait_receivers DEVICE IDENT CAN_ID COUNT [SECONDS]
#   As labvm_wait_receiver, until at least COUNT such sockets receive: for a
#   new receiver where others of its kind listen already, wait for one more
#   than labvm_count_receivers printed before it started.
labvm_wait_receivers() {
    _deadline=$(( $(labvm_uptime) + ${5:-10} ))
    while [ "$(labvm_count_receivers "$1" "$2" "$3")" -lt "$4" ]; do
        if [ "$(labvm_uptime)" -ge "$_deadline" ]; then
            echo "labvm_wait_receivers: fewer than $4 '$2' receivers on $1${3:+ for id $3} after ${5:-10} s" >&2
            cat /proc/net/can/rcvlist_* >&2
            return 1
        fi
        sleep 0.05
    done
}
