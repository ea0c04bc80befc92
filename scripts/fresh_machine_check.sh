#!/usr/bin/env bash
# The README's promise on a truly fresh Debian 12 (docs/reliability.md): makes a minimal root with debootstrap
# (variant minbase: no compiler, no cmake, no git, no zlib headers), puts a clean clone of this repository's HEAD
# in it and runs the README's test command there, `bash scripts/setup.sh test`, which must install everything it
# needs, build and pass. Run it as root, before every change to scripts/setup.sh or its package list.
#   scripts/fresh_machine_check.sh [ROOT]     (default /tmp/surge-fresh-root; removed first, kept after)
# Needs debootstrap and git on this machine and Debian's mirror (deb.debian.org) on the network.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
root="${1:-/tmp/surge-fresh-root}"
mirror="${SURGE_DEBIAN_MIRROR:-http://deb.debian.org/debian}"
[ "$(id -u)" -eq 0 ] || { echo "fresh_machine_check: run as root (debootstrap and chroot need it)" >&2; exit 2; }
command -v debootstrap >/dev/null || { echo "fresh_machine_check: apt-get install debootstrap" >&2; exit 2; }

unmount() {
  for m in dev/shm dev/pts dev proc sys; do
    mountpoint -q "$root/$m" 2>/dev/null && umount -l "$root/$m" || true
  done
}
trap unmount EXIT
unmount
rm -rf "$root"

start=$(date +%s)
debootstrap --variant=minbase bookworm "$root" "$mirror" >"$root.debootstrap.log" 2>&1 ||
  { tail -20 "$root.debootstrap.log"; exit 1; }
made=$(date +%s)
echo "fresh_machine_check: minbase root in $((made - start)) s"

# What a booted machine has and a bare root lacks: /proc, /sys with its cgroup filesystem (slurmd needs it),
# /dev, a resolver, and an /etc/hosts naming localhost and the machine (the installer writes one; slurmd
# resolves the machine's name).
mount -t proc proc "$root/proc"
mount --rbind /sys "$root/sys"
mount --make-rslave "$root/sys"
mount --bind /dev "$root/dev"
mount --bind /dev/pts "$root/dev/pts"
mount -t tmpfs tmpfs "$root/dev/shm"
cp /etc/resolv.conf "$root/etc/resolv.conf"
printf '127.0.0.1\tlocalhost %s\n::1\tlocalhost ip6-localhost ip6-loopback\n' "$(hostname)" >"$root/etc/hosts"
# A clean clone of what is committed, as a newcomer would have it (git is not in the root: cloned from here).
git clone -q "$here" "$root/root/surge"

set +e
chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
  TERM=dumb LANG=C.UTF-8 /bin/bash -c "cd /root/surge && bash scripts/setup.sh test" 2>&1 |
  tee "$root.test.log" | grep -E "surge setup|tests passed|tests failed|Total Test time"
status=${PIPESTATUS[0]}
set -e
end=$(date +%s)
echo "fresh_machine_check: scripts/setup.sh test exited $status after $((end - made)) s (in all $((end - start)) s);" \
  "log in $root.test.log"
exit "$status"
