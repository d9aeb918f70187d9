#!/bin/sh
# Faults lose nothing: a bake killed at any point leaves the previous pack
# intact and verifiable; SIGINT and SIGTERM remove the temporary files; a
# full disk, an unwritable parent or an output that is a file give a clear
# error, exit 1, no partial pack and no temporary files.
# Usage: test_faults.sh SKYBAKE SOURCE_ROOT
set -u
skybake=$1
root=$2
. "$root/tests/cli_lib.sh"
export SKYBAKE_VALIDATE=1
chmod 755 "$tmp" # the unprivileged user below reads the scenes here

# The previous pack, and a scene whose pack would differ from it.
printf '{"atmosphere":{"preset":"earth"},"products":["irradiance_ground"]}' >"$tmp/old.json"
printf '{"atmosphere":{"preset":"earth","mie_g":0.7},"products":["irradiance_ground"]}' >"$tmp/new.json"
# A bake long enough for the signals below to land in it (5 to 6 s on
# lavapipe; irradiance_ground alone now takes less than their 1.5 s).
printf '{"atmosphere":{"preset":"earth","mie_g":0.7},"products":["irradiance_sky"]}' >"$tmp/slow.json"
check "the previous pack" expect_exit 0 "$skybake" bake "$tmp/old.json" -o "$tmp/old" -q
cp -r "$tmp/old" "$tmp/reference"
old_manifest=$(cat "$tmp/old/manifest.json")

temporaries() { ls -d "$tmp"/pack.tmp-* 2>/dev/null; }
reset_pack() { rm -rf "$tmp/pack" "$tmp"/pack.tmp-*; cp -r "$tmp/reference" "$tmp/pack"; }

# SIGKILL at each point of publishing (a fault hook in formats/pack.c).
for point in artifact manifest publish published; do
    reset_pack
    check "killed at '$point'" expect_exit 137 env SKYBAKE_FAULT=$point "$skybake" bake "$tmp/new.json" -o "$tmp/pack" --force -q
    check "after a kill at '$point' the pack verifies" expect_exit 0 "$skybake" verify "$tmp/pack"
    if [ $point = published ]; then
        check "killed after the rename: the new pack is in place" test "$(cat "$tmp/pack/manifest.json")" != "$old_manifest"
    else
        check "killed at '$point': the previous pack is untouched" test "$(cat "$tmp/pack/manifest.json")" = "$old_manifest"
        check "killed at '$point': its files too" expect_exit 0 "$skybake" diff "$tmp/pack" "$tmp/reference"
    fi
    check "a kill leaves its temporary directory" test -n "$(temporaries)"
    check "the next bake after a kill at '$point'" expect_exit 0 "$skybake" bake "$tmp/old.json" -o "$tmp/pack" -q
    check "removes what the killed bake left" test -z "$(temporaries)"
done

# SIGKILL, SIGTERM and SIGINT at moments of a real bake.
stop_after() { # signal seconds: bake into $tmp/pack, send the signal after that long; echo the exit code
    "$skybake" bake "$tmp/slow.json" -o "$tmp/pack" --force -q 2>"$tmp/err" &
    pid=$!
    sleep "$2"
    kill -s "$1" $pid 2>/dev/null
    wait $pid
    echo $?
}
# A kill that lands between the rename and the exit is a 137 with the new
# pack in place: either pack is right, as long as it is whole.
check "the slow bake, whole" expect_exit 0 "$skybake" bake "$tmp/slow.json" -o "$tmp/slow" -q
is_old_or_new() {
    [ "$(cat "$tmp/pack/manifest.json")" = "$old_manifest" ] ||
        "$skybake" diff "$tmp/pack" "$tmp/slow" --tol 0 >/dev/null 2>&1
}
for at in 0.3 2 5; do
    reset_pack
    code=$(stop_after KILL $at)
    check "SIGKILL after ${at} s ends the bake ($code)" test "$code" = 137 -o "$code" = 0
    check "after SIGKILL at ${at} s the pack verifies" expect_exit 0 "$skybake" verify "$tmp/pack"
    check "after SIGKILL at ${at} s it is the previous pack or the whole new one" is_old_or_new
