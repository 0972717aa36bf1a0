#!/bin/sh
# Fetches a Debian source package once and links its tree as <dest>/tree:
#
#   mk/fetch-debian-source.sh <package> <dest>
#
# Enables deb-src in the machine's apt sources if the source index is
# missing (root or sudo needed then), runs apt-get source in <dest>, and
# leaves <dest>/tree pointing at the unpacked tree. With <dest>/tree in
# place it does nothing. Used for mbedTLS (mk/mbedtls.mk), which the
# firmware is built with from Debian's own source.
set -eu

[ $# -eq 2 ] || { echo "usage: $0 <package> <dest>" >&2; exit 2; }
package=$1
dest=$2
apt_sources=/etc/apt/sources.list.d/debian.sources

say() { echo "fetch-debian-source: $*" >&2; }
fail() { echo "fetch-debian-source: error: $*" >&2; exit 1; }

[ -d "$dest/tree" ] && exit 0

as_root() {
    if [ "$(id -u)" -eq 0 ]; then
        "$@"
    elif command -v sudo >/dev/null 2>&1; then
        sudo "$@"
    else
        fail "this step needs root and there is no sudo: $*"
    fi
}

mkdir -p "$dest"
# One fetch at a time: parallel make runs in the same tree wait here.
exec 9>"$dest/.lock"
flock -w 600 9 || fail "another fetch held $dest/.lock for 10 minutes"
[ -d "$dest/tree" ] && exit 0

if [ -z "$(apt-cache showsrc "$package" 2>/dev/null | head -n 1)" ]; then
    [ -f "$apt_sources" ] || fail "no source package index and no $apt_sources to enable deb-src in; \
add 'deb-src' to your apt sources, run 'apt-get update' and try again"
    if ! grep -q '^Types:.*deb-src' "$apt_sources"; then
        say "enabling source packages (deb-src) in $apt_sources"
        as_root sed -i 's/^Types: *deb *$/Types: deb deb-src/' "$apt_sources"
    fi
    say "refreshing the package lists for the source index"
    as_root apt-get update -q
fi
say "fetching Debian's $package source (apt-get source $package) into $dest"
(cd "$dest" && apt-get source -q "$package") >"$dest/apt-get-source.log" 2>&1 || {
    tail -n 20 "$dest/apt-get-source.log" >&2
    fail "apt-get source $package failed (log: $dest/apt-get-source.log)"
}
for candidate in "$dest"/"$package"-*; do
    if [ -d "$candidate" ]; then
        ln -sfn "$(basename "$candidate")" "$dest/tree"
        say "source: $candidate"
        exit 0
    fi
done
fail "apt-get source $package left no $package-<version>/ folder in $dest"
