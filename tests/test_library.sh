#!/bin/sh
# libskybake-formats as an engine uses it: the example program built through
# pkg-config alone (the build's uninstalled .pc), against the shared and the
# static library, loads a pack that the baker wrote and refuses a broken one.
# Usage: test_library.sh BUILD_DIR SKYBAKE SOURCE_ROOT
set -u
build=$1
skybake=$2
root=$3
. "$root/tests/cli_lib.sh"
export PKG_CONFIG_PATH="$build/meson-uninstalled"
cc=${CC:-cc}
extra=${EXAMPLE_CFLAGS:-} # a sanitizer build's library needs its runtime in the program too
export SKYBAKE_VALIDATE=1

check "pkg-config knows skybake-formats" pkg-config --exists skybake-formats
flags=$(pkg-config --cflags --libs skybake-formats)
check "the example builds against the shared library" \
    $cc -std=c11 -Wall -Werror $extra "$root/tests/example_engine.c" -o "$tmp/example_shared" $flags
# --static adds the private dependencies; -Bstatic takes the archive for ours alone.
static_flags=$(pkg-config --static --cflags --libs skybake-formats |
    sed 's/-lskybake-formats/-Wl,-Bstatic -lskybake-formats -Wl,-Bdynamic/')
check "the example builds against the static library" \
    $cc -std=c11 -Wall -Werror $extra "$root/tests/example_engine.c" -o "$tmp/example_static" $static_flags
check "the shared build links libskybake-formats.so" sh -c "ldd '$tmp/example_shared' | grep -q 'libskybake-formats.so'"
check "the static build does not" sh -c "! ldd '$tmp/example_static' | grep -q 'libskybake-formats.so'"

printf '{"atmosphere":{"preset":"earth"},"products":["transmittance","cloud_detail"],%s}' \
    '"clouds":{"cloud_detail":{"size":16,"worley_cells":[1,2,4]}}' >"$tmp/t.json"
check "bake a pack" expect_exit 0 "$skybake" bake "$tmp/t.json" -o "$tmp/pack" -q
hash=$(sed -n 's/.*"content_hash":[[:space:]]*"\([0-9a-f]*\)".*/\1/p' "$tmp/pack/manifest.json" | head -n 1)
volume_hash=$(sed -n 's/.*"content_hash":[[:space:]]*"\([0-9a-f]*\)".*/\1/p' "$tmp/pack/manifest.json" | tail -n 1)
# The static example lies outside the build tree, with nothing beside it:
# it finds the VDB helper only where SKYBAKE_LIBEXEC_DIR says (the shared
# one finds it beside the library), and says so when it cannot.
check "the static example without the helper fails" expect_exit 1 "$tmp/example_static" "$tmp/pack"
check "naming the helper and SKYBAKE_LIBEXEC_DIR" grep -q "cannot find the helper program skybake-vdb.*SKYBAKE_LIBEXEC_DIR" "$tmp/err"
for kind in shared static; do
    check "the $kind example loads the pack" expect_exit 0 env LD_LIBRARY_PATH="$build/formats" \
        SKYBAKE_LIBEXEC_DIR="$([ $kind = static ] && echo "$build/formats")" "$tmp/example_$kind" "$tmp/pack"
    check "the $kind example reads the transmittance" grep -q "^transmittance 160x100x1 x3 first value 0\.[0-9]* hash $hash" "$tmp/out"
    check "the $kind example reads the volume (OpenVDB)" grep -q "^cloud_detail 16x16x16 x3 first value 0\.[0-9]* hash $volume_hash" "$tmp/out"
done
echo x >"$tmp/pack/stray"
check "the example refuses a pack that does not verify" expect_exit 1 env LD_LIBRARY_PATH="$build/formats" "$tmp/example_shared" "$tmp/pack"
check "with the code's name and description" grep -q "refused: unlisted-file (a file in a pack" "$tmp/out"

echo "library: $checks checks, $fails failed"
[ $fails = 0 ]
