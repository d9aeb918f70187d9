#!/bin/sh
# skybake as a user runs it: exit codes, error messages, determinism across
# thread counts, and a failed bake that must leave the previous pack intact.
# Usage: test_cli.sh SKYBAKE SOURCE_ROOT
set -u
skybake=$1
root=$2
. "$root/tests/cli_lib.sh"
scene=$root/data/scenes/earth.json
export SKYBAKE_VALIDATE=1

check "help exits 0" expect_exit 0 "$skybake" --help
check "no arguments is a usage error" expect_exit 2 "$skybake"
check "bake without -o is a usage error" expect_exit 2 "$skybake" bake "$scene"
check "missing scene is exit 2" expect_exit 2 "$skybake" bake "$tmp/nope.json" -o "$tmp/p"
check "missing scene names the file" grep -q "nope.json" "$tmp/err"

printf '{"atmosphere":{"preset":"earth","mie_g":1.5}}' >"$tmp/bad.json"
check "out-of-range scene is exit 2" expect_exit 2 "$skybake" bake "$tmp/bad.json" -o "$tmp/p"
check "error names the JSON path" grep -q "atmosphere.mie_g" "$tmp/err"
check "no pack after a refused scene" test ! -e "$tmp/p"

check "no Vulkan device is exit 3" expect_exit 3 env VK_DRIVER_FILES=/nonexistent.json VK_ICD_FILENAMES=/nonexistent.json "$skybake" bake "$scene" -o "$tmp/p"
check "no-device message is one clear line" grep -q "no Vulkan device" "$tmp/err"
check "unknown --device is exit 3" expect_exit 3 "$skybake" bake "$scene" -o "$tmp/p" --device no-such-gpu

# Determinism: identical content hashes across runs and lavapipe thread counts.
check "bake with 1 thread" expect_exit 0 env LP_NUM_THREADS=1 "$skybake" bake "$scene" -o "$tmp/a" --json -q
cp "$tmp/out" "$tmp/a.json"
check "bake with 2 threads" expect_exit 0 env LP_NUM_THREADS=2 "$skybake" bake "$scene" -o "$tmp/b" --json -q
cp "$tmp/out" "$tmp/b.json"
hashes() { grep '"content_hash"' "$1"; }
check "four artifacts" test "$(hashes "$tmp/a/manifest.json" | wc -l)" = 4
check "hashes equal across thread counts" test "$(hashes "$tmp/a/manifest.json")" = "$(hashes "$tmp/b/manifest.json")"
check "hashes equal in --json and manifest" test "$(hashes "$tmp/a.json" | tr -d ' ,')" = "$(hashes "$tmp/a/manifest.json" | tr -d ' ,')"
for f in manifest.json transmittance.exr multiscattering.exr irradiance_ground.exr irradiance_sky.exr; do
    check "pack holds $f" test -s "$tmp/a/$f"
done
check "manifest has format_version 1" grep -Eq '"format_version":[[:space:]]*1,' "$tmp/a/manifest.json"

# Rebaking over a pack replaces it whole; a failed bake leaves it as it was.
check "rebake over a pack" expect_exit 0 "$skybake" bake "$scene" -o "$tmp/a" -q
before=$(cat "$tmp/a/manifest.json")
check "bad scene into an existing pack fails" expect_exit 2 "$skybake" bake "$tmp/bad.json" -o "$tmp/a"
check "previous pack untouched" test "$before" = "$(cat "$tmp/a/manifest.json")"
mkdir "$tmp/notapack" && echo keep >"$tmp/notapack/file.txt"
check "refuses to replace a directory that is not a pack" expect_exit 1 "$skybake" bake "$scene" -o "$tmp/notapack"
check "foreign directory untouched" test "$(cat "$tmp/notapack/file.txt")" = keep
check "no temporary directories left" test -z "$(ls -d "$tmp"/*.tmp-* 2>/dev/null)"
check "output into a missing parent fails" expect_exit 1 "$skybake" bake "$scene" -o "$tmp/missing/parent/p"

echo "cli: $checks checks, $fails failed"
echo "$((checks - fails)) passed, $fails failed"
[ "$fails" = 0 ]