done
for sig in TERM INT HUP; do
    reset_pack
    code=$(stop_after $sig 1.5)
    check "SIG$sig ends the bake as the signal does ($code)" test "$code" -gt 128
    check "SIG$sig leaves no temporary files" test -z "$(temporaries)"
    check "after SIG$sig the previous pack is untouched" test "$(cat "$tmp/pack/manifest.json")" = "$old_manifest"
    check "after SIG$sig the pack verifies" expect_exit 0 "$skybake" verify "$tmp/pack"
done

# A full disk: a file size limit makes the writes fail (EFBIG).
reset_pack
check "a full disk is exit 1" expect_exit 1 sh -c 'ulimit -f 64 && exec "$@"' sh "$skybake" bake "$tmp/new.json" -o "$tmp/pack" --force
check "a full disk is named" grep -qi "file too large" "$tmp/err"
check "a full disk leaves no temporary files" test -z "$(temporaries)"
check "a full disk leaves the previous pack" test "$(cat "$tmp/pack/manifest.json")" = "$old_manifest"
check "a full disk: the pack verifies" expect_exit 0 "$skybake" verify "$tmp/pack"
rm -rf "$tmp/fresh"
check "a full disk with no previous pack is exit 1" expect_exit 1 sh -c 'ulimit -f 64 && exec "$@"' sh "$skybake" bake "$tmp/new.json" -o "$tmp/fresh"
check "and leaves no pack" test ! -e "$tmp/fresh"
check "and no temporary files" test -z "$(ls -d "$tmp"/fresh.tmp-* 2>/dev/null)"
# The same for a volume (OpenVDB's bytes go through write(2), so the reason
# survives): cloud_detail's file is larger than the limit.
printf '{"atmosphere":{"preset":"earth"},"products":["cloud_detail"]}' >"$tmp/volume.json"
check "a full disk under a volume is exit 1" expect_exit 1 sh -c 'ulimit -f 64 && exec "$@"' sh "$skybake" bake "$tmp/volume.json" -o "$tmp/fresh"
check "and names the reason and the VDB file" grep -Eqi "cloud_detail.vdb.*file too large" "$tmp/err"
check "and leaves no pack" test ! -e "$tmp/fresh"
check "and no temporary files" test -z "$(ls -d "$tmp"/fresh.tmp-* 2>/dev/null)"
# OpenVDB writes in its helper program: without it, the volume's file and
# the helper are named, and nothing is left.
mkdir -p "$tmp/no-helpers"
check "a volume without skybake-vdb is exit 1" expect_exit 1 env SKYBAKE_LIBEXEC_DIR="$tmp/no-helpers" "$skybake" bake "$tmp/volume.json" -o "$tmp/fresh"
check "and names the helper" grep -q "cannot find the helper program skybake-vdb" "$tmp/err"
check "and the VDB file" grep -q "cloud_detail.vdb: OpenVDB's process could not start writing the volume" "$tmp/err"
check "and leaves no pack" test ! -e "$tmp/fresh"
check "and no temporary files" test -z "$(ls -d "$tmp"/fresh.tmp-* 2>/dev/null)"

# An unwritable parent (as an unprivileged user when run as root, since
# root writes anywhere), a parent on a read-only file system, an output
# that is a file.
mkdir "$tmp/ro" && chmod 555 "$tmp/ro"
if [ "$(id -u)" = 0 ]; then
    as_user="setpriv --reuid=65534 --regid=65534 --clear-groups"
else
    as_user=""
fi
check "an unwritable parent is exit 1" expect_exit 1 env HOME="$tmp" $as_user "$skybake" bake "$tmp/old.json" -o "$tmp/ro/pack"
check "an unwritable parent is named" grep -q "$tmp/ro: cannot create a temporary directory" "$tmp/err"
check "and nothing is written there" test -z "$(ls -A "$tmp/ro")"
check "a read-only file system is exit 1" expect_exit 1 "$skybake" bake "$tmp/old.json" -o /proc/skybake-pack
check "a read-only file system is named" grep -q "/proc" "$tmp/err"
echo keep >"$tmp/file"
check "an output that is a file is exit 1" expect_exit 1 "$skybake" bake "$tmp/old.json" -o "$tmp/file"
check "it says so" grep -q "not a directory" "$tmp/err"
check "the file is untouched" test "$(cat "$tmp/file")" = keep

echo "faults: $checks checks, $fails failed"
[ $fails = 0 ]
